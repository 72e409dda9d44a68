// Batch runs (issue 21): shards are disjoint and cover the assets, reruns skip what is done,
// a failing asset makes the exit code non-zero while the others complete, manifests.
// Issue 36: resuming after a kill at any moment — a skipped job repeats its recorded result, a
// stale or half-rewritten output is redone, temp files left by SIGKILL are removed by the next
// run, and `quadlod batch` SIGKILLed at random moments then resumed ends where one run ends.
#include "cli_runner.h"

#include "quadlod/batch.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <thread>
#include <sys/wait.h>
#include <unistd.h>

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

// ---- Issue 36: resume after a kill at any moment -----------------------------------------------

namespace {

/// A line without what differs between runs: its status (done / skipped) and every time.
nlohmann::json without_times(nlohmann::json j) {
  if (j.is_object()) {
    nlohmann::json kept = nlohmann::json::object();
    for (auto& [key, value] : j.items())
      if (key != "status" && !key.ends_with("seconds")) kept[key] = without_times(value);
    return kept;
  }
  if (j.is_array())
    for (auto& e : j) e = without_times(e);
  return j;
}

/// The dot-named temp files (write_file_atomically: .NAME.tmp-PID-HEX) anywhere under `root`.
std::vector<fs::path> temporaries_under(const fs::path& root) {
  std::vector<fs::path> found;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(e.path());
  return found;
}

void set_mtime_ago(const fs::path& p, std::chrono::seconds ago) {
  fs::last_write_time(p, fs::file_time_type::clock::now() - ago);
}

}  // namespace

TEST_F(Batch, ASkippedLineRepeatsTheRecordedResult) {
  make_assets();
  const BatchJob reduce{asset(0), dir / "out" / "t0.obj", {{"ratio", 0.5}}};
  const BatchJob chain{asset(1), dir / "out" / "t1", {{"levels", {0.5, 0.25}}}};
  for (const BatchJob& job : {reduce, chain}) {
    SCOPED_TRACE(job.output.string());
    EXPECT_FALSE(batch_output_is_current(job));
    const nlohmann::json done = run_batch_job(job, {});
    ASSERT_EQ(done["status"], "done") << done.dump();
    EXPECT_TRUE(fs::is_regular_file(batch_record_path(job)));
    EXPECT_TRUE(batch_output_is_current(job));
    const nlohmann::json skipped = run_batch_job(job, {});
    EXPECT_EQ(skipped["status"], "skipped");
    EXPECT_EQ(without_times(skipped), without_times(done));
    // --force redoes it, to the same result.
    const nlohmann::json forced = run_batch_job(job, {.force = true});
    EXPECT_EQ(forced["status"], "done");
    EXPECT_EQ(without_times(forced), without_times(done));
  }
  // Known answers: t0 is a 12×8 torus, 96 quads = 192 triangle-equivalents, half is 96.
  EXPECT_EQ(batch_record_path(reduce), dir / "out" / ".t0.obj.batch.json");
  EXPECT_EQ(batch_record_path(chain), dir / "out" / ".t1.batch.json");
  const nlohmann::json again = run_batch_job(reduce, {});
  EXPECT_EQ(again["input_tri_equivalent"], 192);
  EXPECT_EQ(again["target"], 96);
  // A chain given as "out/t1/" is the same job with the same record.
  BatchJob slash = chain;
  slash.output = dir / "out" / "t1" / "";
  EXPECT_EQ(batch_record_path(slash), batch_record_path(chain));
  EXPECT_EQ(run_batch_job(slash, {})["status"], "skipped");
}

