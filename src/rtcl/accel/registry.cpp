// The one list of structures make_accel knows. A new structure adds its
// builder file (with its StructureSpec: name, summary, options), its kernel
// file and one line here.
#include <functional>

#include "rtcl/accel.hpp"
#include "rtcl/accel/brute.hpp"
#include "rtcl/accel/bsp.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/bvh_mixed.hpp"
#include "rtcl/accel/grid.hpp"
#include "rtcl/accel/octree.hpp"
#include "rtcl/accel/octree_ptr.hpp"
#include "rtcl/accel/octree_r.hpp"
#include "rtcl/accel/kdtree.hpp"
#include "rtcl/error.hpp"

namespace rtcl {

namespace {

using Factory = std::function<std::unique_ptr<Accel>(const Device&, const Geometry&, const AccelConfig&)>;

struct Entry {
  const StructureSpec& spec;
  Factory make;
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries = {
      {brute_structure(), [](const Device& d, const Geometry& g, const AccelConfig& c) { return make_brute(d, g, c); }},
      {bvh_structure(), make_bvh_sah},
      {bvh_ploc_structure(), make_bvh_ploc},
      {bvh_packet_structure(), make_bvh_packet},
      {bvh_mixed_structure(), make_bvh_mixed},
      {grid_structure(), make_grid_accel},
      {octree_structure(), make_octree_accel},
      {octree_ptr_structure(), make_octree_ptr_accel},
      {octree_r_structure(), make_octree_r_accel},
      {bsp_structure(), make_bsp_accel},
      {kdtree_structure(), make_kdtree_accel},
      {kdtree_packet_structure(), make_kdtree_packet_accel},
  };
  return entries;
}

}  // namespace

std::vector<std::string> accel_names() {
  std::vector<std::string> names;
  for (const Entry& entry : registry()) names.push_back(entry.spec.name);
  return names;
}

const std::vector<StructureSpec>& structure_specs() {
  static const std::vector<StructureSpec> specs = [] {
    std::vector<StructureSpec> out;
    for (const Entry& entry : registry()) out.push_back(entry.spec);
    return out;
  }();
  return specs;
}

const StructureSpec& structure_spec(std::string_view name) {
  for (const Entry& entry : registry())
    if (entry.spec.name == name) return entry.spec;
  std::string known;
  for (const Entry& entry : registry()) known += (known.empty() ? "" : ", ") + entry.spec.name;
  throw Error("accel \"" + std::string(name) + "\": unknown acceleration structure (known: " + known + ")");
}

// The options are parsed, checked and completed with their defaults here,
// once: a factory receives every declared option of its structure.
std::unique_ptr<Accel> make_accel(const Device& device, std::string_view name, const Geometry& geometry,
                                  const AccelConfig& config) {
  const std::string context = "make_accel name \"" + std::string(name) + "\"";
  AccelSpec spec = parse_accel_spec(name, context);
  AccelConfig full = config;
  full.options = spec.options;
  for (const auto& [option, value] : config.options.values()) full.options.set(option, value);
  const Entry* entry = nullptr;
  for (const Entry& e : registry())
    if (e.spec.name == spec.name) entry = &e;
  if (!entry) throw Error("internal: structure " + spec.name + " has no factory");
  full.options = resolve_options(entry->spec, full.options, context);
  require_precision(device.info(), config.precision);  // before the build; the Accel base checks it for bvh-motion
  return entry->make(device, geometry, full);
}

}  // namespace rtcl
