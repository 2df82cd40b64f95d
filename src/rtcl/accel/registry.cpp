// The one list of structures make_accel knows. A new structure adds its
// builder file, its kernel file and one line here.
#include <functional>

#include "rtcl/accel/accel.hpp"
#include "rtcl/accel/brute.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/grid.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

using Factory = std::function<std::unique_ptr<Accel>(const Device&, const Geometry&, const AccelConfig&)>;

const std::vector<std::pair<std::string, Factory>>& registry() {
  static const std::vector<std::pair<std::string, Factory>> entries = {
      {"brute", [](const Device& d, const Geometry& g, const AccelConfig& c) { return make_brute(d, g, c); }},
      {"bvh", make_bvh_sah},
      {"bvh-ploc", make_bvh_ploc},
      {"bvh-packet", make_bvh_packet},
      {"grid", [](const Device& d, const Geometry& g, const AccelConfig& c) { return make_grid(d, g, {}, c); }},
  };
  return entries;
}

}  // namespace

std::vector<std::string> accel_names() {
  std::vector<std::string> names;
  for (const auto& entry : registry()) names.push_back(entry.first);
  return names;
}

std::unique_ptr<Accel> make_accel(const Device& device, std::string_view name, const Geometry& geometry,
                                  const AccelConfig& config) {
  for (const auto& entry : registry())
    if (entry.first == name) {
      require_precision(device.info(), config.precision);
      return entry.second(device, geometry, config);
    }
  std::string known;
  for (const auto& entry : registry()) known += (known.empty() ? "" : ", ") + entry.first;
  throw Error("--accel " + std::string(name) + ": unknown acceleration structure (known: " + known + ")");
}

}  // namespace rtcl
