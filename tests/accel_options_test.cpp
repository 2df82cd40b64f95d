// Structure build options (src/rtcl/accel/options.cpp and each structure's
// declaration): parsing, validation errors naming structure and option, the
// declared defaults, and the same options reached through make_accel, the
// spec text and scene files.
#include <gtest/gtest.h>

#include <string>

#include "rtcl/accel.hpp"
#include "rtcl/accel/bvh.hpp"
#include "rtcl/accel/grid.hpp"
#include "rtcl/error.hpp"
#include "rtcl/scene/scene_file.hpp"
#include "support/error_of.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

std::string error_of_spec(const std::string& text) {
  return error_of([&] { parse_accel_spec(text); });
}

TEST(AccelOptions, EveryStructureIsDeclaredWithItsDefaults) {
  ASSERT_EQ(structure_specs().size(), accel_names().size());
  for (std::size_t i = 0; i < accel_names().size(); ++i) {
    const StructureSpec& s = structure_specs()[i];
    EXPECT_EQ(s.name, accel_names()[i]);
    EXPECT_FALSE(s.summary.empty());
    AccelOptions defaults = resolve_options(s, {}, s.name);
    EXPECT_EQ(defaults.values().size(), s.options.size());
    for (const OptionSpec& o : s.options) {
      EXPECT_FALSE(o.help.empty()) << s.name << "." << o.name;
      // a declared default passes its own check
      EXPECT_NO_THROW(resolve_options(s, AccelOptions().set(o.name, o.default_value), s.name)) << o.name;
    }
  }
  EXPECT_TRUE(structure_spec("brute").options.empty());
  // The declarations agree with the config structs they set.
  AccelOptions bvh = resolve_options(structure_spec("bvh"), {}, "bvh");
  SahConfig sah;
  EXPECT_EQ(bvh.integer("bin_count"), sah.bin_count);
  EXPECT_EQ(bvh.real("node_cost"), sah.node_cost);
  EXPECT_EQ(bvh.integer("max_leaf_size"), sah.max_leaf_size);
  EXPECT_EQ(bvh.integer("max_sah_depth"), sah.max_sah_depth);
  EXPECT_EQ(bvh.boolean("merge_leaves"), BvhConfig{}.merge_leaves);
  AccelOptions ploc = resolve_options(structure_spec("bvh-ploc"), {}, "bvh-ploc");
  EXPECT_EQ(ploc.integer("search_radius"), PlocConfig{}.search_radius);
  EXPECT_EQ(ploc.integer("max_depth"), PlocConfig{}.max_depth);
  AccelOptions grid = resolve_options(structure_spec("grid"), {}, "grid");
  EXPECT_EQ(grid.real("lambda"), GridConfig{}.lambda);
  EXPECT_EQ(grid.resolution("res"), (Resolution3{0, 0, 0}));
}

TEST(AccelOptions, SpecsParseAndFormatBack) {
  AccelSpec s = parse_accel_spec("grid:lambda=4,res=64x32x16");
  EXPECT_EQ(s.name, "grid");
  EXPECT_EQ(s.options.real("lambda"), 4.0);
  EXPECT_EQ(s.options.resolution("res"), (Resolution3{64, 32, 16}));
  EXPECT_EQ(format_accel_spec(s), "grid:lambda=4,res=64x32x16");
  EXPECT_EQ(format_accel_spec(parse_accel_spec("grid:res=auto")), "grid:res=auto");
  EXPECT_EQ(format_accel_spec(parse_accel_spec("bvh")), "bvh");
  AccelSpec b = parse_accel_spec("bvh:bin_count=16,merge_leaves=false,node_cost=1");
  EXPECT_EQ(b.options.integer("bin_count"), 16);
  EXPECT_FALSE(b.options.boolean("merge_leaves"));
  EXPECT_EQ(b.options.real("node_cost"), 1.0);
}

