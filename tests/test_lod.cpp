// LOD chains (issue 21): lod_chain's levels shrink in order and are measured against the input,
// the screen-size rule's known values, `quadlod lod` writes one file per level and lods.json.
#include "cli_runner.h"
#include "scene_test_util.h"

#include "quadlod/generators.h"
#include "quadlod/lod.h"
#include "quadlod/metrics.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

using namespace quadlod;
using namespace quadlod::scene_test;
using namespace quadlod::testing;
namespace fs = std::filesystem;

TEST(LodScreenSize, KnownValues) {
  // s = τ / (h · H), clamped to [0, 1].
  EXPECT_DOUBLE_EQ(lod_screen_size(0.01, 1.0, 1000.0), 0.1);
  EXPECT_DOUBLE_EQ(lod_screen_size(0.002, 2.0, 1000.0), 1.0);
  EXPECT_DOUBLE_EQ(lod_screen_size(0.0005, 1.0, 1000.0), 1.0);  // clamped
  EXPECT_DOUBLE_EQ(lod_screen_size(0.0, 1.0, 1080.0), 1.0);
  EXPECT_DOUBLE_EQ(lod_screen_size(0.5, 1.0, 100.0), 0.02);
}

TEST(LodRatios, ByCount) {
  EXPECT_EQ(lod_ratios_by_count(4), (std::vector<double>{0.5, 0.25, 0.125, 0.0625}));
  EXPECT_EQ(lod_ratios_by_count(2, 0.4), (std::vector<double>{0.4, 0.4 * 0.4}));
}

TEST(LodChain, LevelsShrinkAndAreMeasuredAgainstTheInput) {
  const PolyMesh torus = make_torus(48, 24);
  LodChainParams params;
  params.ratios = {0.5, 0.25, 0.125};
  params.simplify.progress = false;
  params.hausdorff_samples = 20000;
  const LodChainResult chain = lod_chain(torus, params);
  ASSERT_TRUE(chain.ok()) << chain.error;
  ASSERT_EQ(chain.levels.size(), 3u);
  EXPECT_EQ(chain.input_tri_equivalent, 48u * 24u * 2u);
  for (std::size_t l = 0; l < 3; ++l) {
    const LodLevel& level = chain.levels[l];
    EXPECT_EQ(level.target, static_cast<std::uint64_t>(std::llround(params.ratios[l] * 2304)));
    EXPECT_EQ(level.achieved, tri_equivalent_count(level.mesh));
    EXPECT_NEAR(double(level.achieved), double(level.target), 0.05 * double(level.target)) << "level " << l;
    const FaceCounts counts = count_faces(level.mesh);
    EXPECT_EQ(level.quads, counts.quads);
    EXPECT_EQ(level.triangles, counts.tris);
    // Hausdorff against the INPUT, as `quadlod eval` measures it.
    EvalParams eval;
    eval.samples = params.hausdorff_samples;
    eval.curve_samples = params.hausdorff_samples / 50;
    const EvalResult measured = evaluate(torus, level.mesh, eval);
    ASSERT_TRUE(measured.ok());
    EXPECT_DOUBLE_EQ(level.hausdorff, measured.hausdorff);
    EXPECT_GT(level.hausdorff, 0.0);
    const BoundingBox box = bounding_box(torus);
    EXPECT_NEAR(level.hausdorff_over_diagonal, level.hausdorff * box.longest_side() / box.diagonal(), 1e-12);
    if (l > 0) {
      EXPECT_LT(level.achieved, chain.levels[l - 1].achieved);
      EXPECT_LE(level.screen_size, chain.levels[l - 1].screen_size);
    }
  }
  // Each level is reduced from the previous one: simplify() of level 1 with level 2's target
  // gives level 2 exactly (deterministic pipeline).
  SimplifyOptions again = params.simplify;
  again.ratio = 1.0;
  again.target_tri_equivalent = chain.levels[2].target;
  const SimplifyResult from_previous = simplify(chain.levels[1].mesh, again);
  ASSERT_TRUE(from_previous.ok());
  EXPECT_EQ(from_previous.mesh.corner_vertex, chain.levels[2].mesh.corner_vertex);
  EXPECT_EQ(from_previous.mesh.positions, chain.levels[2].mesh.positions);
}

