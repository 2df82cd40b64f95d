// Resource limits: a job larger than the device allows (largest buffer,
// global memory) is refused before its upload with both numbers; the limits
// can be lowered with RTCL_MAX_ALLOC_BYTES / RTCL_MAX_GLOBAL_BYTES; device
// out-of-memory codes become errors that say what to do.
#include "rtcl/cl/device_limits.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rtcl/accel.hpp"
#include "rtcl/opencl.hpp"
#include "rtcl/io/ray_file.hpp"
#include "support/cli_run.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/scoped_env.hpp"

namespace rtcl::test {
namespace {

// device.allocated_bytes() once the buffers released so far are freed: a
// driver may free a buffer that a finished command still referenced a
// little later, on a thread of its own (PoCL does, on a loaded machine;
// Device::check_fits waits for it likewise). After the queue finishes,
// waits (up to 2 s) for the count to equal `expected`, or without one for
// the count to stay the same for 50 ms.
std::size_t settled_allocated_bytes(const Device& device, std::optional<std::size_t> expected = std::nullopt) {
  device.queue().finish();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  std::size_t bytes = device.allocated_bytes();
  auto unchanged_since = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < deadline) {
    if (expected ? bytes == *expected
                 : std::chrono::steady_clock::now() - unchanged_since >= std::chrono::milliseconds(50))
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const std::size_t now = device.allocated_bytes();
    if (now != bytes) unchanged_since = std::chrono::steady_clock::now();
    bytes = now;
  }
  return bytes;
}

// Sets an environment variable for one scope.
TEST(DeviceLimits, RefusalsGiveBothNumbers) {
  DeviceLimits limits{1000, 5000};
  EXPECT_EQ(error_of([&] { check_allocation(limits, 1000, 3999, "nodes", "dev"); }), "");
  std::string e = error_of([&] { check_allocation(limits, 1001, 0, "nodes", "dev"); });
  EXPECT_EQ(e, "nodes: 1001 bytes exceed the largest buffer dev allows (1000 bytes)");
  e = error_of([&] { check_allocation(limits, 1000, 4001, "rays", "dev"); });
  EXPECT_EQ(e, "rays: 1000 bytes, with the 4001 bytes rtcl already holds there, exceed the global memory of dev "
               "(5000 bytes)");
}

TEST(DeviceLimits, EnvironmentOnlyLowersLimits) {
  {
    ScopedEnv alloc("RTCL_MAX_ALLOC_BYTES", "4096");
    ScopedEnv global("RTCL_MAX_GLOBAL_BYTES", "999999999999999");
    DeviceLimits l = limits_with_overrides({1 << 20, 1 << 30});
    EXPECT_EQ(l.max_alloc_bytes, 4096u);
    EXPECT_EQ(l.global_mem_bytes, std::size_t(1) << 30) << "a larger value never raises a limit";
  }
  for (const char* bad : {"lots", "-5", "0", "12k"}) {
    ScopedEnv alloc("RTCL_MAX_ALLOC_BYTES", bad);
    std::string e = error_of([] { limits_with_overrides({1 << 20, 1 << 30}); });
    EXPECT_NE(e.find(std::string("RTCL_MAX_ALLOC_BYTES='") + bad + "': expected a positive number of bytes"),
              std::string::npos)
        << e;
  }
}

TEST(DeviceLimits, AStructureLargerThanTheLargestBufferIsRefused) {
  ScopedEnv alloc("RTCL_MAX_ALLOC_BYTES", "4096");
  Device device = Device::open();
  EXPECT_EQ(device.info().max_alloc_bytes, 4096u);
  Geometry soup = random_soup(1000, 3);
  for (const std::string& name : accel_names()) {
    std::string e = error_of([&] { make_accel(device, name, soup); });
    // the device layer's message, or a structure's own refusal before any
    // work (the grid checks its cell offsets first): both give both numbers
    EXPECT_NE(e.find("largest buffer"), std::string::npos) << name << ": " << e;
    EXPECT_NE(e.find("4096 bytes"), std::string::npos) << name << ": " << e;
  }
}

// Live buffers count against global memory until they are released.
TEST(DeviceLimits, GlobalMemoryCountsLiveBuffers) {
  ScopedEnv global("RTCL_MAX_GLOBAL_BYTES", "1000000");
  Device device = Device::open();
  EXPECT_EQ(device.info().global_mem_bytes, 1000000u);
  std::string e;
  {
    cl::Buffer first = device.allocate(600000, "first");
    e = error_of([&] { device.allocate(600000, "second"); });
    EXPECT_EQ(e, "second: 600000 bytes, with the 600000 bytes rtcl already holds there, exceed the global memory "
                 "of " + device.info().name + " (1000000 bytes)");
  }
  EXPECT_EQ(error_of([&] { device.allocate(600000, "after release"); }), "") << "the first buffer was released";
}

// Device::allocated_bytes: the live buffers allocated through a device and
// its copies, each gone from the count once released.
TEST(DeviceLimits, AllocatedBytesCountLiveBuffers) {
  Device device = Device::open();
  EXPECT_EQ(device.allocated_bytes(), 0u) << "a device just opened holds no buffer";
  {
    cl::Buffer first = device.allocate(600000, "first");
    const Device copy = device;
    const std::vector<unsigned char> data(1000, 7);
    cl::Buffer second = copy.upload(data.data(), data.size(), "second");
    EXPECT_EQ(device.allocated_bytes(), 601000u);
    EXPECT_EQ(copy.allocated_bytes(), 601000u) << "copies share one count";
  }
  EXPECT_EQ(device.allocated_bytes(), 0u) << "both buffers were released";
}

// Repeated queries on host arrays hold no more device buffers after their
// first call than after it (the first call of a kind may keep buffers for
// the next: the ray sort's), in both host-array ways and over several
// batches (a 64 KiB largest buffer: 2048 rays a batch); a structure's
// buffers leave with it.
TEST(DeviceLimits, HostArrayQueriesLeaveNoDeviceBuffersBehind) {
  for (const bool copy : {false, true}) {
    SCOPED_TRACE(copy ? "RTCL_HOST_ARRAYS=copy" : "host arrays shared on CPU devices");
    ScopedEnv host_arrays("RTCL_HOST_ARRAYS", copy ? std::optional<std::string>("copy") : std::nullopt);
    ScopedEnv alloc("RTCL_MAX_ALLOC_BYTES", "65536");
    Device device = Device::open();
    Geometry soup = random_soup(100, 5);
    std::vector<Ray> rays = random_rays(soup, 5000, 9);
    std::vector<glm::vec3> points;
    for (const Ray& r : rays) points.emplace_back(r.ox, r.oy, r.oz);
    {
      auto bvh = make_accel(device, "bvh", soup);
      EXPECT_GE(device.allocated_bytes(), bvh->stats().device_bytes) << "the structure is on the device";
      std::vector<Hit> hits(rays.size());
      auto calls = [&] {
        for (Coherence coherence : {Coherence::incoherent, Coherence::coherent, Coherence::scattered})
          for (Query query : {Query::closest, Query::any}) bvh->trace(query, rays, hits, coherence);
        bvh->count(rays);
        bvh->all_hits(rays, 4);
        bvh->closest_points(points);
      };
      calls();
      const std::size_t after_first = settled_allocated_bytes(device);
      for (int i = 0; i < 5; ++i) calls();
      EXPECT_EQ(settled_allocated_bytes(device, after_first), after_first);
    }
    EXPECT_EQ(settled_allocated_bytes(device, 0), 0u) << "the structure's buffers left with it";
  }
}

TEST(DeviceLimits, OutOfMemoryCodesSayWhatToDo) {
  for (int code : {CL_MEM_OBJECT_ALLOCATION_FAILURE, CL_OUT_OF_RESOURCES}) {
    std::string e = error_of([&] { with_cl_errors([&] { throw cl::Error(code, "clEnqueueNDRangeKernel"); }); });
    EXPECT_NE(e.find("clEnqueueNDRangeKernel failed: " + std::string(cl_error_name(code))), std::string::npos) << e;
    EXPECT_NE(e.find("the device ran out of memory"), std::string::npos) << e;
  }
}

TEST(DeviceLimits, TraceRefusesARaySetTooLargeForTheDeviceBeforeUploading) {
  TempDir dir;
  dir.write("mesh.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  std::vector<Ray> rays(400, Ray{0.2f, 0.2f, -1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 10.0f});
  write_rays(dir.file("in.rays"), rays);
  CliRun run = run_cli(dir, {"trace", "mesh.obj", "in.rays", "-o", "out.hits"}, "RTCL_MAX_ALLOC_BYTES=8192");
  expect_failure(run, "ray buffer for in.rays: 12800 bytes exceed the largest buffer", dir, "out.hits");
  EXPECT_NE(run.err.find("allows (8192 bytes)"), std::string::npos) << run.err;
  EXPECT_EQ(run.out.find("accel:"), std::string::npos) << "refused before the structure was built: " << run.out;
  run = run_cli(dir, {"trace", "mesh.obj", "in.rays", "-o", "out.hits"}, "RTCL_MAX_GLOBAL_BYTES=10000");
  expect_failure(run, "exceed the global memory of", dir, "out.hits");
}

}  // namespace
}  // namespace rtcl::test
