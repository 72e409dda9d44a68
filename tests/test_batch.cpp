// Batch runs (issue 21): shards are disjoint and cover the assets, reruns skip what is done,
// a failing asset makes the exit code non-zero while the others complete, manifests.
#include "cli_runner.h"

#include "quadlod/batch.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <map>
#include <sstream>

using namespace quadlod;
using namespace quadlod::testing;
namespace fs = std::filesystem;

namespace {

class Batch : public ScratchDirTest {
 protected:
  /// Seven tori of different sizes in dir/assets.
  void make_assets() {
    fs::create_directories(dir / "assets");
    for (Index i = 0; i < 7; ++i) ASSERT_TRUE(write_mesh(make_torus(12 + 2 * i, 8), asset(i)).ok());
  }
  fs::path asset(Index i) const {
    std::string name = "t";
    name += std::to_string(i);
    name += ".obj";
    return dir / "assets" / name;
  }
  std::vector<nlohmann::json> lines(const std::string& out) {
    std::vector<nlohmann::json> parsed;
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line))
      if (!line.empty()) parsed.push_back(nlohmann::json::parse(line));
    return parsed;
  }
};

}  // namespace

TEST(BatchShard, ParseAndSplit) {
  unsigned i = 9, n = 9;
  EXPECT_TRUE(parse_shard("2/3", i, n));
  EXPECT_EQ(i, 2u);
  EXPECT_EQ(n, 3u);
  EXPECT_FALSE(parse_shard("3/3", i, n));
  EXPECT_FALSE(parse_shard("1/0", i, n));
  EXPECT_FALSE(parse_shard("1-3", i, n));
  EXPECT_FALSE(parse_shard("a/3", i, n));
  std::vector<BatchJob> jobs(7);
  for (std::size_t k = 0; k < jobs.size(); ++k) jobs[k].input = "in" + std::to_string(k);
  EXPECT_EQ(shard_jobs(jobs, 0, 3).size(), 3u);  // 0, 3, 6
  EXPECT_EQ(shard_jobs(jobs, 1, 3).size(), 2u);  // 1, 4
  EXPECT_EQ(shard_jobs(jobs, 2, 3)[1].input, "in5");
}