// Each case below was "skipped" by the rule before issue 36 (output not older than the input),
// leaving a stale or foreign output reported as done; each must be redone to its known result.
TEST_F(Batch, StaleOutputsAreRedoneNotSkipped) {
  make_assets();
  const BatchJob job{asset(0), dir / "out" / "t0.obj", {{"ratio", 0.5}}};
  ASSERT_EQ(run_batch_job(job, {})["status"], "done");
  const std::string half = slurp(job.output);
  BatchJob quarter_job = job;
  quarter_job.options["ratio"] = 0.25;
  quarter_job.output = dir / "ref" / "t0.obj";
  ASSERT_EQ(run_batch_job(quarter_job, {})["status"], "done");
  const std::string quarter = slurp(quarter_job.output);
  ASSERT_NE(half, quarter);

  // Threads do not change the output: still current.
  BatchJob threaded = job;
  threaded.options["threads"] = 2;
  EXPECT_EQ(run_batch_job(threaded, {})["status"], "skipped");

  // Other options: redone, to the other ratio's bytes (known: 192 / 4 = 48).
  BatchJob changed = job;
  changed.options["ratio"] = 0.25;
  nlohmann::json line = run_batch_job(changed, {});
  EXPECT_EQ(line["status"], "done");
  EXPECT_EQ(line["target"], 48);
  EXPECT_EQ(slurp(job.output), quarter);
  EXPECT_EQ(run_batch_job(changed, {})["status"], "skipped");

  // The output replaced after its record (a later run killed between the output's rename and
  // its record, or an edit): newer than the input, but not what the record vouches for.
  ASSERT_EQ(run_batch_job(job, {})["status"], "done");
  ASSERT_EQ(slurp(job.output), half);
  write_text(job.output, quarter);
  EXPECT_FALSE(batch_output_is_current(job));
  EXPECT_EQ(run_batch_job(job, {})["status"], "done");
  EXPECT_EQ(slurp(job.output), half);

  // The output removed, the record kept: redone.
  fs::remove(job.output);
  EXPECT_EQ(run_batch_job(job, {})["status"], "done");
  EXPECT_EQ(slurp(job.output), half);

  // No record (a run killed before writing it), or a torn one: redone.
  fs::remove(batch_record_path(job));
  EXPECT_EQ(run_batch_job(job, {})["status"], "done");
  write_text(batch_record_path(job), "{\"quadlod_batch_record\": 1, \"opt");
  EXPECT_EQ(run_batch_job(job, {})["status"], "done");
  EXPECT_EQ(run_batch_job(job, {})["status"], "skipped");

  // The input replaced by another mesh dated an hour back (cp -p, git checkout, rsync -t): older
  // than the output, yet the output is stale. Known: a 14×8 torus, 224 → 112.
  ASSERT_TRUE(write_mesh(make_torus(14, 8), asset(0)).ok());
  set_mtime_ago(asset(0), std::chrono::hours(1));
  line = run_batch_job(job, {});
  EXPECT_EQ(line["status"], "done");
  EXPECT_EQ(line["input_tri_equivalent"], 224);
  EXPECT_EQ(line["target"], 112);
  EXPECT_EQ(run_batch_job(job, {})["status"], "skipped");
}

TEST_F(Batch, AChainRewrittenInPartIsRedone) {
  make_assets();
  const BatchJob chain{asset(1), dir / "out" / "t1", {{"levels", {0.5, 0.25}}, {"format", ".obj"}}};
  const nlohmann::json first = run_batch_job(chain, {});
  ASSERT_EQ(first["status"], "done") << first.dump();
  const fs::path lod1 = chain.output / "t1.lod1.obj", lod2 = chain.output / "t1.lod2.obj";
  const std::string bytes1 = slurp(lod1), bytes2 = slurp(lod2);
  ASSERT_FALSE(bytes1.empty());
  // A later run that got as far as its first level (lods.json and the record still the old ones,
  // as a run before issue 36 left them): the old rule saw lods.json and skipped.
  write_text(lod1, bytes2);
  EXPECT_FALSE(batch_output_is_current(chain));
  nlohmann::json line = run_batch_job(chain, {});
  EXPECT_EQ(line["status"], "done");
  EXPECT_EQ(without_times(line), without_times(first));
  EXPECT_EQ(slurp(lod1), bytes1);
  // A level lost: redone.
  fs::remove(lod2);
  EXPECT_EQ(run_batch_job(chain, {})["status"], "done");
  EXPECT_EQ(slurp(lod2), bytes2);
  EXPECT_EQ(run_batch_job(chain, {})["status"], "skipped");
}

