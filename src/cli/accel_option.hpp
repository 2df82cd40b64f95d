// The --accel option, declared once for every subcommand that builds a
// structure (trace, render): one default, one validation, one message.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace rtcl::cli {

// "bvh" when it is registered, else the first registered structure.
std::string default_accel();

// Adds "--accel NAME" to `cmd`, stored in `spec`. An unknown structure is a
// usage error at parse time: "--accel: unknown acceleration structure 'x'
// (known: brute, bvh, ...)". The structure name is the text before the first
// ':' ("grid:lambda=4" names "grid"); what follows is left to the structure.
CLI::Option* add_accel_option(CLI::App& cmd, std::string& spec);

// `spec`, or default_accel() when it is empty.
std::string accel_or_default(const std::string& spec);

}  // namespace rtcl::cli
