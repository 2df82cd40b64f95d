// `mpirun -np N rtcl bench` on localhost against the single-process
// `rtcl bench` of the same matrix: the merged bench.json holds exactly the
// single run's cells (scene, structure, ray set; the same ray counts,
// packets, occluder runs and sorting), each agreeing with brute force, each
// on a device entry that names its rank.
// Built only with MPI (RTCL_HAVE_MPI).
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_run.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

std::string rank_env() {
  return mpi_rank_env("RTCL_SCENES_DIR=" + shell_quoted(scenes_dir()));
}

using Key = std::tuple<std::string, std::string, std::string>;

std::map<Key, nlohmann::json> cells_of(const nlohmann::json& json) {
  std::map<Key, nlohmann::json> out;
  for (const auto& c : json["cells"]) {
    Key key{c["scene"].get<std::string>(), c["accel"].get<std::string>(), c["rays"].get<std::string>()};
    EXPECT_FALSE(out.count(key)) << "cell twice: " << c.dump();
    out[key] = c;
  }
  return out;
}

TEST(MpiBench, TheMatrixSplitOverRanksMergesIntoTheSingleRunsCells) {
  TempDir dir;
  const std::vector<std::string> args = {"bench", "--size", "24", "--scene", "tetra:levels=2,sphereflake:levels=1",
                                         "--accel", "bvh,grid,kdtree", "--rays", "primary,shadow,diffuse", "--repeat",
                                         "1", "--check-rays", "32", "--diffuse-sort", "always"};
  std::vector<std::string> single = args, split = args;
  single.insert(single.end(), {"--device", "0", "-o", dir.file("single")});
  split.insert(split.end(), {"-o", dir.file("split")});
  CliRun one = run_cli(dir, single, rank_env());
  ASSERT_EQ(one.status, 0) << one.err;
  CliRun many = run_cli_launched(dir, RTCL_MPIEXEC " --allow-run-as-root --oversubscribe -np 3", split, rank_env());
  ASSERT_EQ(many.status, 0) << many.err;

  nlohmann::json a = nlohmann::json::parse(read_text(dir.file("single/bench.json")));
  nlohmann::json b = nlohmann::json::parse(read_text(dir.file("split/bench.json")));
  std::map<Key, nlohmann::json> reference = cells_of(a), merged = cells_of(b);
  ASSERT_EQ(merged.size(), reference.size());
  for (const auto& [key, cell] : reference) {
    ASSERT_TRUE(merged.count(key)) << std::get<0>(key) << " " << std::get<1>(key) << " " << std::get<2>(key);
    const nlohmann::json& m = merged[key];
    for (const char* field : {"ray_count", "packets", "occluder_run", "sorted"})
      EXPECT_EQ(m[field], cell[field]) << field << ": " << m.dump();
    EXPECT_TRUE(m["check"]["ok"].get<bool>()) << m.dump();
    std::size_t device = m["device"];
    ASSERT_LT(device, b["devices"].size());
    EXPECT_NE(b["devices"][device]["name"].get<std::string>().find("[rank "), std::string::npos);
  }
  EXPECT_EQ(b["scenes"].size(), a["scenes"].size());
}

}  // namespace
}  // namespace rtcl::test
