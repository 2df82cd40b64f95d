// The device compiler lays out the shared records (kernels/shared/layouts.h,
// kernels/shared/render_layouts.h; the list: kernels/probe/layout_entries.h)
// exactly as the host compiler does: sizes, strides, field offsets and the
// shared macros agree, and records written on one side read back field by
// field on the other (kernels/probe/layout_probe.cl).
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include "rtcl/beam/beam_layouts.hpp"
#include "rtcl/bounds/bounds_layouts.hpp"
#include "rtcl/layouts.hpp"
#include "rtcl/render/render_layouts.hpp"
#include "support/fixtures.hpp"

namespace rtcl::test {
namespace {

struct Entry {
  const char* what;
  cl_uint host;
};

// Byte offset of a member reached by an arbitrary designator, the host twin of
// PROBE_OFFSET in the kernel.
template <class T, class F>
cl_uint offset_of(F field) {
  static T record{};
  return static_cast<cl_uint>(reinterpret_cast<const char*>(field(record)) - reinterpret_cast<const char*>(&record));
}

// The host's values for the entries of kernels/probe/layout_entries.h, the
// list probe_layout walks on the device.
#define RTCL_PROBE_RECORD(T) {"sizeof(" #T ")", sizeof(T)}, {#T " array stride", sizeof(T[2]) / 2},
#define RTCL_PROBE_FIELD(T, member) {#T "." #member, offset_of<T>([](auto& r) { return &r.member; })},
#define RTCL_PROBE_SIZE(NAME, TYPE) {#NAME " (device: sizeof(" #TYPE "))", NAME},
#define RTCL_PROBE_VALUE(EXPR) {#EXPR, static_cast<cl_uint>(EXPR)},
std::vector<Entry> host_layout() {
  return {
#include "probe/layout_entries.h"
  };
}

TEST(LayoutProbe, DeviceSizesAndOffsetsMatchHost) {
  const Device& device = test_device();
  cl::Program program = device.program("probe/layout_probe.cl", {});
  std::vector<Entry> host = host_layout();
  std::vector<cl_uint> out(host.size() + 16, 0xdeadbeefu);
  with_cl_errors([&] {
    cl::Buffer result = device.allocate(out.size() * sizeof(cl_uint), "probe layout");
    cl::Kernel kernel(program, "probe_layout");
    kernel.setArg(0, result);
    device.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(1));
    device.queue().enqueueReadBuffer(result, CL_TRUE, 0, out.size() * sizeof(cl_uint), out.data());
  });
  ASSERT_EQ(out[0], host.size()) << "the kernel and this test list different entries";
  for (std::size_t i = 0; i < host.size(); ++i)
    EXPECT_EQ(out[i + 1], host[i].host) << host[i].what << ": device " << out[i + 1] << ", host " << host[i].host;
}

TEST(LayoutProbe, RecordsWrittenOnOneSideReadBackOnTheOther) {
  const Device& device = test_device();
  cl::Program program = device.program("probe/layout_probe.cl", {});
  // Distinct values in every field, so a shifted field cannot go unnoticed.
  Ray ray{1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f, 8.0f};
  TriangleBlock tri{};
  SphereBlock sphere{};
  Bvh8Node node{};
  std::vector<float> floats = {ray.ox, ray.oy, ray.oz, ray.dx, ray.dy, ray.dz, ray.tmin, ray.tmax};
  std::vector<int> ints;
  for (int vertex = 0; vertex < 3; ++vertex)
    for (int axis = 0; axis < 3; ++axis)
      for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
        floats.push_back(tri.v[vertex][axis][lane] = 100.0f * vertex + 10.0f * axis + lane + 0.5f);
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) ints.push_back(tri.prim[lane] = -3 * (lane + 1));
  for (float* field : {sphere.cx, sphere.cy, sphere.cz, sphere.r})
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane)
      floats.push_back(field[lane] = 1000.0f + static_cast<float>(floats.size()));
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) ints.push_back(sphere.prim[lane] = 500 + lane);
  for (int row = 0; row < 6; ++row)
    for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) floats.push_back(node.bounds[row][lane] = -row * 8.0f - lane);
  for (int lane = 0; lane < RTCL_BLOCK_WIDTH; ++lane) ints.push_back(node.child[lane] = RTCL_LEAF_TRIANGLES(lane));

  std::vector<float> device_floats(floats.size() + 8, -1.0f);
  std::vector<int> device_ints(ints.size() + 8, -1);
  Hit device_hits[2] = {};
  with_cl_errors([&] {
    cl::Buffer rays = device.upload(&ray, sizeof ray, "probe ray");
    cl::Buffer tris = device.upload(&tri, sizeof tri, "probe triangle block");
    cl::Buffer spheres = device.upload(&sphere, sizeof sphere, "probe sphere block");
    cl::Buffer nodes = device.upload(&node, sizeof node, "probe node");
    cl::Buffer float_out = device.allocate(device_floats.size() * sizeof(float), "probe floats");
    cl::Buffer int_out = device.allocate(device_ints.size() * sizeof(int), "probe ints");
    cl::Buffer hit_out = device.allocate(sizeof device_hits, "probe hits");
    // sentinels: whatever the kernel does not write stays -1
    device.queue().enqueueWriteBuffer(float_out, CL_TRUE, 0, device_floats.size() * sizeof(float),
                                      device_floats.data());
    device.queue().enqueueWriteBuffer(int_out, CL_TRUE, 0, device_ints.size() * sizeof(int), device_ints.data());
    cl::Kernel kernel(program, "probe_fields");
    kernel.setArg(0, rays);
    kernel.setArg(1, tris);
    kernel.setArg(2, spheres);
    kernel.setArg(3, nodes);
    kernel.setArg(4, float_out);
    kernel.setArg(5, int_out);
    kernel.setArg(6, hit_out);
    device.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(1));
    device.queue().enqueueReadBuffer(float_out, CL_TRUE, 0, device_floats.size() * sizeof(float),
                                     device_floats.data());
    device.queue().enqueueReadBuffer(int_out, CL_TRUE, 0, device_ints.size() * sizeof(int), device_ints.data());
    device.queue().enqueueReadBuffer(hit_out, CL_TRUE, 0, sizeof device_hits, device_hits);
  });
  for (std::size_t i = 0; i < floats.size(); ++i) EXPECT_EQ(device_floats[i], floats[i]) << "float field " << i;
  EXPECT_EQ(device_floats[floats.size()], -1.0f) << "the kernel wrote more float fields than the host has";
  for (std::size_t i = 0; i < ints.size(); ++i) EXPECT_EQ(device_ints[i], ints[i]) << "int field " << i;
  EXPECT_EQ(device_ints[ints.size()], -1) << "the kernel wrote more int fields than the host has";
  EXPECT_EQ(device_hits[0].t, 1.5f);
  EXPECT_EQ(device_hits[0].u, 0.25f);
  EXPECT_EQ(device_hits[0].v, 0.125f);
  EXPECT_EQ(device_hits[0].prim, -7);
  EXPECT_EQ(device_hits[1].t, 2.5f);
  EXPECT_EQ(device_hits[1].u, 0.5f);
  EXPECT_EQ(device_hits[1].v, 0.375f);
  EXPECT_EQ(device_hits[1].prim, 123456);
}

}  // namespace
}  // namespace rtcl::test
