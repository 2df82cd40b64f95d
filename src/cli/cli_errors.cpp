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

std::string subcommand_names(const CLI::App& app) {
  std::string out;
  for (const CLI::App* sub : app.get_subcommands({})) out += (out.empty() ? "" : ", ") + sub->get_name();
  return out;
}

// Arguments CLI11 could not place, in the order given: an unknown flag or an
// extra positional is named even when CLI11 stopped at a missing one first.
std::vector<std::string> unplaced(const CLI::App& app) {
  std::vector<std::string> out = app.remaining();
  for (const CLI::App* sub : app.get_subcommands())
    for (const std::string& arg : sub->remaining()) out.push_back(arg);
  return out;
}

// The value given to the option or positional `name` of the subcommand
// being parsed ("" when none is found): the message names it after the flag.
std::string given_value(const CLI::App& app, const std::string& name) {
  std::vector<const CLI::App*> scopes;
  for (const CLI::App* sub : app.get_subcommands()) scopes.push_back(sub);
  scopes.push_back(&app);
  for (const CLI::App* scope : scopes)
    if (const CLI::Option* option = scope->get_option_no_throw(name); option && !option->results().empty())
      return option->results().back();
  return "";
}

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

bool ends_with(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// CLI11's message for `e` in the form "<what>: <problem>".
std::string usage_message(const CLI::ParseError& e, const CLI::App& app) {
  if (std::vector<std::string> extras = unplaced(app); !extras.empty()) {
    const std::string& arg = extras.front();
    if (starts_with(arg, "-")) return arg + ": unknown option";
    if (app.get_subcommands().empty())
      return arg + ": unknown subcommand (known: " + subcommand_names(app) + ")";
    return arg + ": unexpected argument";
  }
  const std::string what = e.what();
  const std::size_t colon = what.find(": ");
  const std::string name = colon == std::string::npos ? what : what.substr(0, colon);
  const std::string rest = colon == std::string::npos ? "" : what.substr(colon + 2);
  if (dynamic_cast<const CLI::RequiredError*>(&e)) {
    if (what == "A subcommand is required") return "no subcommand given (known: " + subcommand_names(app) + ")";
    if (ends_with(what, " is required")) return what.substr(0, what.size() - 12) + ": missing (required)";
  }
  if (dynamic_cast<const CLI::ValidationError*>(&e) && colon != std::string::npos) {
    std::string value = given_value(app, name);
    return name + (value.empty() ? "" : " " + value) + ": " + rest;
  }
  if (dynamic_cast<const CLI::ConversionError*>(&e) && starts_with(what, "Could not convert: ")) {
    std::string pair = what.substr(19);  // "NAME = VALUE"
    std::size_t eq = pair.find(" = ");
    if (eq != std::string::npos) return pair.substr(0, eq) + " " + pair.substr(eq + 3) + ": not a valid value";
  }
  if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) && colon != std::string::npos) {
    if (starts_with(rest, "At Most ")) {
      std::size_t received = rest.rfind(' ');
      return name + ": given " + rest.substr(received + 1) + " times (at most once)";
    }
    if (ends_with(rest, " missing")) return name + ": needs a value";
  }
  if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) && starts_with(what, "Expected ")) {
    std::size_t to = what.find(" arguments to "), got = what.rfind(", got ");
    if (to != std::string::npos && got != std::string::npos && got > to)
      return what.substr(to + 14, got - to - 14) + ": needs a value";
  }
  if (dynamic_cast<const CLI::ExcludesError*>(&e)) {
    std::size_t at = what.find(" excludes ");
    if (at != std::string::npos) return what.substr(0, at) + ": not with " + what.substr(at + 10);
  }
  if (dynamic_cast<const CLI::RequiresError*>(&e)) {
    std::size_t at = what.find(" requires ");
    if (at != std::string::npos) return what.substr(0, at) + ": needs " + what.substr(at + 10);
  }
  return what;
}

int report_usage(const std::string& message, const CLI::App& app) {
  int code = report(message, ExitCode::usage);
  std::fprintf(stderr, "rtcl: see '%s --help' for the options\n", command_name(app).c_str());
  return code;
}

// `rtcl` with no subcommand: the error, then each subcommand with its summary.
int report_no_subcommand(const CLI::App& app) {
  int code = report("no subcommand given (known: " + subcommand_names(app) + ")", ExitCode::usage);
  for (const CLI::App* sub : app.get_subcommands({}))
    std::fprintf(stderr, "  %-11s %s\n", sub->get_name().c_str(), sub->get_description().c_str());
  std::fprintf(stderr, "rtcl: see 'rtcl --help' and 'rtcl SUBCOMMAND --help' for the options\n");
  return code;
}

}  // namespace

int run_command_line(CLI::App& app, int argc, char** argv) {
  if (argc < 2) return report_no_subcommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::RequiredError& e) {
    if (std::string(e.what()) == "A subcommand is required" && unplaced(app).empty()) return report_no_subcommand(app);
    return report_usage(usage_message(e, app), app);
  } catch (const CLI::ParseError& e) {
    return report_usage(usage_message(e, app), app);
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
