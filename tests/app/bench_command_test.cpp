// `patchskin bench --quick --json FILE` as a smoke test: it runs, prints every
// row of the table, and the JSON holds every figure with positive median, min
// and max (min <= median <= max). Nothing here checks speed.

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/data_paths.h"
#include "support/run_process.h"

namespace {

namespace fs = std::filesystem;

void ExpectFigure(const nlohmann::json& f, const std::string& name) {
  ASSERT_TRUE(f.is_object()) << name;
  const double median = f.at("median").get<double>(), lo = f.at("min").get<double>(),
               hi = f.at("max").get<double>();
  EXPECT_GT(lo, 0.0) << name;
  EXPECT_LE(lo, median) << name;
  EXPECT_LE(median, hi) << name;
  EXPECT_FALSE(f.at("runs").empty()) << name;
  EXPECT_FALSE(f.at("unit").get<std::string>().empty()) << name;
}

TEST(BenchCommand, QuickRunPrintsEveryRowAndWritesPositiveFigures) {
  const fs::path dir = testsupport::TestOutputPath("bench_command/x").parent_path();
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path json_path = dir / "bench.json";
  std::vector<std::string> args{"bench", "--quick", "--threads", "2", "--json", json_path.string()};
#ifndef NDEBUG
  args.push_back("--allow-debug");  // the dev preset: the command refuses Debug builds otherwise
  const bool release = false;
#else
  const bool release = true;
#endif
  const testsupport::ProcessResult r = testsupport::RunPatchskin(args, dir / "logs");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("machine: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("build:   "), std::string::npos) << r.out;

  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("header").at("release").get<bool>(), release);
  EXPECT_FALSE(j.at("header").at("cpu").get<std::string>().empty());

  const nlohmann::json& table1 = j.at("table1");
  ASSERT_EQ(table1.size(), 4u);
  const char* patches[] = {"elbow", "shoulder", "abdomen", "face"};
  const char* grids[] = {"9x10", "9x6", "5x5", "7x7"};
  for (std::size_t i = 0; i < 4; ++i) {
    const nlohmann::json& row = table1[i];
    EXPECT_EQ(row.at("patch").get<std::string>(), patches[i]);
    EXPECT_EQ(row.at("grid").get<std::string>(), grids[i]);
    EXPECT_GT(row.at("bound_vertices").get<int>(), 0);
    for (const char* q : {"update_per_s", "rebuild_per_s", "total_per_s"}) {
      ExpectFigure(row.at(q), std::string(patches[i]) + " " + q);
      // The table prints the same row.
      EXPECT_NE(r.out.find(std::string(patches[i]) + "_" + q), std::string::npos) << q;
    }
    // The paper's update figure is there for every row, with the ratio.
    EXPECT_GT(row.at("update_per_s").at("paper").get<double>(), 0.0);
    EXPECT_GT(row.at("update_per_s").at("ratio").get<double>(), 0.0);
    // total = 1 / (1/update + 1/rebuild): below both.
    EXPECT_LT(row.at("total_per_s").at("median").get<double>(),
              row.at("rebuild_per_s").at("max").get<double>());
  }
  for (const char* key : {"bvh_parse_generated", "ssd_1_thread", "ssd_2_threads", "raster_fps_1280x720",
                          "raster_fps_1920x1080", "demo_end_to_end_fps", "demo_end_to_end_per_cpu_s",
                          "png_encode_fps",
                          "bytes_per_bound_vertex", "peak_memory",
                          // Long captures (issue 8): one child render per capture size.
                          "long_capture_1000_peak_rss", "long_capture_10000_peak_rss",
                          "long_capture_100000_peak_rss", "long_capture_1000_start",
                          "long_capture_100000_start", "long_capture_growth_per_frame"}) {
    ExpectFigure(j.at("figures").at(key), key);
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " missing from the table";
  }
}

}  // namespace
