// Scenes too large for the host's memory during the build, or for the
// device, are refused before the build allocates: one error naming both
// sizes (rtcl/accel/build_memory.hpp). The limits are injected (arguments,
// RTCL_MAX_HOST_BYTES), so that no test needs a large scene.
#include "rtcl/accel/build_memory.hpp"

#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cstdint>
#include <fstream>
#include <string>

#include "rtcl/accel.hpp"
#include "rtcl/scene/procedural.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/scoped_env.hpp"

namespace rtcl::test {
namespace {

const BuildFootprint footprint{100.0, 60.0, 40.0};  // host peak, device total, largest buffer: bytes per primitive

TEST(BuildMemory, RefusalsNameBothSizes) {
  // 1000 primitives: 100,000 host bytes, 60,000 device bytes, a 40,000-byte buffer.
  EXPECT_EQ(error_of([] { check_build_memory(footprint, 1000, "make_accel", 100000, 40000, 60000, "dev"); }), "");
  EXPECT_EQ(error_of([] { check_build_memory(footprint, 1000, "make_accel", 99999, 1 << 30, 1 << 30, "dev"); }),
            "make_accel (1000 primitives): the build needs about 100000 bytes of host memory at its peak, more than "
            "the 99999 bytes available (MemAvailable, the address-space limit or RTCL_MAX_HOST_BYTES)");
  EXPECT_EQ(error_of([] { check_build_memory(footprint, 1000, "make_accel", 1 << 30, 39999, 1 << 30, "dev"); }),
            "make_accel (1000 primitives): its largest buffer needs about 40000 bytes, more than the largest buffer "
            "dev allows (39999 bytes, CL_DEVICE_MAX_MEM_ALLOC_SIZE)");
  EXPECT_EQ(error_of([] { check_build_memory(footprint, 1000, "make_accel", 1 << 30, 1 << 30, 59999, "dev"); }),
            "make_accel (1000 primitives): the structure needs about 60000 bytes on the device, more than the "
            "global memory of dev (59999 bytes)");
}

// On a CPU device the structure's buffers are host memory too.
TEST(BuildMemory, ACpuDeviceAddsItsBuffersToTheHostPeak) {
  EXPECT_EQ(error_of([] { check_build_memory(footprint, 1000, "m", 160000, 1 << 30, 1 << 30, "cpu", true); }), "");
  std::string e = error_of([] { check_build_memory(footprint, 1000, "m", 159999, 1 << 30, 1 << 30, "cpu", true); });
  EXPECT_NE(e.find("needs about 160000 bytes of host memory at its peak, more than the 159999 bytes"),
            std::string::npos)
      << e;
}

TEST(BuildMemory, HugeCountsDoNotOverflow) {
  const std::size_t most = SIZE_MAX / 2;
  std::string e = error_of([&] { check_build_memory(footprint, most, "m", SIZE_MAX - 1, SIZE_MAX, SIZE_MAX, "d"); });
  EXPECT_NE(e.find("bytes of host memory"), std::string::npos) << e;
}

TEST(BuildMemory, TheEnvironmentLowersTheHostLimit) {
  const std::size_t machine = available_host_bytes();
  EXPECT_GT(machine, std::size_t(1) << 20) << "MemAvailable read";
  {
    ScopedEnv host("RTCL_MAX_HOST_BYTES", "123456");
    EXPECT_EQ(available_host_bytes(), 123456u);
  }
  for (const char* bad : {"lots", "-5", "0", "12k"}) {
    ScopedEnv host("RTCL_MAX_HOST_BYTES", bad);
    EXPECT_EQ(error_of([] { available_host_bytes(); }),
              std::string("RTCL_MAX_HOST_BYTES='") + bad + "': expected a positive number of bytes");
  }
}

// An address-space limit (prlimit --as, ulimit -v) bounds what a build may
// still map: the limit less what the process maps now.
TEST(BuildMemory, TheAddressSpaceLimitBoundsTheHostLimit) {
  rlimit saved{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &saved), 0);
  const std::size_t margin = std::size_t(256) << 20;
  std::ifstream status("/proc/self/status");
  std::string line;
  std::size_t mapped = 0;
  while (std::getline(status, line))
    if (line.rfind("VmSize:", 0) == 0) mapped = std::stoull(line.substr(7)) * 1024;
  ASSERT_GT(mapped, 0u);
  if (saved.rlim_max != RLIM_INFINITY && saved.rlim_max < mapped + margin) GTEST_SKIP() << "hard limit too low";
  rlimit lowered = saved;
  lowered.rlim_cur = mapped + margin;
  ASSERT_EQ(setrlimit(RLIMIT_AS, &lowered), 0);
  const std::size_t available = available_host_bytes();
  ASSERT_EQ(setrlimit(RLIMIT_AS, &saved), 0);
  EXPECT_LE(available, margin);
  EXPECT_GE(available, margin / 2) << "the process mapped little between the two readings";
}

// Every structure refuses before building when the host cannot hold the
// build: the message names the structure, the scene and both sizes.
TEST(BuildMemory, EveryStructureChecksTheHostBeforeBuilding) {
  Device device = Device::open();
  Geometry soup = random_soup(1000, 3);
  soup.source = "a soup";
  ScopedEnv host("RTCL_MAX_HOST_BYTES", "1000");
  for (const std::string& name : accel_names()) {
    std::string e = error_of([&] { make_accel(device, name, soup); });
    EXPECT_NE(e.find("make_accel name \"" + name + "\" over a soup (1000 primitives): the build needs about "),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("more than the 1000 bytes available"), std::string::npos) << e;
  }
}

// A scene well within the limit is built by every structure.
TEST(BuildMemory, AFittingSceneBuildsUnderATightButSufficientLimit) {
  Device device = Device::open();
  Geometry surface = tessellated_surface(20000);
  ScopedEnv host("RTCL_MAX_HOST_BYTES", std::to_string(std::size_t(64) << 20).c_str());
  for (const std::string& name : accel_names())
    EXPECT_EQ(error_of([&] { make_accel(device, name, surface); }), "") << name;
}

}  // namespace
}  // namespace rtcl::test
