// The device layer (src/rtcl/device.hpp) and the buffer checks of
// Accel::trace: discovery, selection, adoption of a caller's context, build
// errors, the program cache, and errors that name what the user passed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

#include "rtcl/accel.hpp"
#include "rtcl/device.hpp"
#include "rtcl/cl/program.hpp"
#include "rtcl/cl/upload_consuming.hpp"
#include "rtcl/error.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/scoped_env.hpp"

namespace rtcl::test {
namespace {

// Sets (or, with nullopt, unsets) an environment variable for one scope.
std::string toggle_case(std::string s) {
  for (char& c : s) c = std::isupper(static_cast<unsigned char>(c)) ? std::tolower(c) : std::toupper(c);
  return s;
}

// The square [-1, 1]^2 at z = 0 as two triangles; the ray below hits
// triangle 1 = (v0, v2, v3) at t = 2 with u = 0.625, v = 0.125.
Geometry unit_quad() {
  const float xyz[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const std::uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  return Geometry::from_arrays(xyz, 4, indices, 2, "unit quad");
}
constexpr Ray kQuadRay{0.25f, 0.5f, -2.0f, 0.0f, 0.0f, 1.0f, 0.0f, 1e30f};

void expect_quad_hit(const Hit& hit, const std::string& accel) {
  EXPECT_EQ(hit.prim, 1) << accel;
  EXPECT_FLOAT_EQ(hit.t, 2.0f) << accel;
  EXPECT_NEAR(hit.u, 0.625f, 1e-6f) << accel;
  EXPECT_NEAR(hit.v, 0.125f, 1e-6f) << accel;
}

TEST(Device, ListsAtLeastOneDevice) {
  auto devices = list_devices();
  // Never a skip: a machine without an OpenCL device fails the suite.
  ASSERT_FALSE(devices.empty()) << "no OpenCL device found; install one (Debian: pocl-opencl-icd)";
  for (std::size_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(devices[i].index, i);
    EXPECT_FALSE(devices[i].name.empty());
    EXPECT_FALSE(devices[i].platform.empty());
    EXPECT_GT(devices[i].max_alloc_bytes, 0u);
    EXPECT_GT(devices[i].compute_units, 0u);
  }
}

TEST(Device, OpensByIndex) {
  ScopedEnv env("RTCL_DEVICE", std::nullopt);
  auto devices = list_devices();
  ASSERT_FALSE(devices.empty());
  for (const auto& d : devices) {
    Device device = Device::open(std::to_string(d.index));
    EXPECT_EQ(device.info().index, d.index);
    EXPECT_EQ(device.info().name, d.name);
    EXPECT_EQ(device.info().platform, d.platform);
  }
  EXPECT_EQ(Device::open().info().index, 0u) << "no selector and no RTCL_DEVICE: device 0";
}

TEST(Device, OpensByCaseInsensitiveNameSubstring) {
  ScopedEnv env("RTCL_DEVICE", std::nullopt);
  auto devices = list_devices();
  ASSERT_FALSE(devices.empty());
  const std::string& name = devices[0].name;
  std::string middle = name.substr(name.size() / 4, std::max<std::size_t>(1, name.size() / 2));
  for (const std::string& selector : {toggle_case(middle), toggle_case(devices[0].platform), toggle_case(name)}) {
    Device device = Device::open(selector);
    EXPECT_EQ(device.info().index, 0u) << "selector '" << selector << "': the first match is device 0";
    EXPECT_EQ(device.info().name, name);
  }
}

TEST(Device, BadIndexAndUnknownNameAreErrorsNamingTheSelector) {
  ScopedEnv env("RTCL_DEVICE", std::nullopt);
  std::string bad_index = error_of([] { Device::open("4096"); });
  EXPECT_NE(bad_index.find("4096"), std::string::npos) << bad_index;
  EXPECT_NE(bad_index.find("no such device"), std::string::npos) << bad_index;
  std::string unknown = error_of([] { Device::open("no-such-device-zq9"); });
  EXPECT_NE(unknown.find("Device::open selector \"no-such-device-zq9\": no device name matches"), std::string::npos)
      << unknown;
}

TEST(Device, HonoursRtclDeviceVariable) {
  auto devices = list_devices();
  ASSERT_FALSE(devices.empty());
  {
    ScopedEnv env("RTCL_DEVICE", "no-such-device-zq9");
    std::string message = error_of([] { Device::open(); });
    EXPECT_NE(message.find("RTCL_DEVICE"), std::string::npos) << message;
    EXPECT_NE(message.find("no-such-device-zq9"), std::string::npos) << message;
    EXPECT_EQ(Device::open("0").info().index, 0u) << "an explicit selector wins over RTCL_DEVICE";
  }
  {
    ScopedEnv env("RTCL_DEVICE", "999");
    std::string message = error_of([] { Device::open(); });
    EXPECT_NE(message.find("RTCL_DEVICE \"999\": no such device"), std::string::npos) << message;
  }
  std::size_t last = devices.size() - 1;
  {
    ScopedEnv env("RTCL_DEVICE", std::to_string(last));
    EXPECT_EQ(Device::open().info().index, last);
  }
  {
    ScopedEnv env("RTCL_DEVICE", toggle_case(devices[0].name));
    EXPECT_EQ(Device::open().info().name, devices[0].name);
  }
}

// A context and queue made with the OpenCL C API, as an application has them.
struct RawOpenCl {
  cl_platform_id platform = nullptr;
  cl_device_id device = nullptr;
  cl_context context = nullptr;
  cl_command_queue queue = nullptr;

  explicit RawOpenCl(cl_command_queue_properties properties) {
    const cl::Device& d = test_device().device();
    device = d();
    check_cl(clGetDeviceInfo(device, CL_DEVICE_PLATFORM, sizeof platform, &platform, nullptr), "clGetDeviceInfo");
    cl_context_properties props[] = {CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(platform), 0};
    cl_int status = CL_SUCCESS;
    context = clCreateContext(props, 1, &device, nullptr, nullptr, &status);
    check_cl(status, "clCreateContext");
    queue = clCreateCommandQueue(context, device, properties, &status);
    check_cl(status, "clCreateCommandQueue");
  }
  ~RawOpenCl() { release(); }
  void release() {
    if (queue) clReleaseCommandQueue(queue);
    if (context) clReleaseContext(context);
    queue = nullptr;
    context = nullptr;
  }
};

// Traces kQuadRay through every accel on raw cl_mem buffers of `raw`'s
// context, through a Device adopted from it.
void trace_quad_on_adopted(RawOpenCl& raw, bool release_before_use) {
  Device device = Device::adopt(raw.context, raw.device, raw.queue);
  cl_context context = raw.context;
  cl_command_queue queue = raw.queue;
  // The Device holds its own references: the caller may drop its handles.
  if (release_before_use) {
    clRetainContext(context);  // kept only to create the buffers below
    clRetainCommandQueue(queue);
    raw.release();
  }
  EXPECT_EQ(device.info().name, test_device().info().name);
  EXPECT_EQ(device.context()(), context);
  EXPECT_EQ(device.queue()(), queue);
  for (const std::string& name : accel_names()) {
    auto accel = make_accel(device, name, unit_quad());
    cl_int status = CL_SUCCESS;
    cl_mem rays = clCreateBuffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(Ray),
                                 const_cast<Ray*>(&kQuadRay), &status);
    check_cl(status, "clCreateBuffer");
    cl_mem hits = clCreateBuffer(context, CL_MEM_WRITE_ONLY, sizeof(Hit), nullptr, &status);
    check_cl(status, "clCreateBuffer");
    for (Query query : {Query::closest, Query::any}) {
      cl::Event done = accel->trace(query, rays, hits, 1);
      cl_event wait = done();
      Hit hit{};
      check_cl(clEnqueueReadBuffer(queue, hits, CL_TRUE, 0, sizeof hit, &hit, 1, &wait, nullptr),
               "clEnqueueReadBuffer");
      expect_quad_hit(hit, name);
    }
    clReleaseMemObject(rays);
    clReleaseMemObject(hits);
  }
  if (release_before_use) {
    clReleaseCommandQueue(queue);
    clReleaseContext(context);
  }
}

TEST(Device, AdoptsCallerContextAndQueue) {
  RawOpenCl raw(0);
  trace_quad_on_adopted(raw, false);
  EXPECT_FALSE(Device::adopt(raw.context, raw.device, raw.queue).profiling());
  RawOpenCl profiled(CL_QUEUE_PROFILING_ENABLE);
  EXPECT_TRUE(Device::adopt(profiled.context, profiled.device, profiled.queue).profiling());
}

TEST(Device, AdoptedDeviceOutlivesTheCallersHandles) {
  RawOpenCl raw(0);
  trace_quad_on_adopted(raw, true);
}

TEST(Device, AdoptsOutOfOrderQueue) {
  cl_command_queue_properties supported = 0;
  check_cl(clGetDeviceInfo(test_device().device()(), CL_DEVICE_QUEUE_PROPERTIES, sizeof supported, &supported,
                           nullptr),
           "clGetDeviceInfo");
  // Not every device offers out-of-order queues; the in-order case is above.
  cl_command_queue_properties mode = supported & CL_QUEUE_OUT_OF_ORDER_EXEC_MODE_ENABLE;
  RawOpenCl raw(mode);
  trace_quad_on_adopted(raw, false);
}

TEST(Device, AdoptRejectsNullHandles) {
  RawOpenCl raw(0);
  std::string message = error_of([&] { Device::adopt(nullptr, raw.device, raw.queue); });
  EXPECT_NE(message.find("Device::adopt"), std::string::npos) << message;
  error_of([&] { Device::adopt(raw.context, raw.device, nullptr); });
}

// NVIDIA's compiler ignores #line and reports positions in the assembled
// source ("<kernel>:N:C"); the log then names the original file and line.
TEST(KernelSource, CompilerPositionsInTheAssembledSourceNameTheOriginalFileAndLine) {
  std::filesystem::path root =
      std::filesystem::temp_directory_path() / ("rtcl-lines-" + std::to_string(getpid()));
  std::filesystem::create_directories(root / "k");
  std::ofstream(root / "k" / "main.cl") << "// main line 1\n#include \"k/part.h\"\nint main_line_3;\nint main_line_4;\n";
  std::ofstream(root / "k" / "part.h") << "int part_line_1;\nint part_line_2;\n";
  std::string source;
  {
    ScopedEnv env("RTCL_KERNEL_DIR", root.string());
    source = kernel_source("k/main.cl");
  }
  std::filesystem::remove_all(root);
  // The assembled line numbers of each original line, counted here.
  auto assembled_line_of = [&](const std::string& text) {
    std::size_t at = source.find(text);
    return std::count(source.begin(), source.begin() + static_cast<long>(at), '\n') + 1;
  };
  auto at = [&](const std::string& text) { return "<kernel>:" + std::to_string(assembled_line_of(text)) + ":"; };
  std::string log = at("part_line_2") + "7: error: a\n" + at("main_line_4") + "1: warning: b\n" +
                    "k/main.cl:3:1: note: already named\n<kernel>:999: beyond the source\n";
  EXPECT_EQ(name_source_lines(log, source), "k/part.h:2:7: error: a\nk/main.cl:4:1: warning: b\n"
                                            "k/main.cl:3:1: note: already named\n<kernel>:999: beyond the source\n");
}

// A kernel directory holding one broken file (RTCL_KERNEL_DIR development mode).
class BrokenKernelDir {
 public:
  BrokenKernelDir() : root_(std::filesystem::temp_directory_path() / ("rtcl-broken-" + std::to_string(getpid()))) {
    std::filesystem::create_directories(root_ / "broken");
    std::ofstream(root_ / "broken" / "broken.cl") << "/* line 1 */\n"
                                                   << "kernel void broken(global int* out) {\n"
                                                   << "  out[0] = rtcl_no_such_identifier;\n"
                                                   << "}\n";
  }
  ~BrokenKernelDir() { std::filesystem::remove_all(root_); }
  std::string path() const { return root_.string(); }