// A SIGKILL in the middle of write_file_atomically (hit on purpose, as in test_interrupt.cpp)
// leaves its temp file; the next run of that job removes it, and the temp files of the job's
// record and chain, but not another output's in the same folder.
TEST_F(Batch, TempFilesLeftBySigkillAreRemovedByTheNextRun) {
  make_assets();
  const BatchJob reduce{asset(0), dir / "out" / "t0.obj", {{"ratio", 0.5}}};
  const BatchJob chain{asset(1), dir / "out" / "t1", {{"levels", {0.5}}}};
  fs::create_directories(dir / "out" / "t1");
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string contents(std::size_t{128} << 20, 'x');
    ::_exit(write_file_atomically(reduce.output, contents).ok() ? 0 : 1);
  }
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (temporaries_under(dir / "out").empty() && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the write finished before the kill";
  const std::vector<fs::path> left = temporaries_under(dir / "out");
  ASSERT_EQ(left.size(), 1u);
  EXPECT_TRUE(left[0].filename().string().starts_with(".t0.obj.tmp-" + std::to_string(pid) + "-")) << left[0];
  EXPECT_FALSE(fs::exists(reduce.output));  // the rename never happened

  // What else a SIGKILL can leave: the record's temp, a chain's level and lods.json temps.
  write_text(dir / "out" / "..t0.obj.batch.json.tmp-77-beef", "{");
  write_text(dir / "out" / "t1" / ".t1.lod1.glb.tmp-12-ab", "glTF");
  write_text(dir / "out" / "t1" / ".lods.json.tmp-12-cd", "{");
  // Not this job's: another output's temp in the shared folder, and names not of the pattern.
  write_text(dir / "out" / ".t5.obj.tmp-1-2", "x");
  write_text(dir / "out" / ".t0.obj.tmp-notours", "x");
  write_text(dir / "out" / ".t0.obj.tmp-1-2.obj", "x");

  EXPECT_EQ(run_batch_job(reduce, {})["status"], "done");
  EXPECT_EQ(run_batch_job(chain, {})["status"], "done");
  std::set<std::string> remaining;
  for (const fs::path& p : temporaries_under(dir / "out")) remaining.insert(p.filename().string());
  EXPECT_EQ(remaining, (std::set<std::string>{".t5.obj.tmp-1-2", ".t0.obj.tmp-notours", ".t0.obj.tmp-1-2.obj"}));
  EXPECT_LT(fs::file_size(reduce.output), std::size_t{1} << 20);  // the reduction, not the killed write

  // A skipped job cleans up too.
  write_text(dir / "out" / ".t0.obj.tmp-5-a", "x");
  EXPECT_EQ(remove_batch_temporaries(reduce), 1u);
  write_text(dir / "out" / ".t0.obj.tmp-5-a", "x");
  EXPECT_EQ(run_batch_job(reduce, {})["status"], "skipped");
  EXPECT_FALSE(fs::exists(dir / "out" / ".t0.obj.tmp-5-a"));
}

