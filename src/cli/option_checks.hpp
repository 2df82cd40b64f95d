// The checks of option values at parse time, and the options every
// subcommand declares alike (--device, -q). A check returns the problem
// without the value ("must be an integer in [1, 65536]"); the error path
// (cli_errors.cpp) prefixes the flag and the value as given:
// "rtcl: error: --width 0: must be an integer in [1, 65536]", exit 2.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace rtcl::cli {

// An integer in [lo, hi] (decimal, the whole text).
CLI::Validator integer_in(long long lo, long long hi);

// A number (the whole text) that `accept` takes; `what` says which, as in
// "a finite number >= 0" or "in (0, 1]".
CLI::Validator number_where(const std::string& what, std::function<bool(double)> accept);

// One of `names`; `what` names the kind in "unknown method (known: ray, ...)".
CLI::Validator one_of(const std::vector<std::string>& names, const std::string& what);

// --device SELECTOR: an index or a name substring from `rtcl devices`, the
// same in every subcommand; `fallback` says what is used without it. Checked
// when the device is opened (flag_names.hpp: open_device_flag).
CLI::Option* add_device_option(CLI::App& cmd, std::string& selector, const std::string& fallback);

// -q, --quiet: no progress display on stderr (progress.hpp).
CLI::Option* add_quiet_flag(CLI::App& cmd, bool& quiet);

}  // namespace rtcl::cli