TEST_F(Batch, ThreeShardsDoEveryAssetExactlyOnce) {
  make_assets();
  std::map<std::string, int> done;
  for (int shard = 0; shard < 3; ++shard) {
    const CliRun run = run_cli("-q batch '" + (dir / "assets").string() + "' -o '" + (dir / "out").string() +
                                   "' --ratio 0.5 --shard " + std::to_string(shard) + "/3",
                               dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    for (const nlohmann::json& line : lines(run.out)) {
      EXPECT_EQ(line["status"], "done") << line.dump();
      done[line["input"].get<std::string>()]++;
      EXPECT_LT(line["achieved"].get<std::uint64_t>(), line["input_tri_equivalent"].get<std::uint64_t>());
    }
  }
  ASSERT_EQ(done.size(), 7u);
  for (const auto& [input, times] : done) EXPECT_EQ(times, 1) << input;
  for (Index i = 0; i < 7; ++i) EXPECT_TRUE(fs::exists(dir / "out" / asset(i).filename()));

  // Resumable: a rerun of everything skips it all; touching one input redoes that one.
  fs::last_write_time(dir / "assets" / "t3.obj", fs::file_time_type::clock::now() + std::chrono::seconds(5));
  const CliRun again = run_cli("-q batch '" + (dir / "assets").string() + "' -o '" + (dir / "out").string() + "' --ratio 0.5", dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const auto second = lines(again.out);
  ASSERT_EQ(second.size(), 7u);
  for (const nlohmann::json& line : second)
    EXPECT_EQ(line["status"], line["input"].get<std::string>().ends_with("t3.obj") ? "done" : "skipped") << line.dump();
}

TEST_F(Batch, AFailedAssetFailsTheRunWhileTheOthersComplete) {
  make_assets();
  write_text(dir / "assets" / "broken.fbx", "not an fbx");
  const CliRun run = run_cli("-q batch '" + (dir / "assets").string() + "' -o '" + (dir / "out").string() + "' --ratio 0.5", dir);
  EXPECT_EQ(run.exit_code, 2);
  const auto parsed = lines(run.out);
  ASSERT_EQ(parsed.size(), 8u);
  int failed = 0, done = 0;
  for (const nlohmann::json& line : parsed) {
    if (line["status"] == "failed") {
      ++failed;
      EXPECT_NE(line["error"].get<std::string>().find("broken.fbx"), std::string::npos);
    }
    done += line["status"] == "done";
  }
  EXPECT_EQ(failed, 1);
  EXPECT_EQ(done, 7);
}

TEST_F(Batch, ManifestWithPerAssetOptionsAndLodChains) {
  make_assets();
  write_text(dir / "jobs.jsonl",
             "{\"input\": \"assets/t0.obj\", \"output\": \"out/t0.glb\", \"options\": {\"ratio\": 0.5}}\n"
             "\n"
             "{\"input\": \"assets/t1.obj\", \"output\": \"out/t1_lods\", \"levels\": [0.5, 0.25], \"format\": \"fbx\"}\n"
             "{\"input\": \"assets/t2.obj\", \"output\": \"out/t2.obj\", \"ratio\": 0.5, \"colour\": 1}\n");
  const CliRun run = run_cli("-q batch '" + (dir / "jobs.jsonl").string() + "'", dir);
  EXPECT_EQ(run.exit_code, 2);  // the typo'd option
  const auto parsed = lines(run.out);
  ASSERT_EQ(parsed.size(), 3u);
  EXPECT_EQ(parsed[0]["status"], "done");
  EXPECT_TRUE(fs::exists(dir / "out" / "t0.glb"));
  EXPECT_EQ(parsed[1]["status"], "done") << parsed[1].dump();
  EXPECT_EQ(parsed[1]["levels"].size(), 2u);
  EXPECT_TRUE(fs::exists(dir / "out" / "t1_lods" / "t1.lod2.fbx"));
  EXPECT_TRUE(fs::exists(dir / "out" / "t1_lods" / "lods.json"));
  EXPECT_EQ(parsed[2]["status"], "failed");
  EXPECT_NE(parsed[2]["error"].get<std::string>().find("colour"), std::string::npos);

  const BatchPlan bad = plan_batch_manifest(dir / "missing.jsonl", {});
  EXPECT_FALSE(bad.ok());
  write_text(dir / "bad.jsonl", "{\"input\": \"a.obj\", \"output\": \"b.obj\"}\n{not json\n");
  const BatchPlan malformed = plan_batch_manifest(dir / "bad.jsonl", {});
  ASSERT_FALSE(malformed.ok());
  EXPECT_NE(malformed.error.find("bad.jsonl:2"), std::string::npos) << malformed.error;
}

TEST_F(Batch, RecoverQuadsReachesEachJobAndIsChecked) {
  // A torus written as triangles (each quad split along a diagonal).
  const PolyMesh torus = make_torus(16, 8);
  PolyMesh tris;
  tris.positions = torus.positions;
  for (Index f = 0; f < torus.num_faces(); ++f) {
    const auto v = torus.face_vertices(f);
    tris.add_face({v[0], v[1], v[2]});
    tris.add_face({v[0], v[2], v[3]});
  }
  fs::create_directories(dir / "assets");
  ASSERT_TRUE(write_mesh(tris, dir / "assets" / "tris.obj").ok());
  write_text(dir / "jobs.jsonl",
             "{\"input\": \"assets/tris.obj\", \"output\": \"out/auto.obj\", \"ratio\": 0.5}\n"
             "{\"input\": \"assets/tris.obj\", \"output\": \"out/off.obj\", \"ratio\": 0.5, \"recover_quads\": \"off\"}\n"
             "{\"input\": \"assets/tris.obj\", \"output\": \"out/bad.obj\", \"ratio\": 0.5, \"recover_quads\": \"maybe\"}\n");
  const CliRun run = run_cli("-q batch '" + (dir / "jobs.jsonl").string() + "'", dir);
  EXPECT_EQ(run.exit_code, 2);  // the bad value
  const auto parsed = lines(run.out);
  ASSERT_EQ(parsed.size(), 3u);
  EXPECT_EQ(parsed[0]["status"], "done") << parsed[0].dump();
  EXPECT_EQ(parsed[1]["status"], "done") << parsed[1].dump();
  EXPECT_EQ(parsed[2]["status"], "failed");
  EXPECT_NE(parsed[2]["error"].get<std::string>().find("recover_quads must be auto, on or off"), std::string::npos)
      << parsed[2].dump();
  auto quads = [](const fs::path& p) {
    const ReadResult r = read_mesh(p);
    Index n = 0;
    for (Index f = 0; f < r.mesh.num_faces(); ++f) n += r.mesh.face_size(f) == 4;
    return n;
  };
  EXPECT_GT(quads(dir / "out" / "auto.obj"), 0);
  EXPECT_EQ(quads(dir / "out" / "off.obj"), 0);
  // The folder mode's --recover-quads is checked by the command line.
  EXPECT_EQ(run_cli("-q batch assets -o out2 --ratio 0.5 --recover-quads maybe", dir).exit_code, 1);
}
