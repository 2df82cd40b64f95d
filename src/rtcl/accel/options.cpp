#include "rtcl/accel_options.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "rtcl/error.hpp"

namespace rtcl {

namespace {

// x as written: an integer without a fraction ("1000000"), a value that is
// a float (a default declared as one, such as 1.3f) in the float's shortest
// form ("1.3", not 1.29999995231628), else the double's shortest form.
std::string number_text(double x) {
  char text[64];
  if (std::isfinite(x) && x == std::trunc(x) && std::abs(x) < 1e15) {
    std::snprintf(text, sizeof text, "%.0f", x);
    return text;
  }
  const float f = static_cast<float>(x);
  auto [end, ec] = static_cast<double>(f) == x ? std::to_chars(text, text + sizeof text, f)
                                               : std::to_chars(text, text + sizeof text, x);
  return ec == std::errc() ? std::string(text, end) : std::string("?");
}

bool parse_double(std::string_view text, double* out) {
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *out);
  return ec == std::errc() && end == text.data() + text.size() && std::isfinite(*out);
}

bool parse_int(std::string_view text, std::int64_t* out) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *out);
  return ec == std::errc() && end == text.data() + text.size();
}

bool in_range(const OptionSpec& spec, double x) {
  if (!((spec.min_exclusive ? x > spec.min : x >= spec.min) && x <= spec.max)) return false;
  // Within [min, max] first: the cast below then cannot overflow.
  return !spec.power_of_two || (x >= 1.0 && (static_cast<std::int64_t>(x) & (static_cast<std::int64_t>(x) - 1)) == 0);
}

std::string option_list(const StructureSpec& s) {
  if (s.options.empty()) return s.name + " has no options";
  std::string list;
  for (const OptionSpec& o : s.options) list += (list.empty() ? "" : ", ") + o.name;
  return "options: " + list;
}

// "unknown option foo of grid (options: lambda, res, ...)".
std::string unknown_option(const StructureSpec& s, const std::string& option) {
  return "unknown option " + option + " of " + s.name + " (" + option_list(s) + ")";
}

// Checks a typed value against the declaration (type and range).
void check_value(const OptionSpec& spec, const OptionValue& value, const std::string& context) {
  auto fail = [&](const std::string& what) { throw Error(context + ": " + spec.name + " must be " + what); };
  switch (spec.type) {
    case OptionType::integer:
      if (!std::holds_alternative<std::int64_t>(value)) fail("an integer");
      if (!in_range(spec, static_cast<double>(std::get<std::int64_t>(value)))) fail(option_range_text(spec));
      break;
    case OptionType::real: {
      double x = std::holds_alternative<double>(value) ? std::get<double>(value)
                 : std::holds_alternative<std::int64_t>(value)
                     ? static_cast<double>(std::get<std::int64_t>(value))
                     : (fail("a number"), 0.0);
      if (!std::isfinite(x) || !in_range(spec, x)) fail(option_range_text(spec));
      break;
    }
    case OptionType::boolean:
      if (!std::holds_alternative<bool>(value)) fail("true or false");
      break;
    case OptionType::resolution: {
      if (!std::holds_alternative<Resolution3>(value)) fail("a resolution AxBxC");
      const Resolution3& r = std::get<Resolution3>(value);
      if (r == Resolution3{0, 0, 0}) break;  // auto
      for (std::uint32_t axis : r)
        if (!in_range(spec, axis)) fail(option_range_text(spec));
      break;
    }
  }
}

}  // namespace

const OptionSpec* StructureSpec::find(std::string_view option) const {
  for (const OptionSpec& o : options)
    if (o.name == option) return &o;
  return nullptr;
}

AccelOptions& AccelOptions::set(std::string name, OptionValue value) {
  values_[std::move(name)] = value;
  return *this;
}

bool AccelOptions::has(std::string_view name) const { return values_.find(name) != values_.end(); }

const OptionValue& AccelOptions::get(std::string_view name) const {
  auto it = values_.find(name);
  if (it == values_.end()) throw Error("internal: structure option " + std::string(name) + " is not set");
  return it->second;
}

std::int64_t AccelOptions::integer(std::string_view name) const {
  const OptionValue& v = get(name);
  if (!std::holds_alternative<std::int64_t>(v)) throw Error("internal: option " + std::string(name) + " is no integer");
  return std::get<std::int64_t>(v);
}

double AccelOptions::real(std::string_view name) const {
  const OptionValue& v = get(name);
  if (std::holds_alternative<std::int64_t>(v)) return static_cast<double>(std::get<std::int64_t>(v));
  if (!std::holds_alternative<double>(v)) throw Error("internal: option " + std::string(name) + " is no number");
  return std::get<double>(v);
}

bool AccelOptions::boolean(std::string_view name) const {
  const OptionValue& v = get(name);
  if (!std::holds_alternative<bool>(v)) throw Error("internal: option " + std::string(name) + " is no boolean");
  return std::get<bool>(v);
}

Resolution3 AccelOptions::resolution(std::string_view name) const {
  const OptionValue& v = get(name);
  if (!std::holds_alternative<Resolution3>(v)) throw Error("internal: option " + std::string(name) + " is no resolution");
  return std::get<Resolution3>(v);
}