// Lines bend below a fraction of the CHAIN's input (issue 32), though each level is reduced from
// the previous one: the cylinder's 2 % level is 0.4 of its 5 % level, yet its rims bend (see
// Simplify.FarBelowTheBendRatioCurvedLinesBendAndTheRunGetsCloser), and levels at or above 10 %
// keep every line within the strict tolerance.
TEST(LodChain, LinesBendBelowAFractionOfTheChainsInput) {
  const PolyMesh cylinder = make_cylinder(16, 24);
  LodChainParams params;
  params.ratios = {0.5, 0.2, 0.1, 0.05, 0.02};
  params.simplify.progress = false;
  params.hausdorff_samples = 2000;
  const LodChainResult chain = lod_chain(cylinder, params);
  ASSERT_TRUE(chain.ok()) << chain.error;
  ASSERT_EQ(chain.levels.size(), 5u);
  for (std::size_t l = 0; l < 3; ++l)
    EXPECT_EQ(chain.levels[l].report["seams"]["line_tolerance"].get<double>(), 0.2) << "level " << l;
  EXPECT_GT(chain.levels[4].report["seams"]["line_tolerance"].get<double>(), 0.2);
  params.simplify.bend_lines_below_ratio = 0.0;
  const LodChainResult kept = lod_chain(cylinder, params);
  ASSERT_TRUE(kept.ok()) << kept.error;
  EXPECT_EQ(kept.levels[4].report["seams"]["line_tolerance"].get<double>(), 0.2);
  EXPECT_LT(chain.levels[4].achieved, kept.levels[4].achieved);
}

TEST(LodChain, BadRatiosAreErrors) {
  LodChainParams params;
  params.ratios = {0.5, 0.6};
  EXPECT_FALSE(lod_chain(make_grid(4, 4), params).ok());
  params.ratios = {1.5};
  EXPECT_FALSE(lod_chain(make_grid(4, 4), params).ok());
  params.ratios = {};
  EXPECT_FALSE(lod_chain(make_grid(4, 4), params).ok());
}

class LodCli : public ScratchDirTest {};