// `quadlod batch` SIGKILLed (and SIGTERMed) at seeded random moments, each run resuming the
// state the previous kill left, over the same outputs with two option sets A and B (a rerun with
// changed options rewrites every output; a chain killed in the middle of that is the case the
// rule before issue 36 called done). A moment is "after the run printed k lines, plus d ms" (k, d
// seeded): the run is inside asset k+1, its write, or between assets, however fast the machine
// (a moment drawn from a measured run time was not: under load, runs ended before it). After
// every kill, every job that counts as done for A or for B (by its record, or by a line the
// killed run printed) has exactly that option set's reference files; a last run of A ends with
// A's reference outputs byte for byte, its lines field for field (times aside), no temp file.
TEST_F(Batch, KilledAtAnyMomentThenResumedEndsAsOneRun) {
  make_assets();
  const auto manifest = [](bool b) {
    std::string text;
    for (Index i = 0; i < 7; ++i) {
      std::string stem(1, 't');  // not "t" + string: GCC 12 warns of a bogus overflow
      stem += std::to_string(i);
      const std::string in = "../assets/" + stem + ".obj";
      if (i % 3 == 2)
        text += "{\"input\": \"" + in + "\", \"output\": \"out/" + stem + "\", \"levels\": " +
                (b ? "[0.6, 0.3]" : "[0.5, 0.25]") + "}\n";
      else
        text += "{\"input\": \"" + in + "\", \"output\": \"out/" + stem + (i % 3 ? ".glb" : ".ply") +
                "\", \"ratio\": " + (i % 2 ? "0.4" : "0.6") + (b ? "5" : "") + "}\n";
    }
    return text + "{\"input\": \"../assets/missing.obj\", \"output\": \"out/missing.obj\", \"ratio\": 0.5}\n";
  };
  for (const char* folder : {"refA", "refB", "run"}) fs::create_directories(dir / folder);
  write_text(dir / "refA" / "jobs.jsonl", manifest(false));
  write_text(dir / "refB" / "jobs.jsonl", manifest(true));
  write_text(dir / "run" / "A.jsonl", manifest(false));
  write_text(dir / "run" / "B.jsonl", manifest(true));
  const CliRun ref = run_cli("-q batch '" + (dir / "refA" / "jobs.jsonl").string() + "'", dir);
  ASSERT_EQ(ref.exit_code, 2) << ref.err;  // the missing input
  ASSERT_EQ(run_cli("-q batch '" + (dir / "refB" / "jobs.jsonl").string() + "'", dir).exit_code, 2);
  const BatchPlan plans[2] = {plan_batch_manifest(dir / "run" / "A.jsonl", {}),
                              plan_batch_manifest(dir / "run" / "B.jsonl", {})};
  const BatchPlan ref_plans[2] = {plan_batch_manifest(dir / "refA" / "jobs.jsonl", {}),
                                  plan_batch_manifest(dir / "refB" / "jobs.jsonl", {})};
  for (const BatchPlan& p : {plans[0], plans[1], ref_plans[0], ref_plans[1]}) ASSERT_TRUE(p.ok() && p.jobs.size() == 8u);

  // A job's files: name → size and hash of the bytes (a chain: every file in its directory but
  // lods.json, which holds times; a temp file there counts too).
  const auto files_of = [](const BatchJob& job) {
    std::map<std::string, std::string> files;
    const auto digest = [](const fs::path& p) {
      const std::string bytes = slurp(p);
      return std::to_string(bytes.size()) + " bytes, hash " + std::to_string(std::hash<std::string>{}(bytes));
    };
    if (fs::is_directory(job.output)) {
      for (const auto& e : fs::directory_iterator(job.output))
        if (e.path().filename() != "lods.json") files[e.path().filename().string()] = digest(e.path());
    } else if (fs::exists(job.output)) {
      files[job.output.filename().string()] = digest(job.output);
    }
    return files;
  };
  std::vector<std::map<std::string, std::string>> expected[2];
  for (int b = 0; b < 2; ++b)
    for (const BatchJob& job : ref_plans[b].jobs) expected[b].push_back(files_of(job));
  for (std::size_t k = 0; k + 1 < expected[0].size(); ++k) {
    ASSERT_FALSE(expected[0][k].empty()) << k;
    ASSERT_NE(expected[0][k], expected[1][k]) << k;  // B really rewrites every output
  }

  const fs::path run_out = dir / "run" / "run.stdout";
  std::mt19937 rng(36);
  std::uniform_int_distribution<int> after_lines(0, 6);      // of 8: the last is the missing input
  std::uniform_real_distribution<double> then_ms(0.0, 20.0);  // an asset takes 10-100 ms here
  const auto printed_lines = [&] {
    const std::string text = slurp(run_out);
    return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  };
  int killed = 0, finished = 0, done_lines_checked = 0, current_checked = 0;
  // A A B B A A B B …: every other trial changes the options; trials 0 and 6 start from nothing,
  // trials 5 and 9 are --force reruns, every fourth is a SIGTERM.
  for (int trial = 0; trial < 12; ++trial) {
    const int b = trial % 4 >= 2;
    const int signal_number = trial % 4 == 3 ? SIGTERM : SIGKILL;
    const bool force = trial == 5 || trial == 9;
    SCOPED_TRACE("trial " + std::to_string(trial) + (b ? ", B" : ", A") + ", signal " + std::to_string(signal_number) +
                 (force ? ", --force" : ""));
    if (trial == 0 || trial == 6) fs::remove_all(dir / "run" / "out");
    const fs::path manifest_path = dir / "run" / (b ? "B.jsonl" : "A.jsonl");
    const pid_t pid = ::fork();
    if (pid == 0) {
      std::freopen(run_out.c_str(), "w", stdout);
      std::freopen("/dev/null", "w", stderr);
      ::execl(QUADLOD_CLI_PATH, QUADLOD_CLI_PATH, "-q", "batch", manifest_path.c_str(), force ? "--force" : "-q",
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    const int k = after_lines(rng);
    const double d = then_ms(rng);
    int status = 0;
    bool ended = false;
    while (!(ended = ::waitpid(pid, &status, WNOHANG) == pid) && printed_lines() < k)
      std::this_thread::sleep_for(std::chrono::microseconds(300));
    if (!ended) {
      std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(d));
      ::kill(pid, signal_number);
      ::waitpid(pid, &status, 0);
    }
    WIFSIGNALED(status) ? ++killed : ++finished;
    // Whatever counts as done now, for either option set, must be exactly that set's reference.
    for (int set = 0; set < 2; ++set)
      for (std::size_t j = 0; j < plans[set].jobs.size(); ++j)
        if (batch_output_is_current(plans[set].jobs[j])) {
          ++current_checked;
          EXPECT_EQ(files_of(plans[set].jobs[j]), expected[set][j]) << (set ? "B " : "A ") << plans[set].jobs[j].output;
        }
    std::istringstream printed(slurp(run_out));
    for (std::string text; std::getline(printed, text);) {
      const nlohmann::json l = nlohmann::json::parse(text, nullptr, false);
      if (l.is_discarded() || l["status"] != "done") continue;  // a line cut by the kill
      ++done_lines_checked;
      for (std::size_t j = 0; j < plans[b].jobs.size(); ++j)
        if (plans[b].jobs[j].output.string() == l["output"].get<std::string>()) {
          EXPECT_TRUE(batch_output_is_current(plans[b].jobs[j])) << l.dump();
          EXPECT_EQ(files_of(plans[b].jobs[j]), expected[b][j]) << l.dump();
        }
    }
  }
  std::printf("batch kills: %d runs killed, %d finished first, %d done lines and %d current outputs checked\n",
              killed, finished, done_lines_checked, current_checked);
  EXPECT_GE(killed, 9);  // most runs have work left after k lines: the fresh, changed and forced ones

  const CliRun last = run_cli("-q batch '" + (dir / "run" / "A.jsonl").string() + "'", dir);
  EXPECT_EQ(last.exit_code, 2) << last.err;
  const auto got = lines(last.out), want = lines(ref.out);
  ASSERT_EQ(got.size(), want.size());
  const auto relative = [&](nlohmann::json l, const char* run) {
    for (const char* key : {"input", "output"}) l[key] = fs::relative(l[key].get<std::string>(), dir / run).string();
    if (l.contains("error")) {
      std::string e = l["error"].get<std::string>();
      const std::string prefix = (dir / run).string() + "/";
      for (std::size_t at; (at = e.find(prefix)) != std::string::npos;) e.erase(at, prefix.size());
      l["error"] = e;
    }
    return without_times(l);
  };
  for (std::size_t j = 0; j < got.size(); ++j) {
    EXPECT_EQ(relative(got[j], "run"), relative(want[j], "refA"));
    EXPECT_EQ(got[j]["status"] == "failed", want[j]["status"] == "failed") << got[j].dump();
    EXPECT_EQ(files_of(plans[0].jobs[j]), expected[0][j]) << plans[0].jobs[j].output;
  }
  EXPECT_TRUE(temporaries_under(dir / "run").empty()) << temporaries_under(dir / "run").front();
}