const char* option_type_name(OptionType type) {
  switch (type) {
    case OptionType::integer: return "integer";
    case OptionType::real: return "number";
    case OptionType::boolean: return "boolean";
    case OptionType::resolution: return "resolution";
  }
  return "?";
}

std::string option_range_text(const OptionSpec& spec) {
  std::string lo = number_text(spec.min), hi = number_text(spec.max);
  switch (spec.type) {
    case OptionType::boolean: return "";
    case OptionType::resolution: return "AxBxC with each axis in [" + lo + ", " + hi + "], or auto";
    default:
      return std::string(spec.power_of_two ? "a power of two " : "") +
             (spec.min_exclusive ? "> " + lo + " and <= " + hi : "in [" + lo + ", " + hi + "]");
  }
}

std::string format_option_value(const OptionValue& value) {
  if (auto* i = std::get_if<std::int64_t>(&value)) return std::to_string(*i);
  if (auto* d = std::get_if<double>(&value)) return number_text(*d);
  if (auto* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  const Resolution3& r = std::get<Resolution3>(value);
  if (r == Resolution3{0, 0, 0}) return "auto";
  return std::to_string(r[0]) + "x" + std::to_string(r[1]) + "x" + std::to_string(r[2]);
}

OptionValue parse_option_value(const OptionSpec& spec, std::string_view text, const std::string& context) {
  auto fail = [&](const std::string& what) {
    throw Error(context + ": " + spec.name + " must be " + what + " (got '" + std::string(text) + "')");
  };
  OptionValue value;
  switch (spec.type) {
    case OptionType::integer: {
      std::int64_t i = 0;
      if (!parse_int(text, &i)) fail("an integer");
      value = i;
      break;
    }
    case OptionType::real: {
      double x = 0.0;
      if (!parse_double(text, &x)) fail("a number");
      value = x;
      break;
    }
    case OptionType::boolean:
      if (text == "true" || text == "1" || text == "on") value = true;
      else if (text == "false" || text == "0" || text == "off") value = false;
      else fail("true or false");
      break;
    case OptionType::resolution: {
      if (text == "auto") {
        value = Resolution3{0, 0, 0};
        break;
      }
      Resolution3 r{};
      std::size_t axis = 0;
      std::string_view rest = text;
      for (; axis < 3; ++axis) {
        std::size_t x = rest.find('x');
        std::string_view part = axis < 2 ? rest.substr(0, x) : rest;
        std::int64_t n = 0;
        if ((axis < 2 && x == std::string_view::npos) || !parse_int(part, &n))
          fail("AxBxC (three integers, e.g. 64x32x16) or auto");
        if (!in_range(spec, static_cast<double>(n))) fail(option_range_text(spec));
        r[axis] = static_cast<std::uint32_t>(n);
        if (axis < 2) rest = rest.substr(x + 1);
      }
      value = r;
      break;
    }
  }
  check_value(spec, value, context);
  return value;
}

AccelOptions resolve_options(const StructureSpec& structure, const AccelOptions& given, const std::string& context) {
  AccelOptions out;
  for (const auto& [name, value] : given.values()) {
    const OptionSpec* spec = structure.find(name);
    if (!spec) throw Error(context + ": " + unknown_option(structure, name));
    check_value(*spec, value, context);
    out.set(name, spec->type == OptionType::real && std::holds_alternative<std::int64_t>(value)
                      ? OptionValue(static_cast<double>(std::get<std::int64_t>(value)))
                      : value);
  }
  for (const OptionSpec& spec : structure.options)
    if (!out.has(spec.name)) out.set(spec.name, spec.default_value);
  return out;
}

AccelSpec parse_accel_spec(std::string_view text, const std::string& given_context) {
  std::string context = given_context.empty() ? "accel \"" + std::string(text) + "\"" : given_context;
  std::size_t colon = text.find(':');
  AccelSpec out;
  out.name = std::string(text.substr(0, colon));
  const StructureSpec* found = nullptr;
  try {
    found = &structure_spec(out.name);
  } catch (const Error& e) {
    // structure_spec's "accel "NAME": PROBLEM", under this context.
    std::string what = e.what();
    std::string own = "accel \"" + out.name + "\"";
    throw Error(context + (what.rfind(own, 0) == 0 ? what.substr(own.size()) : ": " + what));
  }
  const StructureSpec& structure = *found;
  if (colon == std::string_view::npos) return out;
  std::string_view rest = text.substr(colon + 1);
  if (rest.empty()) throw Error(context + ": expected key=value after ':' (" + option_list(structure) + ")");
  while (!rest.empty()) {
    std::size_t comma = rest.find(',');
    std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    std::size_t eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0)
      throw Error(context + ": expected key=value, got '" + std::string(item) + "'");
    std::string key(item.substr(0, eq));
    const OptionSpec* spec = structure.find(key);
    if (!spec) throw Error(context + ": " + unknown_option(structure, key));
    if (out.options.has(key)) throw Error(context + ": option " + key + " given twice");
    out.options.set(key, parse_option_value(*spec, item.substr(eq + 1), context));
  }
  return out;
}

std::string format_accel_spec(const AccelSpec& spec) {
  std::string out = spec.name;
  char sep = ':';
  for (const auto& [name, value] : spec.options.values()) {
    out += sep + name + "=" + format_option_value(value);
    sep = ',';
  }
  return out;
}

}  // namespace rtcl
