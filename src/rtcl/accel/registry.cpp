// The one list of structures make_accel knows. A new structure adds its
// builder file (with its StructureSpec: name, summary, options), its kernel
// file and one line here, with its build's memory per triangle
// (build_memory.hpp: host peak, device total, largest device buffer; the
// larger of what `rtcl bench` measures, peak resident memory and
// device_bytes, on a random soup and on the tessellated surface of 1M
// triangles, rounded down to 8 bytes).
#include <functional>

#include "rtcl/accel.hpp"
#include "rtcl/accel/brute.hpp"
#include "rtcl/accel/bsp.hpp"
#include "rtcl/accel/build_memory.hpp"
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
  BuildFootprint footprint;
};

const std::vector<Entry>& registry() {
  // Footprints: bytes per triangle at the build's peak on the host beyond
  // the geometry, of the structure on the device, and of its largest buffer
  // (the triangle blocks, 320 bytes per 8, in every structure).
  static const std::vector<Entry> entries = {
      {brute_structure(), [](const Device& d, const Geometry& g, const AccelConfig& c) { return make_brute(d, g, c); },
       {40, 40, 40}},
      {bvh_structure(), make_bvh_sah, {112, 48, 40}},
      {bvh_ploc_structure(), make_bvh_ploc, {136, 56, 40}},
      {bvh_packet_structure(), make_bvh_packet, {112, 48, 40}},
      {bvh_mixed_structure(), make_bvh_mixed, {112, 56, 40}},
      {grid_structure(), make_grid_accel, {336, 224, 40}},
      {octree_structure(), make_octree_accel, {224, 120, 40}},
      {octree_ptr_structure(), make_octree_ptr_accel, {224, 120, 40}},
      {octree_r_structure(), make_octree_r_accel, {240, 112, 40}},
      {bsp_structure(), make_bsp_accel, {552, 328, 40}},
      {kdtree_structure(), make_kdtree_accel, {200, 72, 40}},
      {kdtree_packet_structure(), make_kdtree_packet_accel, {200, 72, 40}},
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
  // A sphere's block lane is half a triangle's (SphereBlock, TriangleBlock).
  check_build_memory(entry->footprint, geometry.triangles.size() + (geometry.spheres.size() + 1) / 2,
                     context + " over " + geometry.source, device);
  return entry->make(device, geometry, full);
}

}  // namespace rtcl
