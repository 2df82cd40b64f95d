#include "cli_errors.hpp"

#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace rtcl::cli {

namespace {

// One line: newlines inside a message (a kernel build log, say) are kept on
// the lines that follow, so the "rtcl: error:" line itself stays first.
int report(const std::string& message, ExitCode code) {
  std::fprintf(stderr, "rtcl: error: %s\n", message.c_str());
  return static_cast<int>(code);
}

// "rtcl trace" for the subcommand being parsed, "rtcl" before any.
std::string command_name(const CLI::App& app) {
  std::string name = "rtcl";
  for (const CLI::App* sub : app.get_subcommands()) name += " " + sub->get_name();
  return name;
}

// Arguments CLI11 could not place, in the order given: an unknown flag or an
// extra positional is named even when CLI11 stopped at a missing one first.
std::vector<std::string> unplaced(const CLI::App& app) {
  std::vector<std::string> out = app.remaining();
  for (const CLI::App* sub : app.get_subcommands())
    for (const std::string& arg : sub->remaining()) out.push_back(arg);
  return out;
}

int report_usage(std::string message, const CLI::App& app) {
  if (std::vector<std::string> extras = unplaced(app); !extras.empty())
    message = (extras[0].rfind('-', 0) == 0 ? "unknown option '" : "unexpected argument '") + extras[0] + "'";
  int code = report(message, ExitCode::usage);
  std::fprintf(stderr, "rtcl: see '%s --help' for the options\n", command_name(app).c_str());
  return code;
}

}  // namespace

int run_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help and friends
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return report_usage(e.what(), app);
  } catch (const UsageError& e) {
    return report_usage(e.what(), app);
  } catch (const std::bad_alloc&) {
    return report("out of host memory", ExitCode::failed);
  } catch (const std::exception& e) {
    return report(e.what(), ExitCode::failed);
  }
  return static_cast<int>(ExitCode::ok);
}

}  // namespace rtcl::cli
