// End-to-end tests of the quadlod executable: exit codes, one-line errors, no stray outputs.
#include "cli_runner.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace quadlod::testing;
namespace fs = std::filesystem;

namespace {

int count_lines(const std::string& s) {
  return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

// Every bad input must give exit code 2 and exactly one line on stderr that names the file.
void expect_one_line_error(const CliRun& run, const std::string& must_contain) {
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_EQ(count_lines(run.err), 1) << run.err;
  EXPECT_NE(run.err.find(must_contain), std::string::npos) << run.err;
}

class CliTest : public ScratchDirTest {};


// Issue 32: --seams reaches simplify, lod and batch. Lone triangles (every edge a boundary) can
// only meet a budget by letting small parts vanish: auto does once a pass stalls, strict never,
// and strict's note says so.
TEST_F(CliTest, SeamsStrictKeepsEveryPartAndSaysWhyItStopped) {
  const fs::path mesh = dir / "lone.obj";
  std::string text;
  for (int k = 0; k < 50; ++k) {
    const int x = 2 * (k % 10), y = 2 * (k / 10);
    text += "v " + std::to_string(x) + " " + std::to_string(y) + " 0\n";
    text += "v " + std::to_string(x + 1) + " " + std::to_string(y) + " 0\n";
    text += "v " + std::to_string(x + 1) + " " + std::to_string(y + 1) + " 0\n";
    text += "f " + std::to_string(3 * k + 1) + " " + std::to_string(3 * k + 2) + " " + std::to_string(3 * k + 3) + "\n";
  }
  write_text(mesh, text);
  CliRun run = run_cli("-q simplify " + mesh.string() + " -o " + (dir / "auto.obj").string() + " --ratio 0.4 --report " +
                           (dir / "auto.json").string(), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto a = nlohmann::json::parse(slurp(dir / "auto.json"));
  EXPECT_EQ(a["seams"]["policy"], "auto");
  EXPECT_EQ(a["achieved"], 20);
  run = run_cli("-q simplify " + mesh.string() + " -o " + (dir / "strict.obj").string() +
                    " --ratio 0.4 --seams strict --report " + (dir / "strict.json").string(), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto s = nlohmann::json::parse(slurp(dir / "strict.json"));
  EXPECT_EQ(s["seams"]["policy"], "strict");
  EXPECT_EQ(s["options"]["seams"], "strict");
  EXPECT_EQ(s["achieved"], 50);
  EXPECT_NE(run.out.find("+150.0 %"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("with --seams strict no line merges through an island and no part vanishes"), std::string::npos)
      << run.out;
  const auto bad = run_cli("simplify " + mesh.string() + " -o " + (dir / "x.obj").string() + " --seams sometimes", dir);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("--seams: sometimes not in {auto,strict}"), std::string::npos) << bad.err;
  // The help names the choices and the default as the other choices do (it printed NUL bytes).
  for (const char* sub : {"simplify", "lod"})
    EXPECT_NE(run_cli(std::string(sub) + " --help", dir).out.find("--seams TEXT:{auto,strict}=auto"), std::string::npos) << sub;
  ASSERT_EQ(run_cli("-q lod " + mesh.string() + " -o " + (dir / "lods").string() + " --levels 0.4 --format obj --seams strict", dir).exit_code, 0);
  const auto lods = nlohmann::json::parse(slurp(dir / "lods" / "lods.json"));
  EXPECT_EQ(lods["levels"][0]["achieved"], 50) << lods.dump();
  write_text(dir / "jobs.jsonl",
             "{\"input\": \"lone.obj\", \"output\": \"out/strict.obj\", \"ratio\": 0.4, \"seams\": \"strict\"}\n"
             "{\"input\": \"lone.obj\", \"output\": \"out/bad.obj\", \"ratio\": 0.4, \"seams\": \"loose\"}\n");
  run = run_cli("-q batch '" + (dir / "jobs.jsonl").string() + "'", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("seams must be auto or strict"), std::string::npos) << run.out;
  EXPECT_EQ(nlohmann::json::parse(run_cli("info --json " + (dir / "out" / "strict.obj").string(), dir).out)["faces"], 50);
}

// Issue 34: --symmetry reaches simplify, lod, batch (manifests) and eval's `symmetry` metric. A
// grid bent symmetrically about x = 0, and the same grid with one row lifted (not symmetric).
std::string bent_grid_obj(bool symmetric) {
  std::string text;
  const int n = 12, m = 8;
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = -1.0 + 2.0 * i / n, y = -0.5 + 1.0 * j / m;
      const double z = 0.3 * std::exp(-3.0 * (x * x + y * y)) + 0.1 * y + (!symmetric && j == 2 && i < 4 ? 0.05 : 0.0);
      char line[96];
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", x, y, z);
      text += line;
    }
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i + 1;
      text += "f " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(a + n + 2) + " " +
              std::to_string(a + n + 1) + "\n";
    }
  return text;
}

TEST_F(CliTest, SymmetryReachesSimplifyLodBatchAndEval) {
  const std::string d = dir.string() + "/";
  write_text(dir / "sym.obj", bent_grid_obj(true));
  write_text(dir / "asym.obj", bent_grid_obj(false));
  CliRun run = run_cli("-q simplify " + d + "sym.obj -o " + d + "sym.out.obj --ratio 0.4 --symmetry x --report " + d + "sym.json", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("symmetry: mirror about the x plane (x = 0): 100.00 % of the input's vertices matched"), std::string::npos)
      << run.out;
  const auto report = nlohmann::json::parse(slurp(dir / "sym.json"));
  EXPECT_EQ(report["symmetry"]["axis"], "x");
  EXPECT_EQ(report["options"]["symmetry"], "x");
  const auto eval = nlohmann::json::parse(run_cli("-q eval " + d + "sym.obj " + d + "sym.out.obj --json --samples 1000", dir).out);
  EXPECT_EQ(eval["symmetry"]["axis"], "x");
  EXPECT_EQ(eval["symmetry"]["output_mirrored_fraction"], 1.0);
  // Not symmetric: one line of note, reduced as with off.
  run = run_cli("-q simplify " + d + "asym.obj -o " + d + "asym.auto.obj --ratio 0.4 --symmetry auto", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("note: not mirror-symmetric about any bbox-centred axis plane"), std::string::npos) << run.out;
  ASSERT_EQ(run_cli("-q simplify " + d + "asym.obj -o " + d + "asym.off.obj --ratio 0.4 --symmetry off", dir).exit_code, 0);
  EXPECT_EQ(slurp(dir / "asym.auto.obj"), slurp(dir / "asym.off.obj"));
  const CliRun bad = run_cli("simplify " + d + "sym.obj -o " + d + "x.obj --ratio 0.4 --symmetry sideways", dir);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("--symmetry: sideways not in {auto,x,y,z,off}"), std::string::npos) << bad.err;
  for (const char* sub : {"simplify", "lod"})
    EXPECT_NE(run_cli(std::string(sub) + " --help", dir).out.find("--symmetry TEXT:{auto,x,y,z,off}"), std::string::npos) << sub;
  // lod: each level about its input's plane, on stdout and in lods.json.
  run = run_cli("-q lod " + d + "sym.obj -o " + d + "lods --levels 0.5,0.25 --format obj --symmetry auto", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("lod2: symmetry: mirror about the x plane"), std::string::npos) << run.out;
  const auto lods = nlohmann::json::parse(slurp(dir / "lods" / "lods.json"));
  EXPECT_EQ(lods["levels"][1]["meshes"][0]["symmetry"]["axis"], "x") << lods.dump();
  // batch: the manifest's option, and a bad value refused.
  write_text(dir / "jobs.jsonl",
             "{\"input\": \"sym.obj\", \"output\": \"out/sym.obj\", \"ratio\": 0.4, \"symmetry\": \"x\"}\n"
             "{\"input\": \"sym.obj\", \"output\": \"out/bad.obj\", \"ratio\": 0.4, \"symmetry\": \"w\"}\n");
  run = run_cli("-q batch " + d + "jobs.jsonl", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.out.find("symmetry must be auto, x, y, z or off"), std::string::npos) << run.out;
  EXPECT_EQ(slurp(dir / "out" / "sym.obj"), slurp(dir / "sym.out.obj"));
}

}  // namespace