 private:
  std::filesystem::path root_;
};

TEST(Device, KernelBuildFailureReportsTheBuildLog) {
  BrokenKernelDir dir;
  ScopedEnv env("RTCL_KERNEL_DIR", dir.path());
  std::string message = error_of([] { test_device().program("broken/broken.cl", {"RTCL_TEST=1"}); });
  EXPECT_NE(message.find("broken/broken.cl"), std::string::npos) << message;
  EXPECT_NE(message.find("-DRTCL_TEST=1"), std::string::npos) << "the options are named: " << message;
  EXPECT_NE(message.find(test_device().info().name), std::string::npos) << message;
  // the compiler's own words, from CL_PROGRAM_BUILD_LOG, pointing at line 3
  EXPECT_NE(message.find("rtcl_no_such_identifier"), std::string::npos) << message;
  EXPECT_NE(message.find("broken/broken.cl:3"), std::string::npos) << message;

  std::string missing = error_of([] { test_device().program("broken/missing.cl", {}); });
  EXPECT_NE(missing.find("broken/missing.cl"), std::string::npos) << missing;
  EXPECT_NE(missing.find("RTCL_KERNEL_DIR"), std::string::npos) << missing;
}

TEST(Device, UnknownEmbeddedKernelIsAnError) {
  ScopedEnv env("RTCL_KERNEL_DIR", std::nullopt);
  std::string message = error_of([] { test_device().program("accel/no_such_structure.cl", {}); });
  EXPECT_NE(message.find("accel/no_such_structure.cl"), std::string::npos) << message;
}

TEST(Device, ProgramCacheReturnsTheSameProgramForTheSameOptions) {
  const Device& device = test_device();
  cl::Program a = device.program("probe/layout_probe.cl", {});
  cl::Program b = device.program("probe/layout_probe.cl", {});
  EXPECT_EQ(a(), b());
  cl::Program c = device.program("probe/layout_probe.cl", {"RTCL_PROBE_VARIANT=1"});
  EXPECT_NE(a(), c()) << "other options, other program";
  EXPECT_EQ(c(), device.program("probe/layout_probe.cl", {"RTCL_PROBE_VARIANT=1"})());
  // Another Device has another context, hence its own cache.
  Device other = Device::open(std::to_string(device.info().index));
  EXPECT_NE(a(), other.program("probe/layout_probe.cl", {})());
}

TEST(Device, OversizedBufferIsAnErrorNamingTheBuffer) {
  const Device& device = test_device();
  std::size_t too_big = device.info().max_alloc_bytes + 1;
  char byte = 0;  // never read: the size check comes first
  std::string upload = error_of([&] { device.upload(&byte, too_big, "oversized test buffer"); });
  EXPECT_NE(upload.find("oversized test buffer"), std::string::npos) << upload;
  EXPECT_NE(upload.find(std::to_string(too_big)), std::string::npos) << upload;
  std::string allocate = error_of([&] { device.allocate(too_big, "oversized scratch"); });
  EXPECT_NE(allocate.find("oversized scratch"), std::string::npos) << allocate;
}

// upload_consuming copies in parts and discards each part's host pages:
// the device copy must equal the data as it was (a copy kept apart), for
// sizes below, at and across part boundaries and off page boundaries.
TEST(Device, ConsumingUploadCopiesEveryPartWhole) {
  const Device& device = test_device();
  constexpr std::size_t kPart = kConsumingUploadPartBytes;
  for (std::size_t bytes : {std::size_t{1}, std::size_t{4097}, kPart, kPart + 1, 2 * kPart + 12345}) {
    std::vector<unsigned char> data(bytes + 3);  // consumed from offset 3: off every page boundary
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<unsigned char>((i * 2654435761u) >> 13);
    const std::vector<unsigned char> expected(data.begin() + 3, data.end());
    cl::Buffer buffer = upload_consuming(device, data.data() + 3, bytes, "consumed test buffer");
    std::vector<unsigned char> back(bytes);
    device.queue().enqueueReadBuffer(buffer, CL_TRUE, 0, bytes, back.data());
    EXPECT_TRUE(back == expected) << bytes << " bytes";
  }
  char byte = 0;  // never read: the size check comes first
  const std::size_t too_big = device.info().max_alloc_bytes + 1;
  std::string message = error_of([&] { upload_consuming(device, &byte, too_big, "oversized consumed buffer"); });
  EXPECT_NE(message.find("oversized consumed buffer"), std::string::npos) << message;
}

TEST(Device, TraceRejectsTooSmallBuffersAndStaysInBounds) {
  const Device& device = test_device();
  constexpr std::size_t n = 37;
  constexpr std::size_t guard = 64;  // hit records after the sub-buffer
  std::vector<Ray> rays(n + guard, kQuadRay);
  const Hit sentinel{-123.0f, -4.0f, -5.0f, 777};
  for (const std::string& name : accel_names()) {
    auto accel = make_accel(device, name, unit_quad());
    with_cl_errors([&] {
      cl::Buffer all_rays = device.upload(rays.data(), rays.size() * sizeof(Ray), "test rays");
      cl::Buffer all_hits = device.allocate((n + guard) * sizeof(Hit), "test hits");
      std::vector<Hit> fill(n + guard, sentinel);
      device.queue().enqueueWriteBuffer(all_hits, CL_TRUE, 0, fill.size() * sizeof(Hit), fill.data());
      // Sub-buffers at offset 0 hold exactly n records (or one fewer).
      cl_buffer_region exact_hits{0, n * sizeof(Hit)}, short_hits{0, (n - 1) * sizeof(Hit)};
      cl_buffer_region exact_rays{0, n * sizeof(Ray)}, short_rays{0, (n - 1) * sizeof(Ray)};
      auto sub = [](cl::Buffer& parent, cl_mem_flags flags, cl_buffer_region& region) {
        return parent.createSubBuffer(flags, CL_BUFFER_CREATE_TYPE_REGION, &region);
      };
      cl::Buffer hits_n = sub(all_hits, CL_MEM_READ_WRITE, exact_hits);
      cl::Buffer hits_short = sub(all_hits, CL_MEM_READ_WRITE, short_hits);
      cl::Buffer rays_n = sub(all_rays, CL_MEM_READ_ONLY, exact_rays);
      cl::Buffer rays_short = sub(all_rays, CL_MEM_READ_ONLY, short_rays);
      for (Query query : {Query::closest, Query::any}) {
        std::string hit_error = error_of([&] { accel->trace(query, rays_n, hits_short, n); });
        EXPECT_NE(hit_error.find("hit buffer holds 36 hits, 37 requested"), std::string::npos) << hit_error;
        EXPECT_NE(hit_error.find(name), std::string::npos) << hit_error;
        std::string ray_error = error_of([&] { accel->trace(query, rays_short, hits_n, n); });
        EXPECT_NE(ray_error.find("ray buffer holds 36 rays, 37 requested"), std::string::npos) << ray_error;
        device.queue().finish();
        std::vector<Hit> after(n + guard);
        device.queue().enqueueReadBuffer(all_hits, CL_TRUE, 0, after.size() * sizeof(Hit), after.data());
        for (std::size_t i = 0; i < after.size(); ++i)
          ASSERT_EQ(after[i].prim, sentinel.prim) << name << ": a rejected trace wrote hit " << i;

        // Exactly n records: every hit written, nothing after them.
        cl::Event done = accel->trace(query, rays_n, hits_n, n);
        std::vector<cl::Event> wait{done};
        device.queue().enqueueReadBuffer(all_hits, CL_TRUE, 0, after.size() * sizeof(Hit), after.data(), &wait);
        for (std::size_t i = 0; i < n; ++i) expect_quad_hit(after[i], name);
        for (std::size_t i = n; i < after.size(); ++i)
          ASSERT_EQ(after[i].t, sentinel.t) << name << ": trace of " << n << " rays wrote hit " << i;
        device.queue().enqueueWriteBuffer(all_hits, CL_TRUE, 0, fill.size() * sizeof(Hit), fill.data());
      }
      // Zero rays is a no-op that still returns an event to wait on.
      cl::Event none = accel->trace(Query::closest, rays_short, hits_short, 0);
      none.wait();
    });
  }
}

}  // namespace
}  // namespace rtcl::test
