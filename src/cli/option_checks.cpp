#include "option_checks.hpp"

#include <charconv>
#include <cmath>

namespace rtcl::cli {

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

CLI::Validator integer_in(long long lo, long long hi) {
  const std::string problem = "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, problem](std::string& text) {
        long long value = 0;
        const char* end = text.data() + text.size();
        auto [stop, ec] = std::from_chars(text.data(), end, value);
        bool ok = !text.empty() && ec == std::errc() && stop == end && value >= lo && value <= hi;
        return ok ? std::string() : problem;
      },
      "INT in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

CLI::Validator number_where(const std::string& what, std::function<bool(double)> accept) {
  return CLI::Validator(
      [what, accept](std::string& text) {
        double value = 0.0;
        const char* end = text.data() + text.size();
        auto [stop, ec] = std::from_chars(text.data(), end, value);
        bool number = !text.empty() && ec == std::errc() && stop == end;
        return number && accept(value) ? std::string() : "must be " + what;
      },
      "NUMBER " + what);
}

CLI::Validator one_of(const std::vector<std::string>& names, const std::string& what) {
  return CLI::Validator(
      [names, what](std::string& text) {
        for (const std::string& n : names)
          if (text == n) return std::string();
        return "unknown " + what + " (known: " + joined(names) + ")";
      },
      joined(names));
}

CLI::Option* add_device_option(CLI::App& cmd, std::string& selector, const std::string& fallback) {
  return cmd.add_option("--device", selector,
                        "OpenCL device: an index or a name substring from `rtcl devices` (default: " + fallback + ")");
}

CLI::Option* add_quiet_flag(CLI::App& cmd, bool& quiet) {
  return cmd.add_flag("-q,--quiet", quiet, "no progress display on stderr (shown only when stderr is a terminal)");
}

}  // namespace rtcl::cli