TEST_F(CliTest, UsageErrorsExitWithOne) {
  EXPECT_EQ(run_cli("", dir).exit_code, 1);
  EXPECT_EQ(run_cli("frobnicate", dir).exit_code, 1);
  EXPECT_EQ(run_cli("info", dir).exit_code, 1);
  EXPECT_EQ(run_cli("--help", dir).exit_code, 0);
}

TEST_F(CliTest, InfoJsonHasTheDocumentedKeys) {
  const fs::path mesh = dir / "vase.obj";
  ASSERT_EQ(run_cli("generate vase --n 10 --m 4 -o " + mesh.string(), dir).exit_code, 0);
  const CliRun run = run_cli("info --json " + mesh.string(), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  for (const char* key : {"vertices", "faces", "triangles", "quads", "ngons", "tri_equivalent",
                          "boundary_edges", "nonmanifold_edges", "degenerate_faces", "components",
                          "has_uvs", "bbox", "edges", "boundary_loops", "nonmanifold_vertices",
                          "duplicate_faces", "zero_length_edges", "faces_by_degree"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["faces"], 51);
  EXPECT_EQ(j["quads"], 40);
  EXPECT_EQ(j["triangles"], 10);
  EXPECT_EQ(j["ngons"], 1);
  EXPECT_EQ(j["tri_equivalent"], 98);
  EXPECT_EQ(j["boundary_edges"], 0);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["has_uvs"], true);
  EXPECT_EQ(j["faces_by_degree"]["10"], 1);
}

TEST_F(CliTest, InfoCountsRepeatedIndexFacesInsteadOfRefusing) {
  const fs::path mesh = dir / "rep.obj";
  write_text(mesh, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 2 3\n");
  const CliRun run = run_cli("info --json " + mesh.string(), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["repeated_index_faces"], 1);
  EXPECT_EQ(j["degenerate_faces"], 1);
}

TEST_F(CliTest, BadInputTruncatedPly) {
  const fs::path mesh = dir / "trunc.ply";
  write_text(mesh, "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\n"
                   "property float y\nproperty float z\nelement face 6\n"
                   "property list uchar int vertex_indices\nend_header\n\x01\x02");
  expect_one_line_error(run_cli("info " + mesh.string(), dir), "trunc.ply");
}

TEST_F(CliTest, BadInputTruncatedObj) {
  const fs::path mesh = dir / "trunc.obj";
  write_text(mesh, "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3 4");  // the face names vertex 4: cut short
  expect_one_line_error(run_cli("info " + mesh.string(), dir), "trunc.obj");
}

TEST_F(CliTest, BadInputGarbageBytes) {
  const fs::path mesh = dir / "garbage.obj";
  std::string bytes;
  for (int i = 0; i < 4096; ++i) bytes.push_back(static_cast<char>((i * 2654435761u) >> 13));
  write_text(mesh, bytes);
  expect_one_line_error(run_cli("info " + mesh.string(), dir), "garbage.obj");
}

TEST_F(CliTest, BadInputNonFiniteCoordinates) {
  for (const char* value : {"nan", "inf", "-inf", "1e999"}) {
    const fs::path mesh = dir / "nonfinite.obj";
    write_text(mesh, std::string("v 0 0 0\nv 1 0 0\nv 0 ") + value + " 0\nf 1 2 3\n");
    expect_one_line_error(run_cli("info " + mesh.string(), dir), "nonfinite.obj:3");
  }
}

TEST_F(CliTest, BadInputIndexOutOfRange) {
  const fs::path mesh = dir / "range.obj";
  write_text(mesh, "v 0 0 0\nv 1 0 0\nv 0 1 0\n# comment\nf 1 2 9\n");
  expect_one_line_error(run_cli("info " + mesh.string(), dir), "range.obj:5");
  const fs::path off = dir / "range.off";
  write_text(off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  expect_one_line_error(run_cli("info " + off.string(), dir), "range.off");
}

TEST_F(CliTest, BadInputEmptyMesh) {
  const fs::path mesh = dir / "empty.obj";
  write_text(mesh, "# nothing here\n");
  expect_one_line_error(run_cli("info " + mesh.string(), dir), "empty.obj");
  const fs::path zero = dir / "zero.obj";
  write_text(zero, "");
  expect_one_line_error(run_cli("info " + zero.string(), dir), "zero.obj");
}

TEST_F(CliTest, BadInputFaceUsesVertexTwice) {
  const fs::path mesh = dir / "twice.obj";
  write_text(mesh, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n");
  const fs::path out = dir / "out.obj";
  expect_one_line_error(run_cli("eval " + mesh.string() + " " + mesh.string(), dir), "twice.obj:4");
}

TEST_F(CliTest, BadInputMissingFile) {
  expect_one_line_error(run_cli("info " + (dir / "nope.obj").string(), dir), "nope.obj");
}

TEST_F(CliTest, OutputInMissingDirectoryLeavesNothing) {
  const fs::path target = dir / "no" / "such" / "dir" / "vase.obj";
  expect_one_line_error(run_cli("generate vase -o " + target.string(), dir), "vase.obj");
  EXPECT_FALSE(fs::exists(dir / "no"));
  // Nothing else appeared in the scratch directory either.
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST_F(CliTest, GenerateWritesEveryFormat) {
  for (const char* ext : {"obj", "ply", "off"}) {
    const fs::path mesh = dir / (std::string("cube.") + ext);
    ASSERT_EQ(run_cli("generate cube --n 2 -o " + mesh.string(), dir).exit_code, 0);
    const CliRun run = run_cli("info --json " + mesh.string(), dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    EXPECT_EQ(j["quads"], 24);
    EXPECT_EQ(j["vertices"], 26);
    EXPECT_EQ(j["boundary_edges"], 0);
  }
}

TEST_F(CliTest, AnAllTriangleInputIsJoinedIntoQuadsAndTheSummarySaysSo) {
  // A 3 × 2 grid written as triangles (each quad split along a diagonal, as a glTF exporter does).
  const fs::path mesh = dir / "tris.obj", out = dir / "out.obj", kept = dir / "kept.obj";
  std::string text;
  for (int y = 0; y <= 2; ++y)
    for (int x = 0; x <= 3; ++x) text += "v " + std::to_string(x) + " " + std::to_string(y) + " 0\n";
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) {
      const int a = y * 4 + x + 1, b = a + 1, c = a + 5, d = a + 4;
      text += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
      text += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
    }
  write_text(mesh, text);
  CliRun run = run_cli("simplify " + mesh.string() + " -o " + out.string() + " --ratio 1", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("quads: the input is all triangles; 6 pairs were joined into quads first"), std::string::npos) << run.out;
  run = run_cli("simplify " + mesh.string() + " -o " + kept.string() + " --ratio 1 --recover-quads off", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out.find("quads:"), std::string::npos) << run.out;
  EXPECT_EQ(run_cli("simplify " + mesh.string() + " -o " + kept.string() + " --recover-quads maybe", dir).exit_code, 1);
  const auto info = nlohmann::json::parse(run_cli("info --json " + out.string(), dir).out);
  EXPECT_EQ(info["quads"], 6);
  EXPECT_EQ(info["triangles"], 0);
  // The LOD chain's first level is reduced from the joined mesh too, unless told not to.
  ASSERT_EQ(run_cli("-q lod " + mesh.string() + " -o " + (dir / "lods").string() + " --levels 0.5 --format obj", dir).exit_code, 0);
  ASSERT_EQ(run_cli("-q lod " + mesh.string() + " -o " + (dir / "lods_off").string() + " --levels 0.5 --format obj --recover-quads off", dir).exit_code, 0);
  const auto lods = nlohmann::json::parse(slurp(dir / "lods" / "lods.json"));
  const auto lods_off = nlohmann::json::parse(slurp(dir / "lods_off" / "lods.json"));
  EXPECT_GT(lods["levels"][0]["quads"].get<int>(), 0) << lods.dump();
  EXPECT_EQ(lods_off["levels"][0]["quads"].get<int>(), 0) << lods_off.dump();
}
