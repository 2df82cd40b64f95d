// Time to give every MPI rank the scene, as `rtcl render --scene-from root`
// does (src/cli/mpi/mpi_render.cpp): rank 0 encodes a scene of one random
// triangle soup mesh (scene_to_bytes), every rank enters a barrier, then
// broadcast_bytes, then the receivers decode it (scene_from_bytes). The
// slowest rank's time counts. Prints one Markdown table; a plain MPI
// program, not a Google Benchmark suite.
//
//   mpirun -np 2 build/bench/rtcl_mpi_broadcast_bench [REPEATS] [TRIANGLES...]
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "mpi/mpi_world.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/procedural.hpp"
#include "rtcl/scene/scene_bytes.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

rtcl::SceneDescription soup_scene(std::size_t triangles) {
  rtcl::Geometry g = rtcl::random_triangle_soup(triangles);
  rtcl::SceneDescription scene = rtcl::default_scene();
  scene.meshes.clear();
  scene.spheres.clear();
  rtcl::SceneMesh mesh;
  mesh.name = "soup";
  rtcl::MeshShape& shape = mesh.edit_shape();
  shape.vertices = std::move(g.vertices);
  shape.triangles = std::move(g.triangles);
  shape.materials.assign(shape.triangles.size(), 0);
  scene.meshes.push_back(std::move(mesh));
  return scene;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  try {
    rtcl::cli::MpiWorld world;
    int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
    std::vector<std::size_t> sizes;
    for (int i = 2; i < argc; ++i) sizes.push_back(std::strtoull(argv[i], nullptr, 10));
    if (sizes.empty()) sizes = {1000, 16000, 256000, 1000000, 4000000};
    if (world.rank == 0)
      std::printf("%d ranks on %s; median of %d\n\n| triangles | MiB | encode ms | broadcast ms | decode ms | "
                  "broadcast MiB/s |\n|---:|---:|---:|---:|---:|---:|\n",
                  world.size, world.host.c_str(), repeats);
    for (std::size_t n : sizes) {
      std::vector<double> encode, bcast, decode;
      std::size_t bytes_size = 0;
      for (int r = 0; r < repeats; ++r) {
        std::vector<std::byte> bytes;
        double encode_ms = 0.0;
        if (world.rank == 0) {
          rtcl::SceneDescription scene = soup_scene(n);
          Clock::time_point t = Clock::now();
          bytes = rtcl::scene_to_bytes(scene);
          encode_ms = ms_since(t);
        }
        rtcl::cli::check_mpi(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier");
        Clock::time_point t = Clock::now();
        rtcl::cli::broadcast_bytes(bytes, 0);
        double local[2] = {ms_since(t), 0.0};
        if (world.rank != 0) {
          Clock::time_point d = Clock::now();
          rtcl::SceneDescription back = rtcl::scene_from_bytes(bytes, "broadcast");
          local[1] = ms_since(d);
        }
        double slowest[2] = {0.0, 0.0};
        rtcl::cli::check_mpi(MPI_Reduce(local, slowest, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD), "MPI_Reduce");
        encode.push_back(encode_ms);
        bcast.push_back(slowest[0]);
        decode.push_back(slowest[1]);
        bytes_size = bytes.size();
      }
      if (world.rank == 0) {
        double mib = bytes_size / 1048576.0, b = median(bcast);
        std::printf("| %zu | %.2f | %.2f | %.2f | %.2f | %.0f |\n", n, mib, median(encode), b, median(decode),
                    b > 0.0 ? mib / (b * 1e-3) : 0.0);
        std::fflush(stdout);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rtcl_mpi_broadcast_bench: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
