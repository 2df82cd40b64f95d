// Typed build options of acceleration structures. Each structure declares
// its options once (name, type, default, range, the trade-off it makes; the
// declaration lives beside its builder and is listed by the registry); the
// C++ API (AccelConfig::options), the CLI (--accel grid:lambda=4,res=64x32x16),
// scene files ("accel": {"name": "grid", "lambda": 4}) and bench/ all reach
// them through that declaration, and a bad value is an Error naming the
// structure and the option.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace rtcl {

enum class OptionType {
  integer,     // decimal integer
  real,        // decimal number
  boolean,     // true / false (also 1 / 0, on / off)
  resolution,  // AxBxC cells per axis, or "auto" ({0, 0, 0}: chosen by the structure)
};

using Resolution3 = std::array<std::uint32_t, 3>;
using OptionValue = std::variant<std::int64_t, double, bool, Resolution3>;

struct OptionSpec {
  std::string name;
  OptionType type = OptionType::integer;
  OptionValue default_value;
  // Inclusive range of integers and reals, and of each axis of a
  // resolution; min_exclusive makes the lower bound strict (> min).
  double min = 0.0, max = 0.0;
  bool min_exclusive = false;
  std::string help;  // what it controls and what it trades
  bool power_of_two = false;  // integers only: the value must also be 2^n
};

// One structure in the registry: its name, one line on what it is, and its
// options.
struct StructureSpec {
  std::string name;
  std::string summary;
  std::vector<OptionSpec> options;
  const OptionSpec* find(std::string_view option) const;
};

// Option values by name. Values set by callers are checked when a
// structure is made (make_accel); a structure's factory receives every
// declared option, defaults filled in, and reads them with the typed
// getters (which throw Error for a missing option or another type).
class AccelOptions {
 public:
  AccelOptions& set(std::string name, OptionValue value);
  bool has(std::string_view name) const;
  bool empty() const { return values_.empty(); }
  const std::map<std::string, OptionValue, std::less<>>& values() const { return values_; }
  std::int64_t integer(std::string_view name) const;
  double real(std::string_view name) const;
  bool boolean(std::string_view name) const;
  Resolution3 resolution(std::string_view name) const;

 private:
  const OptionValue& get(std::string_view name) const;
  std::map<std::string, OptionValue, std::less<>> values_;
};

// A structure and its options as one text: "NAME" or
// "NAME:key=value,key=value" (e.g. "grid:lambda=4,res=64x32x16").
struct AccelSpec {
  std::string name;
  AccelOptions options;  // as given: validated, defaults not filled in
};

// Parses and validates a spec against the registry (structure_spec).
// Errors read "CONTEXT: PROBLEM", by default with the context accel "TEXT",
// e.g. accel "grid:lambda=-1": lambda must be > 0, accel "grid:foo=1":
// unknown option foo of grid (options: lambda, res, ...). `context`
// replaces accel "TEXT" when given: make_accel's make_accel name "TEXT",
// a scene file's "FILE: accel", the CLI's "--accel TEXT".
AccelSpec parse_accel_spec(std::string_view text, const std::string& context = {});

// "grid:lambda=4,res=64x32x16" (options in name order); just the name when
// there are none. parse_accel_spec reads it back to the same spec.
std::string format_accel_spec(const AccelSpec& spec);

// The value of `text` for option `spec`, or Error "CONTEXT: NAME must be ..."
// for a wrong type or a value out of range.
OptionValue parse_option_value(const OptionSpec& spec, std::string_view text, const std::string& context);

// Checks every given option against the structure's declaration (unknown
// name, wrong type, out of range: Error "CONTEXT: ...") and returns them
// with the declared defaults of the others filled in.
AccelOptions resolve_options(const StructureSpec& structure, const AccelOptions& given, const std::string& context);

// "4", "0.5", "true", "64x32x16", "auto".
std::string format_option_value(const OptionValue& value);
// "integer", "number", "boolean", "resolution".
const char* option_type_name(OptionType type);
// "> 0", "in [1, 8]", "each axis in [1, 65536], or auto"; "" for booleans.
std::string option_range_text(const OptionSpec& spec);

// The registry's structures, in accel_names() order (registry.cpp).
const std::vector<StructureSpec>& structure_specs();
// Throws Error accel "NAME": unknown acceleration structure (known: ...).
const StructureSpec& structure_spec(std::string_view name);

}  // namespace rtcl