TEST(AccelOptions, BadOptionsNameTheStructureAndTheOption) {
  EXPECT_EQ(error_of_spec("grid:lambda=-1").rfind("accel \"grid:lambda=-1\": lambda must be > 0", 0), 0u)
      << error_of_spec("grid:lambda=-1");
  EXPECT_NE(error_of_spec("grid:lambda=0").find("lambda must be > 0"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:lambda=nan").find("lambda must be a number"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:lambda=abc").find("lambda must be a number (got 'abc')"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:res=64x0x16").find("res must be AxBxC with each axis in [1, 65536]"),
            std::string::npos);
  EXPECT_NE(error_of_spec("grid:res=64x-2x16").find("res must be"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:res=64x32").find("res must be AxBxC"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:foo=1").find("accel \"grid:foo=1\": unknown option foo of grid (options: lambda, res, macro, occluder_run)"),
            std::string::npos);
  EXPECT_NE(error_of_spec("grid:macro=3").find("macro must be a power of two in [1, 256]"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:macro=512").find("macro must be a power of two in [1, 256]"), std::string::npos);
  EXPECT_NE(error_of_spec("brute:lambda=1").find("brute has no options"), std::string::npos);
  EXPECT_NE(error_of_spec("bvh:bin_count=1").find("bin_count must be in [2, 256]"), std::string::npos);
  EXPECT_NE(error_of_spec("bvh:bin_count=2.5").find("bin_count must be an integer"), std::string::npos);
  EXPECT_NE(error_of_spec("bvh:merge_leaves=maybe").find("merge_leaves must be true or false"), std::string::npos);
  EXPECT_NE(error_of_spec("bvh:presplit=-1").find("presplit must be in [0, 1024]"), std::string::npos);
  EXPECT_NE(error_of_spec("bvh-ploc:presplit=nan").find("presplit"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:lambda=1,lambda=2").find("lambda given twice"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:").find("expected key=value"), std::string::npos);
  EXPECT_NE(error_of_spec("grid:lambda").find("expected key=value"), std::string::npos);
  EXPECT_NE(error_of_spec("quadtree:depth=3").find("accel \"quadtree:depth=3\": unknown acceleration structure (known: brute, bvh"), std::string::npos);
  // Typed values from the API are checked the same way.
  EXPECT_THROW(resolve_options(structure_spec("grid"), AccelOptions().set("lambda", true), "grid"), Error);
  EXPECT_THROW(resolve_options(structure_spec("grid"), AccelOptions().set("lambda", -2.0), "grid"), Error);
}

TEST(AccelOptions, MakeAccelAppliesSpecAndConfigOptions) {
  Geometry g = random_soup(500, 3);
  auto one = make_accel(test_device(), "grid:res=1x1x1", g);
  EXPECT_EQ(one->stats().node_count, 1u);
  AccelConfig config;
  config.options.set("res", Resolution3{2, 3, 4});
  auto api = make_accel(test_device(), "grid", g, config);
  EXPECT_EQ(api->stats().node_count, 24u);
  auto both = make_accel(test_device(), "grid:res=1x1x1", g, config);  // config applied after the spec
  EXPECT_EQ(both->stats().node_count, 24u);
  auto sparse = make_accel(test_device(), "grid:lambda=0.5", g);
  auto dense = make_accel(test_device(), "grid:lambda=16", g);
  EXPECT_LT(sparse->stats().node_count, dense->stats().node_count);
  EXPECT_NO_THROW(make_accel(test_device(), "bvh:bin_count=8,max_leaf_size=4", g));
  AccelConfig bad;
  bad.options.set("lambda", -1.0);
  try {
    make_accel(test_device(), "grid", g, bad);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("make_accel name \"grid\": lambda must be > 0", 0), 0u) << e.what();
  }
}

TEST(AccelOptions, SceneFilesNameAStructureWithOptions) {
  TempDir dir;
  auto scene_with = [&](const std::string& accel) {
    return dir.write("scene.json", "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]}, \"accel\": " +
                                       accel +
                                       ", \"objects\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 1, \"material\": \"m\"}], \"materials\": {\"m\": {}}}");
  };
  EXPECT_EQ(load_scene(scene_with("\"grid:lambda=4\"")).accel, "grid:lambda=4");
  EXPECT_EQ(load_scene(scene_with("{\"name\": \"grid\", \"lambda\": 4, \"res\": [8, 4, 2]}")).accel,
            "grid:lambda=4,res=8x4x2");
  EXPECT_EQ(load_scene(scene_with("{\"name\": \"bvh\", \"merge_leaves\": false}")).accel, "bvh:merge_leaves=false");
  EXPECT_EQ(load_scene(dir.write("none.json", "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]}, "
                                              "\"objects\": [{\"type\": \"sphere\", \"center\": [0, 0, 0], "
                                              "\"radius\": 1, \"material\": \"m\"}], \"materials\": {\"m\": {}}}"))
                .accel,
            "");
  for (const auto& [text, fragment] :
       std::vector<std::pair<std::string, std::string>>{{"{\"name\": \"grid\", \"lambda\": -1}", "lambda must be > 0"},
                                                        {"{\"name\": \"grid\", \"size\": 3}", "unknown option size"},
                                                        {"{\"lambda\": 3}", "missing required key 'name'"},
                                                        {"\"no-such-tree\"", "unknown acceleration structure"},
                                                        {"3", "expected a string or an object"}}) {
    try {
      load_scene(scene_with(text));
      ADD_FAILURE() << text << ": no error";
    } catch (const Error& e) {
      std::string m = e.what();
      EXPECT_NE(m.find("scene.json: accel"), std::string::npos) << m;
      EXPECT_NE(m.find(fragment), std::string::npos) << m;
    }
  }
}

}  // namespace
}  // namespace rtcl::test
