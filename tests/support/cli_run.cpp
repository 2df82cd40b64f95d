#include "support/cli_run.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace rtcl::test {

std::string shell_quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

namespace {

CliRun run_with(const TempDir& dir, const std::vector<std::string>& args, const std::string& env,
                const std::string& limits, const std::string& launcher) {
  if (!std::filesystem::exists(std::string(RTCL_BINARY_DIR) + "/rtcl"))
    return {-2, "",
            std::string("the rtcl binary is missing from ") + RTCL_BINARY_DIR + " (configure with RTCL_BUILD_CLI=ON)"};
  // timeout: a hang fails the test (exit 124) instead of stalling the suite.
  std::string command = "cd " + shell_quoted(dir.path()) + " && " + limits + " " + env + " exec timeout 120 " + launcher + " " +
                        shell_quoted(std::string(RTCL_BINARY_DIR) + "/rtcl");
  for (const auto& a : args) command += " " + shell_quoted(a);
  // Captured outside dir, so that dir holds only what rtcl wrote.
  std::string out = dir.path() + ".stdout", err = dir.path() + ".stderr";
  command += " >" + shell_quoted(out) + " 2>" + shell_quoted(err);
  auto start = std::chrono::steady_clock::now();
  CliRun run;
  // fork + wait4 rather than std::system: the rusage is this run's alone.
  pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int raw = 0;
  struct rusage usage {};
  if (pid < 0 || ::wait4(pid, &raw, 0, &usage) != pid) return {-3, "", "cannot start " + command};
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.max_rss_mib = static_cast<double>(usage.ru_maxrss) / 1024.0;
  run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  run.out = read_text(out);
  run.err = read_text(err);
  std::remove(out.c_str());
  std::remove(err.c_str());
  return run;
}

}  // namespace

CliRun run_cli(const TempDir& dir, const std::vector<std::string>& args, const std::string& env,
               const std::string& limits) {
  return run_with(dir, args, env, limits, "");
}

CliRun run_cli_launched(const TempDir& dir, const std::string& launcher, const std::vector<std::string>& args,
                        const std::string& env) {
  return run_with(dir, args, env, "", launcher);
}

std::size_t count_of(const std::string& text, const std::string& fragment) {
  std::size_t n = 0;
  for (std::size_t p = text.find(fragment); p != std::string::npos; p = text.find(fragment, p + 1)) ++n;
  return n;
}

void expect_failure(const CliRun& run, const std::string& fragment, const TempDir& dir, const std::string& output,
                    int status) {
  EXPECT_EQ(run.status, status) << run.err;
  EXPECT_EQ(count_of(run.err, "rtcl: error:"), 1u) << run.err;
  EXPECT_NE(run.err.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << run.err;
  if (!output.empty()) EXPECT_FALSE(std::filesystem::exists(dir.file(output))) << output << " was written";
  for (const auto& name : dir.entries()) EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "left behind: " << name;
}

void expect_usage_error(const CliRun& run, const std::string& fragment) {
  EXPECT_EQ(run.status, 2) << run.err;
  EXPECT_EQ(count_of(run.err, "rtcl: error:"), 1u) << run.err;
  EXPECT_EQ(run.err.rfind("rtcl: error: ", 0), 0u) << "the error is the first line: " << run.err;
  EXPECT_NE(run.err.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << run.err;
  EXPECT_NE(run.err.find("--help"), std::string::npos) << run.err;
}

std::string mpi_rank_env(const std::string& extra) {
  std::string env = extra;
  if (const char* asan = std::getenv("ASAN_OPTIONS"); asan && *asan)
    env += " ASAN_OPTIONS=" + shell_quoted(std::string(asan) + ":detect_leaks=0:use_sigaltstack=0");
  return env;
}

}  // namespace rtcl::test
