#include "rtcl/precision.hpp"

#include "rtcl/error.hpp"

namespace rtcl {

const std::vector<std::string>& precision_names() {
  static const std::vector<std::string> names = {"fast", "robust", "exact"};
  return names;
}

std::string_view precision_name(Precision precision) {
  return precision_names()[static_cast<std::size_t>(precision)];
}

Precision parse_precision(std::string_view name) {
  const auto& names = precision_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<Precision>(i);
  throw Error("precision \"" + std::string(name) + "\": unknown precision level (known: fast, robust, exact)");
}

std::string precision_unsupported(const DeviceInfo& device, Precision precision) {
  if (precision == Precision::exact && !device.fp64)
    return "exact needs double precision on the device (cl_khr_fp64), which " + device.name + " lacks";
  return "";
}

void require_precision(const DeviceInfo& device, Precision precision) {
  std::string why = precision_unsupported(device, precision);
  if (!why.empty()) throw Error("precision \"" + std::string(precision_name(precision)) + "\": " + why);
}

std::vector<std::string> precision_build_options(Precision precision) {
  switch (precision) {
    case Precision::fast: return {"RTCL_PRECISION_FAST", "-cl-fast-relaxed-math"};
    case Precision::robust: return {"RTCL_PRECISION_ROBUST"};
    case Precision::exact: return {"RTCL_PRECISION_EXACT"};
  }
  return {};
}

}  // namespace rtcl
