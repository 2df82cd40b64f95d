#include "rtcl/io/ray_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "rtcl/error.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

constexpr float nan = std::numeric_limits<float>::quiet_NaN();


float float_at(const std::string& bytes, std::size_t offset) {
  unsigned char b[4];
  std::memcpy(b, bytes.data() + offset, 4);
  std::uint32_t word = b[0] | b[1] << 8 | b[2] << 16 | static_cast<std::uint32_t>(b[3]) << 24;  // little-endian
  float f;
  std::memcpy(&f, &word, 4);
  return f;
}

std::int32_t int_at(const std::string& bytes, std::size_t offset) {
  unsigned char b[4];
  std::memcpy(b, bytes.data() + offset, 4);
  return static_cast<std::int32_t>(b[0] | b[1] << 8 | b[2] << 16 | static_cast<std::uint32_t>(b[3]) << 24);
}

Ray good_ray(float x = 0.0f) { return {x, 1.0f, 2.0f, 0.0f, 0.0f, -1.0f, 0.0f, kInf}; }

TEST(RayFile, RaysRoundTripWithTheDocumentedByteLayout) {
  TempDir dir;
  std::vector<Ray> rays = {{1, 2, 3, 4, 5, 6, 7, 8}, {-1, 0.5f, 0, 0, 1e-30f, 0, -2, kInf}, {0, 0, 0, 1, 0, 0, 3, 3}};
  write_rays(dir.file("r.rays"), rays);
  std::string bytes = read_text(dir.file("r.rays"));
  ASSERT_EQ(bytes.size(), 3u * 32u);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(float_at(bytes, 4 * k), static_cast<float>(k + 1)) << "field " << k;
  EXPECT_EQ(float_at(bytes, 32 + 28), kInf);  // second ray's tmax
  std::vector<Ray> back = read_rays(dir.file("r.rays"));
  ASSERT_EQ(back.size(), rays.size());
  EXPECT_EQ(std::memcmp(back.data(), rays.data(), rays.size() * sizeof(Ray)), 0);
}

TEST(RayFile, HitsRoundTripWithTheDocumentedByteLayout) {
  TempDir dir;
  std::vector<Hit> hits = {{1.5f, 0.25f, 0.5f, 7}, {kInf, 0.0f, 0.0f, -1}};
  write_hits(dir.file("h.hits"), hits);
  std::string bytes = read_text(dir.file("h.hits"));
  ASSERT_EQ(bytes.size(), 32u);
  EXPECT_EQ(float_at(bytes, 0), 1.5f);
  EXPECT_EQ(float_at(bytes, 4), 0.25f);
  EXPECT_EQ(float_at(bytes, 8), 0.5f);
  EXPECT_EQ(int_at(bytes, 12), 7);
  EXPECT_EQ(float_at(bytes, 16), kInf);
  EXPECT_EQ(int_at(bytes, 28), -1);
  std::vector<Hit> back = read_hits(dir.file("h.hits"));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(std::memcmp(back.data(), hits.data(), sizeof(Hit) * 2), 0);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"h.hits"}) << "no temporary file is left";
}

TEST(RayFile, EmptyFilesHoldZeroRecords) {
  TempDir dir;
  EXPECT_TRUE(read_rays(dir.write("none.rays", "")).empty());
  write_hits(dir.file("none.hits"), {});
  EXPECT_EQ(read_text(dir.file("none.hits")), "");
  EXPECT_TRUE(read_hits(dir.file("none.hits")).empty());
}

TEST(RayFile, EdgeValuesThatAreValid) {
  TempDir dir;
  std::vector<Ray> rays = {
      {0, 0, 0, 1e-30f, 0, 0, -kInf, kInf},  // tiny direction, tmin -kInf
      {0, 0, 0, 0, -1, 0, 2.0f, 2.0f},     // tmin == tmax
      {-0.0f, 0, 0, -0.0f, 0, 1, 0.0f, 0.0f},
  };
  write_rays(dir.file("edge.rays"), rays);
  EXPECT_EQ(read_rays(dir.file("edge.rays")).size(), 3u);
}

TEST(RayFileErrors, MissingDirectoryAndBadSize) {
  TempDir dir;
  std::string missing = dir.file("missing.rays");
  std::string e = error_of([&] { read_rays(missing); });
  EXPECT_NE(e.find(missing + ": no such ray file"), std::string::npos) << e;
  e = error_of([&] { read_rays(dir.path()); });
  EXPECT_NE(e.find("is a directory"), std::string::npos) << e;
  std::string odd = dir.write("odd.rays", std::string(33, '\0'));
  e = error_of([&] { read_rays(odd); });
  EXPECT_NE(e.find(odd + ": size 33 bytes is not a multiple of 32"), std::string::npos) << e;
  std::string odd_hits = dir.write("odd.hits", std::string(20, '\0'));
  e = error_of([&] { read_hits(odd_hits); });
  EXPECT_NE(e.find("size 20 bytes is not a multiple of 16"), std::string::npos) << e;
}

// One bad ray among good ones: the message names the file, counts the bad
// rays, and gives the first one's index and problem.
void expect_bad(const std::vector<Ray>& rays, const std::string& count, std::size_t first, const std::string& what) {
  TempDir dir;
  std::string path = dir.file("bad.rays");
  write_rays(path, rays);
  std::string e = error_of([&] { read_rays(path); });
  ASSERT_FALSE(e.empty()) << what << " was accepted";
  EXPECT_NE(e.find(path + ": " + count + " of " + std::to_string(rays.size()) + " rays are invalid"), std::string::npos)
      << e;
  EXPECT_NE(e.find("the first is ray " + std::to_string(first) + " "), std::string::npos) << e;
  EXPECT_NE(e.find(what), std::string::npos) << e;
}

TEST(RayFileErrors, InvalidRaysAreCountedAndTheFirstIsNamed) {
  auto with = [](std::size_t index, Ray bad, std::size_t count = 5) {
    std::vector<Ray> rays(count, good_ray());
    rays[index] = bad;
    return rays;
  };
  Ray r = good_ray();
  Ray nan_origin = r;
  nan_origin.oy = nan;
  expect_bad(with(3, nan_origin), "1", 3, "origin has a NaN or infinite component");
  Ray inf_origin = r;
  inf_origin.ox = -kInf;
  expect_bad(with(0, inf_origin), "1", 0, "origin has a NaN or infinite component");
  Ray nan_dir = r;
  nan_dir.dz = nan;
  expect_bad(with(4, nan_dir), "1", 4, "direction has a NaN or infinite component");
  Ray zero_dir = r;
  zero_dir.dx = zero_dir.dy = zero_dir.dz = 0.0f;
  expect_bad(with(2, zero_dir), "1", 2, "direction has zero length");
  Ray nan_tmin = r;
  nan_tmin.tmin = nan;
  expect_bad(with(1, nan_tmin), "1", 1, "tmin or tmax is NaN");
  Ray nan_tmax = r;
  nan_tmax.tmax = nan;
  expect_bad(with(1, nan_tmax), "1", 1, "tmin or tmax is NaN");
  Ray reversed = r;
  reversed.tmin = 5.0f;
  reversed.tmax = 1.0f;
  expect_bad(with(2, reversed), "1", 2, "tmin 5 is greater than tmax 1");
  // several bad rays: counted, the first is named
  std::vector<Ray> many(10, good_ray());
  many[6] = zero_dir;
  many[8] = nan_origin;
  many[9] = reversed;
  expect_bad(many, "3", 6, "zero length");
}

}  // namespace
}  // namespace rtcl::test
