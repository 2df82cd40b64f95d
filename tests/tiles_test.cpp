// Image tiles: exact cover, both orders, bad sizes; paste.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "rtcl/error.hpp"
#include "rtcl/render/tiles.hpp"

namespace rtcl::test {
namespace {

void expect_exact_cover(const std::vector<ImageRegion>& tiles, std::uint32_t w, std::uint32_t h) {
  std::vector<int> covered(std::size_t(w) * h, 0);
  for (const ImageRegion& t : tiles) {
    ASSERT_GT(t.width, 0u);
    ASSERT_GT(t.height, 0u);
    ASSERT_LE(t.x0 + t.width, w);
    ASSERT_LE(t.y0 + t.height, h);
    EXPECT_EQ(t.x0 % 8, 0u);
    EXPECT_EQ(t.y0 % 8, 0u);
    for (std::uint32_t y = t.y0; y < t.y0 + t.height; ++y)
      for (std::uint32_t x = t.x0; x < t.x0 + t.width; ++x) covered[std::size_t(y) * w + x]++;
  }
  EXPECT_TRUE(std::all_of(covered.begin(), covered.end(), [](int c) { return c == 1; }));
}

TEST(Tiles, CoverTheImageOnceInBothOrders) {
  for (std::uint32_t tile : {8u, 16u, 24u, 64u}) {
    std::vector<ImageRegion> rows = image_tiles(70, 45, tile, TileOrder::rows);
    std::vector<ImageRegion> shuffled = image_tiles(70, 45, tile, TileOrder::shuffled);
    expect_exact_cover(rows, 70, 45);
    expect_exact_cover(shuffled, 70, 45);
    EXPECT_EQ(rows.size(), shuffled.size());
    EXPECT_EQ(rows.size(), std::size_t((70 + tile - 1) / tile) * ((45 + tile - 1) / tile));
  }
  std::vector<ImageRegion> a = image_tiles(64, 64, 8, TileOrder::rows), b = image_tiles(64, 64, 8, TileOrder::shuffled);
  EXPECT_FALSE(std::equal(a.begin(), a.end(), b.begin(),
                          [](const ImageRegion& p, const ImageRegion& q) { return p.x0 == q.x0 && p.y0 == q.y0; }))
      << "the shuffled order is another order";
}

TEST(Tiles, RejectsSizesOffTheRayOrderGrid) {
  for (std::uint32_t tile : {0u, 4u, 12u, 100u}) {
    try {
      image_tiles(64, 64, tile, TileOrder::rows);
      ADD_FAILURE() << "tile " << tile << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("tile size " + std::to_string(tile)), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(parse_tile_order("spiral"), Error);
  EXPECT_EQ(parse_tile_order("shuffled"), TileOrder::shuffled);
}

TEST(Tiles, PastePlacesRowsAndRejectsMisfits) {
  Image image{4, 3, std::vector<float>(4 * 3 * 3, 0.0f)};
  Image part{2, 2, std::vector<float>(2 * 2 * 3, 1.0f)};
  paste(image, {2, 1, 2, 2}, part);
  EXPECT_EQ(image.at(1, 1, 0), 0.0f);
  EXPECT_EQ(image.at(2, 1, 0), 1.0f);
  EXPECT_EQ(image.at(3, 2, 2), 1.0f);
  EXPECT_EQ(image.at(3, 0, 2), 0.0f);
  EXPECT_THROW(paste(image, {3, 1, 2, 2}, part), Error);
}

}  // namespace
}  // namespace rtcl::test
