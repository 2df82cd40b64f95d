// An application that already owns its OpenCL objects (made with the C API)
// and uses rtcl as its ray-tracing backend: it adopts its context and queue,
// builds a structure over its own arrays, and traces rays from its own cl_mem
// buffers into its own cl_mem buffers, then the same rays from host arrays,
// and a scene of two instances of its mesh.
// Only the public umbrella header. Exits 0 when the answers are right.
#include <rtcl/rtcl.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace {

int failures = 0;

void expect(bool ok, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "FAILED: %s\n", what.c_str());
  ++failures;
}

void check(cl_int status, const char* call) {
  if (status != CL_SUCCESS) throw rtcl::Error(std::string(call) + " failed with " + std::to_string(status));
}

// The first device of the first platform that has one.
void first_device(cl_platform_id* platform, cl_device_id* device) {
  cl_uint platform_count = 0;
  check(clGetPlatformIDs(0, nullptr, &platform_count), "clGetPlatformIDs");
  std::vector<cl_platform_id> platforms(platform_count);
  check(clGetPlatformIDs(platform_count, platforms.data(), nullptr), "clGetPlatformIDs");
  for (cl_platform_id p : platforms) {
    if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 1, device, nullptr) == CL_SUCCESS) {
      *platform = p;
      return;
    }
  }
  throw rtcl::Error("no OpenCL device");
}

}  // namespace

int main() try {
  cl_platform_id platform = nullptr;
  cl_device_id device = nullptr;
  first_device(&platform, &device);
  cl_int status = CL_SUCCESS;
  cl_context_properties properties[] = {CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(platform), 0};
  cl_context context = clCreateContext(properties, 1, &device, nullptr, nullptr, &status);
  check(status, "clCreateContext");
  cl_command_queue queue = clCreateCommandQueue(context, device, 0, &status);
  check(status, "clCreateCommandQueue");

  rtcl::Device backend = rtcl::Device::adopt(context, device, queue);

  // The square [-1, 1]^2 at z = 0, as the application stores it.
  const float xyz[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  const std::uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  rtcl::Geometry quad = rtcl::Geometry::from_arrays(xyz, 4, indices, 2, "consumer quad");
  std::vector<std::string> names = rtcl::accel_names();
  std::string name = std::find(names.begin(), names.end(), "bvh") != names.end() ? "bvh" : names.front();
  auto accel = rtcl::make_accel(backend, name, quad);

  // Ray records: origin, direction, [tmin, tmax] (32 bytes each).
  const float inf = INFINITY;
  const rtcl::Ray rays[3] = {
      {0.25f, 0.5f, -2.0f, 0.0f, 0.0f, 1.0f, 0.0f, inf},  // hits triangle 1 at t = 2
      {3.0f, 0.0f, -2.0f, 0.0f, 0.0f, 1.0f, 0.0f, inf},   // passes beside the quad
      {0.25f, 0.5f, -2.0f, 0.0f, 0.0f, 1.0f, 0.0f, 1.5f}, // stops short of it
  };
  cl_mem ray_buffer = clCreateBuffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof rays,
                                     const_cast<rtcl::Ray*>(rays), &status);
  check(status, "clCreateBuffer");
  cl_mem hit_buffer = clCreateBuffer(context, CL_MEM_WRITE_ONLY, 3 * sizeof(rtcl::Hit), nullptr, &status);
  check(status, "clCreateBuffer");

  for (rtcl::Query query : {rtcl::Query::closest, rtcl::Query::any}) {
    std::string label = name + (query == rtcl::Query::closest ? " closest" : " any");
    accel->trace(query, ray_buffer, hit_buffer, 3);
    check(clFinish(queue), "clFinish");
    rtcl::Hit hits[3];
    check(clEnqueueReadBuffer(queue, hit_buffer, CL_TRUE, 0, sizeof hits, hits, 0, nullptr, nullptr),
          "clEnqueueReadBuffer");
    expect(hits[0].prim == 1 && hits[0].t == 2.0f, label + ": ray 0 hits triangle 1 at t = 2");
    expect(std::abs(hits[0].u - 0.625f) < 1e-6f && std::abs(hits[0].v - 0.125f) < 1e-6f,
           label + ": ray 0 barycentrics (0.625, 0.125)");
    expect(hits[1].prim == -1 && std::isinf(hits[1].t), label + ": ray 1 misses");
    expect(hits[2].prim == -1 && std::isinf(hits[2].t), label + ": ray 2 ends before the quad");
  }

  // The same rays from host arrays: records, and separate origin and
  // direction arrays with tmax.
  std::vector<rtcl::Hit> host_hits = accel->intersect(std::span<const rtcl::Ray>(rays, 3));
  expect(host_hits[0].prim == 1 && host_hits[0].t == 2.0f && host_hits[1].prim == -1 && host_hits[2].prim == -1,
         name + " host records: hit, miss, miss");
  const float origins[] = {0.25f, 0.5f, -2.0f, 3.0f, 0.0f, -2.0f, 0.25f, 0.5f, -2.0f};
  const float directions[] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float tmax[] = {inf, inf, 1.5f};
  std::vector<std::uint8_t> blocked = accel->occluded(rtcl::Rays(origins, directions, {}, tmax));
  expect(blocked == std::vector<std::uint8_t>{1, 0, 0}, name + " host arrays: occluded, free, free");

  // The quad as a mesh of a scene, placed twice: as it is and moved by
  // (10, 0, 0), each instance reporting its user id.
  {
    rtcl::Scene scene(backend);
    rtcl::MeshId mesh = scene.add_mesh(quad);
    scene.add_instance({mesh, rtcl::Transform::identity(), std::nullopt, 7u});
    scene.add_instance({mesh, rtcl::Transform::translate(10, 0, 0), std::nullopt, 8u});
    rtcl::CommitStats built = scene.commit();
    expect(built.bottom_levels_built == 1 && built.top_level_built, "scene: one bottom level and the top level");
    const rtcl::Ray scene_rays[2] = {{0.25f, 0.5f, -2.0f, 0.0f, 0.0f, 1.0f, 0.0f, inf},
                                     {10.25f, 0.5f, -2.0f, 0.0f, 0.0f, 1.0f, 0.0f, inf}};
    std::vector<std::uint32_t> ids(2);
    std::vector<rtcl::Hit> scene_hits = scene.intersect(std::span<const rtcl::Ray>(scene_rays, 2), ids);
    expect(scene_hits[0].prim == 1 && scene_hits[1].prim == 1 && scene_hits[1].t == 2.0f,
           "scene: both instances hit triangle 1 at t = 2");
    expect(ids[0] == 7u && ids[1] == 8u, "scene: instance ids 7 and 8");
  }

  // A hit buffer one record short is refused before anything runs.
  cl_mem short_hits = clCreateBuffer(context, CL_MEM_WRITE_ONLY, 2 * sizeof(rtcl::Hit), nullptr, &status);
  check(status, "clCreateBuffer");
  bool refused = false;
  try {
    accel->trace(rtcl::Query::closest, ray_buffer, short_hits, 3);
  } catch (const rtcl::Error&) {
    refused = true;
  }
  expect(refused, "a too small hit buffer is an rtcl::Error");

  clReleaseMemObject(short_hits);
  clReleaseMemObject(hit_buffer);
  clReleaseMemObject(ray_buffer);
  accel.reset();
  clReleaseCommandQueue(queue);
  clReleaseContext(context);
  if (failures) return 1;
  std::printf("rtcl consumer: %s on %s: ok\n", name.c_str(), backend.info().name.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "rtcl consumer: %s\n", e.what());
  return 1;
}
