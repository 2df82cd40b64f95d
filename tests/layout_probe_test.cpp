// The device compiler lays out the shared records (kernels/shared/layouts.h)
// exactly as the host compiler does: sizes, strides, field offsets and the
// shared macros agree, and records written on one side read back field by
// field on the other (kernels/probe/layout_probe.cl).
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include "rtcl/layouts.hpp"
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

// Same entries, same order as probe_layout in kernels/probe/layout_probe.cl.
std::vector<Entry> host_layout() {
  return {
      {"sizeof(Ray)", sizeof(Ray)},
      {"Ray array stride", sizeof(Ray[2]) / 2},
      {"Ray.ox", offsetof(Ray, ox)},
      {"Ray.oy", offsetof(Ray, oy)},
      {"Ray.oz", offsetof(Ray, oz)},
      {"Ray.dx", offsetof(Ray, dx)},
      {"Ray.dy", offsetof(Ray, dy)},
      {"Ray.dz", offsetof(Ray, dz)},
      {"Ray.tmin", offsetof(Ray, tmin)},
      {"Ray.tmax", offsetof(Ray, tmax)},
      {"sizeof(Hit)", sizeof(Hit)},
      {"Hit array stride", sizeof(Hit[2]) / 2},
      {"Hit.t", offsetof(Hit, t)},
      {"Hit.u", offsetof(Hit, u)},
      {"Hit.v", offsetof(Hit, v)},
      {"Hit.prim", offsetof(Hit, prim)},
      {"sizeof(TriangleBlock)", sizeof(TriangleBlock)},
      {"TriangleBlock array stride", sizeof(TriangleBlock[2]) / 2},
      {"TriangleBlock.v", offsetof(TriangleBlock, v)},
      {"TriangleBlock.v[1][0][0]", offset_of<TriangleBlock>([](auto& r) { return &r.v[1][0][0]; })},
      {"TriangleBlock.v[0][1][0]", offset_of<TriangleBlock>([](auto& r) { return &r.v[0][1][0]; })},
      {"TriangleBlock.v[2][2][7]", offset_of<TriangleBlock>([](auto& r) { return &r.v[2][2][7]; })},
      {"TriangleBlock.prim", offsetof(TriangleBlock, prim)},
      {"sizeof(SphereBlock)", sizeof(SphereBlock)},
      {"SphereBlock array stride", sizeof(SphereBlock[2]) / 2},
      {"SphereBlock.cx", offsetof(SphereBlock, cx)},
      {"SphereBlock.cy", offsetof(SphereBlock, cy)},
      {"SphereBlock.cz", offsetof(SphereBlock, cz)},
      {"SphereBlock.r", offsetof(SphereBlock, r)},
      {"SphereBlock.prim", offsetof(SphereBlock, prim)},
      {"sizeof(Bvh8Node)", sizeof(Bvh8Node)},
      {"Bvh8Node array stride", sizeof(Bvh8Node[2]) / 2},
      {"Bvh8Node.bounds", offsetof(Bvh8Node, bounds)},
      {"Bvh8Node.bounds[3][0]", offset_of<Bvh8Node>([](auto& r) { return &r.bounds[3][0]; })},
      {"Bvh8Node.bounds[5][7]", offset_of<Bvh8Node>([](auto& r) { return &r.bounds[5][7]; })},
      {"Bvh8Node.child", offsetof(Bvh8Node, child)},
      {"RTCL_BLOCK_WIDTH", RTCL_BLOCK_WIDTH},
      {"RTCL_CHILD_EMPTY", static_cast<cl_uint>(RTCL_CHILD_EMPTY)},
      {"RTCL_LEAF_TRIANGLES(5)", static_cast<cl_uint>(RTCL_LEAF_TRIANGLES(5))},
      {"RTCL_LEAF_SPHERES(5)", static_cast<cl_uint>(RTCL_LEAF_SPHERES(5))},
  };
}

template <class T>
cl::Buffer two_records(const Device& device, const T& record, const char* what) {
  T pair[2] = {record, record};
  return device.upload(pair, sizeof pair, what);
}

TEST(LayoutProbe, DeviceSizesAndOffsetsMatchHost) {
  const Device& device = test_device();
  cl::Program program = device.program("probe/layout_probe.cl", {});
  std::vector<Entry> host = host_layout();
  std::vector<cl_uint> out(host.size() + 16, 0xdeadbeefu);
  with_cl_errors([&] {
    cl::Buffer rays = two_records(device, Ray{}, "probe rays");
    cl::Buffer hits = two_records(device, Hit{}, "probe hits");
    cl::Buffer tris = two_records(device, TriangleBlock{}, "probe triangle blocks");
    cl::Buffer spheres = two_records(device, SphereBlock{}, "probe sphere blocks");
    cl::Buffer nodes = two_records(device, Bvh8Node{}, "probe nodes");
    cl::Buffer result = device.allocate(out.size() * sizeof(cl_uint), "probe layout");
    cl::Kernel kernel(program, "probe_layout");
    kernel.setArg(0, rays);
    kernel.setArg(1, hits);
    kernel.setArg(2, tris);
    kernel.setArg(3, spheres);
    kernel.setArg(4, nodes);
    kernel.setArg(5, result);
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
