// Rendering an image in tiles (Renderer::render with a region, as rtcl
// render under mpirun does) against rendering it whole: bit-identical for
// every tile size and order.
#include <gtest/gtest.h>

#include <string>

#include "rtcl/error.hpp"
#include "rtcl/render/renderer.hpp"
#include "rtcl/render/tiles.hpp"
#include "rtcl/scene/default_scene.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "support/fixtures.hpp"

namespace rtcl::test {
namespace {

Image tiled(Renderer& renderer, const RenderSettings& s, std::uint32_t tile, TileOrder order) {
  Image image{s.width, s.height, std::vector<float>(std::size_t(s.width) * s.height * 3, -1.0f)};
  for (const ImageRegion& r : image_tiles(s.width, s.height, tile, order)) paste(image, r, renderer.render(s, r));
  return image;
}

TEST(RenderRegion, TilesInAnyOrderAndSizeGiveTheWholeImage) {
  struct Case {
    const char* what;
    SceneDescription scene;
    Sampler sampler;
  };
  const std::string scenes = RTCL_SOURCE_DIR "/scenes/";
  const Case cases[] = {{"default scene", default_scene(), Sampler::stratified},
                        {"cornell", load_scene(scenes + "cornell.json"), Sampler::stratified},
                        // area lights, glossy reflection and a thin lens: every sample keyed by the image's pixel
                        {"cornell_soft, sobol", load_scene(scenes + "cornell_soft.json"), Sampler::sobol}};
  for (const Case& c : cases) {
    Renderer renderer(test_device(), c.scene, "bvh");
    RenderSettings s;
    s.width = 52;  // not a multiple of 8: narrower edge tiles
    s.height = 44;
    s.spp = 4;
    s.sampler = c.sampler;
    Image whole = renderer.render(s);
    for (std::uint32_t tile : {8u, 24u, 64u})
      for (TileOrder order : {TileOrder::rows, TileOrder::shuffled})
        EXPECT_EQ(tiled(renderer, s, tile, order).rgb, whole.rgb) << c.what << ", tile " << tile;
  }
}

TEST(RenderRegion, RegionsOutsideTheImageAreErrors) {
  Renderer renderer(test_device(), default_scene(), "bvh");
  RenderSettings s;
  s.width = s.height = 16;
  for (ImageRegion r : {ImageRegion{8, 8, 9, 8}, ImageRegion{16, 0, 8, 8}, ImageRegion{4, 4, 0, 4}}) {
    try {
      renderer.render(s, r);
      ADD_FAILURE() << "region accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("image region"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace rtcl::test