TEST_F(LodCli, WritesEveryLevelAndLodsJson) {
  const fs::path in = dir / "scene.fbx";
  ASSERT_TRUE(write_scene(make_test_scene(), in).ok());
  const fs::path out = dir / "lods";
  const CliRun run = run_cli("-q lod '" + in.string() + "' -o '" + out.string() + "' --count 2 --hausdorff-samples 5000", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_TRUE(fs::exists(out / "lods.json"));
  const nlohmann::json report = nlohmann::json::parse(slurp(out / "lods.json"));
  ASSERT_EQ(report["levels"].size(), 2u);
  EXPECT_EQ(report["input_tri_equivalent"].get<std::uint64_t>(), 96u + 192u);
  std::uint64_t previous = 96 + 192;
  double previous_screen = 1.0;
  for (std::size_t l = 0; l < 2; ++l) {
    const nlohmann::json& level = report["levels"][l];
    const fs::path file = out / level["file"].get<std::string>();
    EXPECT_EQ(file.filename().string(), "scene.lod" + std::to_string(l + 1) + ".fbx");
    const SceneReadResult back = read_scene(file);
    ASSERT_TRUE(back.ok()) << back.error;
    // The file holds what lods.json says, the scene's nodes and materials with it.
    EXPECT_EQ(back.scene.tri_equivalent_count(), level["achieved"].get<std::uint64_t>());
    std::uint64_t quads = 0;
    for (const SceneMesh& m : back.scene.meshes) quads += tally(m.mesh).quads;
    EXPECT_EQ(quads, level["quads"].get<std::uint64_t>());
    EXPECT_TRUE(mesh_of_node(back.scene, "grid_b"));
    EXPECT_LT(level["achieved"].get<std::uint64_t>(), previous);
    previous = level["achieved"].get<std::uint64_t>();
    for (const char* key : {"ratio", "target", "triangles", "ngons", "hausdorff", "screen_size", "seconds", "quad_fraction"})
      EXPECT_TRUE(level.contains(key)) << key;
    EXPECT_EQ(level["meshes"].size(), 2u);
    EXPECT_LE(level["screen_size"].get<double>(), previous_screen);
    previous_screen = level["screen_size"].get<double>();
  }
  EXPECT_TRUE(report.contains("screen_size_formula"));
}

TEST_F(LodCli, ObjInObjOut) {
  const fs::path in = dir / "torus.obj";
  ASSERT_TRUE(write_mesh(make_torus(24, 12), in).ok());
  const CliRun run = run_cli("-q lod '" + in.string() + "' -o '" + (dir / "l").string() + "' --levels 0.5,0.25 --no-hausdorff", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const ReadResult l2 = read_mesh(dir / "l" / "torus.lod2.obj");
  ASSERT_TRUE(l2.ok()) << l2.error;
  EXPECT_NEAR(double(tri_equivalent_count(l2.mesh)), 0.25 * 576, 0.05 * 576);
  const nlohmann::json report = nlohmann::json::parse(slurp(dir / "l" / "lods.json"));
  EXPECT_TRUE(report["levels"][0]["hausdorff"].is_null());
}

TEST(SimplifyScene, TargetSplitByTriangleEquivalentsOrPerMesh) {
  const Scene scene = make_test_scene();  // grid 96, torus 192 triangle-equivalents
  SceneSimplifyParams params;
  params.options.progress = false;
  params.options.target_tri_equivalent = 144;
  const SceneSimplifyResult split = simplify_scene(scene, params);
  ASSERT_TRUE(split.ok()) << split.error;
  ASSERT_EQ(split.report["meshes"].size(), 2u);
  EXPECT_EQ(split.report["meshes"][0]["target"].get<std::uint64_t>(), 48u);  // 144 · 96 / 288
  EXPECT_EQ(split.report["meshes"][1]["target"].get<std::uint64_t>(), 96u);  // 144 · 192 / 288
  EXPECT_EQ(split.target, 144u);
  EXPECT_EQ(split.achieved, split.scene.tri_equivalent_count());
  // Nodes and materials unchanged; the instanced grid reduced once.
  EXPECT_EQ(split.scene.nodes.size(), scene.nodes.size());
  EXPECT_EQ(split.scene.meshes.size(), 2u);
  EXPECT_EQ(split.scene.nodes[1].meshes, split.scene.nodes[2].meshes);

  params.per_mesh = true;
  params.options.target_tri_equivalent = 80;
  const SceneSimplifyResult each = simplify_scene(scene, params);
  ASSERT_TRUE(each.ok()) << each.error;
  EXPECT_EQ(each.report["meshes"][0]["target"].get<std::uint64_t>(), 80u);
  EXPECT_EQ(each.report["meshes"][1]["target"].get<std::uint64_t>(), 80u);

  EXPECT_FALSE(simplify_scene(Scene{}, params).ok());
}

TEST_F(LodCli, ObjLevelsElsewhereStillFindTheMtl) {
  fs::create_directories(dir / "in");
  PolyMesh grid = make_grid(8, 8);
  grid.material_names = {"paint"};
  grid.face_material.assign(grid.num_faces(), 0);
  grid.material_libraries = {"g.mtl"};
  ASSERT_TRUE(write_mesh(grid, dir / "in" / "g.obj").ok());
  write_text(dir / "in" / "g.mtl", "newmtl paint\nKd 1 0 0\n");
  const CliRun run = run_cli("-q lod '" + (dir / "in" / "g.obj").string() + "' -o '" + (dir / "out").string() +
                                 "' --levels 0.5 --no-hausdorff", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const ReadResult level = read_mesh(dir / "out" / "g.lod1.obj");
  ASSERT_TRUE(level.ok()) << level.error;
  ASSERT_EQ(level.mesh.material_libraries.size(), 1u);
  EXPECT_TRUE(fs::exists(dir / "out" / level.mesh.material_libraries[0])) << level.mesh.material_libraries[0];
}
