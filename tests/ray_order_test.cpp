// Host ray orders (src/rtcl/render/ray_order.cpp): all are permutations,
// the tile order matches the renderer's device order and keeps each group of
// 8 in one tile row, the packet-tile order makes each group of 8 a 4x2
// block, and the Morton order makes consecutive rays alike.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "rtcl/error.hpp"
#include "rtcl/render/ray_order.hpp"

namespace rtcl::test {
namespace {

bool is_permutation_of_iota(std::vector<std::uint32_t> order) {
  std::sort(order.begin(), order.end());
  for (std::size_t i = 0; i < order.size(); ++i)
    if (order[i] != i) return false;
  return true;
}

TEST(RayOrder, TileOrdersCoverEveryPixelOnce) {
  for (auto [w, h] : {std::pair{1024u, 1024u}, {13u, 7u}, {8u, 8u}, {1u, 1u}, {0u, 5u}, {33u, 17u}})
    for (bool packets : {false, true}) {
      SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + (packets ? " packet tiles" : " tiles"));
      auto order = packets ? packet_tile_order(w, h) : tile_order(w, h);
      ASSERT_EQ(order.size(), std::size_t{w} * h);
      EXPECT_TRUE(is_permutation_of_iota(order));
    }
}

TEST(RayOrder, TileOrderGroupsOfEightAreOneTileRow) {
  const std::uint32_t w = 64, h = 40;
  auto order = tile_order(w, h);
  for (std::size_t g = 0; g < order.size(); g += 8) {
    std::uint32_t y = order[g] / w, x0 = order[g] % w;
    EXPECT_EQ(x0 % 8, 0u) << "group " << g / 8;
    for (std::uint32_t k = 0; k < 8; ++k) {
      EXPECT_EQ(order[g + k] / w, y) << "group " << g / 8;
      EXPECT_EQ(order[g + k] % w, x0 + k) << "group " << g / 8;
    }
  }
  // the first 64 rays are the top-left 8x8 tile
  for (std::uint32_t i = 0; i < 64; ++i) EXPECT_EQ(order[i], (i / 8) * w + i % 8);
}

// Away from the edges each group of eight is a 4x2 block, row by row, and
// each run of 64 is one 8x8 tile, its blocks in rows.
TEST(RayOrder, PacketTileOrderGroupsOfEightAre4x2Blocks) {
  const std::uint32_t w = 64, h = 40;
  auto order = packet_tile_order(w, h);
  for (std::size_t g = 0; g < order.size(); g += 8) {
    const std::uint32_t y0 = order[g] / w, x0 = order[g] % w;
    EXPECT_EQ(x0 % 4, 0u) << "group " << g / 8;
    EXPECT_EQ(y0 % 2, 0u) << "group " << g / 8;
    for (std::uint32_t k = 0; k < 8; ++k) EXPECT_EQ(order[g + k], (y0 + k / 4) * w + x0 + k % 4) << "group " << g / 8;
  }
  for (std::uint32_t i = 0; i < 64; ++i) {
    const std::uint32_t block = i / 8, lane = i % 8;
    EXPECT_EQ(order[i], (2 * (block / 2) + lane / 4) * w + 4 * (block % 2) + lane % 4) << i;
  }
}

std::vector<Ray> random_rays_in_unit_cube(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::vector<Ray> rays(count);
  for (Ray& r : rays) r = {unit(rng), unit(rng), unit(rng), normal(rng), normal(rng), normal(rng), 0.0f, 1.0f};
  return rays;
}

float mean_step(const std::vector<Ray>& rays, bool direction) {
  double sum = 0.0;
  for (std::size_t i = 1; i < rays.size(); ++i) {
    const Ray &a = rays[i - 1], &b = rays[i];
    glm::vec3 pa = direction ? glm::normalize(glm::vec3(a.dx, a.dy, a.dz)) : glm::vec3(a.ox, a.oy, a.oz);
    glm::vec3 pb = direction ? glm::normalize(glm::vec3(b.dx, b.dy, b.dz)) : glm::vec3(b.ox, b.oy, b.oz);
    sum += glm::length(pa - pb);
  }
  return static_cast<float>(sum / static_cast<double>(rays.size() - 1));
}

TEST(RayOrder, MortonOrderIsAStablePermutationThatGroupsSimilarRays) {
  const Aabb bounds{glm::vec3(0.0f), glm::vec3(1.0f)};
  std::vector<Ray> rays = random_rays_in_unit_cube(100000, 3);
  auto order = morton_order(rays, bounds);
  ASSERT_EQ(order.size(), rays.size());
  EXPECT_TRUE(is_permutation_of_iota(order));
  std::vector<Ray> sorted = gather<Ray>(rays, order);
  for (std::size_t i = 1; i < sorted.size(); ++i)
    ASSERT_LE(ray_morton_key(sorted[i - 1], bounds), ray_morton_key(sorted[i], bounds));
  // Random order: mean origin step ~0.66. Sorted (origin-major key): ~0.02.
  EXPECT_LT(mean_step(sorted, false) * 20.0f, mean_step(rays, false));
  // Rays from one origin (e.g. a bounce from one point): the direction
  // decides, mean step ~1.3 in random order.
  for (Ray& r : rays) r.ox = r.oy = r.oz = 0.5f;
  std::vector<Ray> fan = gather<Ray>(rays, morton_order(rays, bounds));
  EXPECT_LT(mean_step(fan, true) * 20.0f, mean_step(rays, true));
  // equal keys keep their original order
  std::vector<Ray> same(5, rays[0]);
  EXPECT_EQ(morton_order(same, bounds), (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
}

TEST(RayOrder, MortonKeyPutsOriginBeforeDirectionAndToleratesBadRays) {
  const Aabb bounds{glm::vec3(-1.0f), glm::vec3(1.0f)};
  Ray low{-1.0f, -1.0f, -1.0f, 1.0f, 1.0f, 1.0f, 0.0f, 1.0f};
  Ray high{1.0f, 1.0f, 1.0f, -1.0f, -1.0f, -1.0f, 0.0f, 1.0f};
  EXPECT_LT(ray_morton_key(low, bounds), ray_morton_key(high, bounds));
  Ray low_back = low;
  low_back.dx = low_back.dy = low_back.dz = -1.0f;
  EXPECT_LT(ray_morton_key(low_back, bounds), ray_morton_key(low, bounds));
  EXPECT_LT(ray_morton_key(low, bounds), ray_morton_key(Ray{-0.9f, -1.0f, -1.0f, -1.0f, -1.0f, -1.0f, 0.0f, 1.0f}, bounds));
  EXPECT_EQ(ray_morton_key(high, bounds) >> 60, 0u);  // 60-bit key
  Ray outside{100.0f, -100.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f};
  Ray nan{std::nanf(""), 0.0f, 0.0f, std::nanf(""), 0.0f, 1.0f, 0.0f, 1.0f};
  EXPECT_NO_THROW((void)ray_morton_key(outside, bounds));
  EXPECT_NO_THROW((void)ray_morton_key(nan, bounds));
  std::vector<Ray> bad{outside, nan, low};
  EXPECT_TRUE(is_permutation_of_iota(morton_order(bad, bounds)));
}

TEST(RayOrder, ScatterUndoesGather) {
  std::vector<Ray> rays = random_rays_in_unit_cube(1000, 5);
  auto order = morton_order(rays, Aabb{glm::vec3(0.0f), glm::vec3(1.0f)});
  std::vector<Hit> hits(rays.size());
  for (std::size_t i = 0; i < hits.size(); ++i) hits[i] = {rays[i].ox, 0.0f, 0.0f, static_cast<std::int32_t>(i)};
  std::vector<Hit> in_order = gather<Hit>(hits, order);
  std::vector<Hit> back = scatter<Hit>(in_order, order);
  for (std::size_t i = 0; i < hits.size(); ++i) EXPECT_EQ(back[i].prim, static_cast<std::int32_t>(i));
  std::vector<std::uint32_t> bad{0, 5};
  EXPECT_THROW((void)gather<Hit>(std::span<const Hit>(hits.data(), 2), bad), Error);
  EXPECT_THROW((void)scatter<Hit>(std::span<const Hit>(hits.data(), 2), bad), Error);
  EXPECT_THROW((void)scatter<Hit>(std::span<const Hit>(hits.data(), 3), bad), Error);
}

}  // namespace
}  // namespace rtcl::test
