// An rtcl built without MPI (RTCL_MPI=OFF, or no MPI found) started as one
// of several MPI ranks refuses, saying so, instead of every rank doing the
// whole job. The launcher is simulated by its environment variables. Built
// only without MPI (with MPI, tests/mpi_*_test.cpp run the real thing).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "support/cli_run.hpp"
#include "support/temp_dir.hpp"

namespace rtcl::test {
namespace {

TEST(CliWithoutMpi, RanksOfAnMpiJobAreRefusedWithTheReason) {
  TempDir dir;
  for (const char* env : {"OMPI_COMM_WORLD_SIZE=3", "PMI_SIZE=2"}) {
    CliRun render = run_cli(dir, {"render", "-q", "--width", "16", "-o", "x.png"}, env);
    expect_failure(render, "rtcl render: started as one of", dir, "x.png");
    EXPECT_NE(render.err.find("built without MPI support"), std::string::npos) << render.err;
    CliRun bench = run_cli(dir, {"bench", "--size", "8", "--scene", "tetra:levels=1", "-o", dir.file("b")}, env);
    expect_failure(bench, "rtcl bench: started as one of", dir);
    EXPECT_FALSE(std::filesystem::exists(dir.file("b/bench.json")));
  }
  // One rank is a plain single-process run.
  CliRun one = run_cli(dir, {"render", "-q", "--width", "16", "-o", "one.png"}, "OMPI_COMM_WORLD_SIZE=1");
  EXPECT_EQ(one.status, 0) << one.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("one.png")));
}

}  // namespace
}  // namespace rtcl::test
