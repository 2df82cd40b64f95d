#include "rates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rtcl::cli {

std::string mrays_text(double mrays_per_s) {
  if (!std::isfinite(mrays_per_s) || mrays_per_s < 0.0) return "-";
  if (mrays_per_s == 0.0) return "0";
  // Digits after the point: enough for three significant ones, at least none.
  int digits = std::max(0, 2 - static_cast<int>(std::floor(std::log10(mrays_per_s))));
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, mrays_per_s);
  return text;
}

std::string mrays_text(double rays, double ms) {
  if (rays == 0.0) return "0";
  if (!(ms > 0.0)) return "-";
  return mrays_text(rays / (ms * 1e3));
}

}  // namespace rtcl::cli
