// Protected regions (issue 34; docs/protect.md): weight-1 vertices keep their exact input position
// and the edges between them, through every pass and the surface fit; partial weights move the
// collapses elsewhere; the weights' sources (files, colours) and their one-line errors.
#include "cli_runner.h"
#include "mesh/connectivity.h"
#include "post/cluster_collapse.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"
#include "quadlod/lod.h"
#include "quadlod/protect.h"
#include "quadlod/scene.h"
#include "quadlod/simplify.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>

namespace quadlod {
namespace {

using testing::CliRun;
using testing::run_cli;

// A curved n × n grid (a bump), so every collapse has a price and the surface fit moves vertices.
PolyMesh bumpy_grid(Index n) {
  PolyMesh mesh = make_grid(n, n, 1.0, 1.0);
  for (Vec3& p : mesh.positions) {
    const double dx = p.x() - 0.5, dy = p.y() - 0.5;
    p.z() = 0.15 * std::exp(-6.0 * (dx * dx + dy * dy)) + 0.01 * std::sin(7.3 * p.x()) * std::cos(5.1 * p.y());
  }
  return mesh;
}

using Position = std::array<double, 3>;
Position key(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

// Output vertex at exactly each position (the first when several share one).
std::map<Position, Index> exact_positions(const PolyMesh& mesh) {
  std::map<Position, Index> at;
  for (Index v = 0; v < mesh.num_vertices(); ++v) at.emplace(key(mesh.positions[v]), v);
  return at;
}

std::set<std::pair<Index, Index>> edge_set(const PolyMesh& mesh) {
  std::set<std::pair<Index, Index>> edges;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const auto fv = mesh.face_vertices(f);
    for (std::size_t i = 0; i < fv.size(); ++i) {
      const Index a = fv[i], b = fv[(i + 1) % fv.size()];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  return edges;
}

struct Untouched {
  Index protected_vertices = 0, moved = 0;  // weight-1 input vertices, and those not found exactly
  Index protected_edges = 0, lost = 0;      // input edges between two of them, and those missing
};

Untouched check_protected(const PolyMesh& input, const std::vector<double>& weights, const PolyMesh& output) {
  Untouched u;
  const auto at = exact_positions(output);
  const auto out_edges = edge_set(output);
  for (Index v = 0; v < input.num_vertices(); ++v)
    if (weights[v] >= 1.0) {
      ++u.protected_vertices;
      u.moved += at.count(key(input.positions[v])) == 0;
    }
  for (const auto& [a, b] : edge_set(input)) {
    if (weights[a] < 1.0 || weights[b] < 1.0) continue;
    ++u.protected_edges;
    const auto ia = at.find(key(input.positions[a])), ib = at.find(key(input.positions[b]));
    if (ia == at.end() || ib == at.end() ||
        !out_edges.count({std::min(ia->second, ib->second), std::max(ia->second, ib->second)}))
      ++u.lost;
  }
  return u;
}

// Input vertices that are not at their exact position in the output (moved or merged).
Index moved_where(const PolyMesh& input, const PolyMesh& output, const std::function<bool(const Vec3&)>& where) {
  const auto at = exact_positions(output);
  Index moved = 0;
  for (const Vec3& p : input.positions)
    if (where(p) && !at.count(key(p))) ++moved;
  return moved;
}

TEST(Protect, ProtectedRegionOfAGridComesOutUntouched) {
  const PolyMesh grid = bumpy_grid(24);
  std::vector<double> w(grid.num_vertices(), 0.0);
  for (Index v = 0; v < grid.num_vertices(); ++v) w[v] = grid.positions[v].x() > 0.8 ? 1.0 : 0.0;  // 5 of 25 columns
  SimplifyOptions options;
  options.ratio = 0.3;
  options.protect_weights = w;
  const SimplifyResult r = simplify(grid, options);
  ASSERT_TRUE(r.ok()) << r.error;
  const Untouched u = check_protected(grid, w, r.mesh);
  EXPECT_EQ(u.protected_vertices, 5u * 25u);
  EXPECT_EQ(u.moved, 0u);
  EXPECT_EQ(u.protected_edges, 4u * 25u + 5u * 24u);
  EXPECT_EQ(u.lost, 0u);
  // The rest of the grid pays for the target: within Eq. 2's band.
  EXPECT_NEAR(double(r.achieved), double(r.target), 0.03 * double(r.target));
  // The weights follow the vertices: exactly the untouched ones carry weight 1.
  ASSERT_EQ(r.protect_weights.size(), r.mesh.num_vertices());
  EXPECT_EQ(Index(std::count(r.protect_weights.begin(), r.protect_weights.end(), 1.0)), u.protected_vertices);
  const auto at = exact_positions(r.mesh);
  for (Index v = 0; v < grid.num_vertices(); ++v)
    if (w[v] >= 1.0) EXPECT_EQ(r.protect_weights[at.at(key(grid.positions[v]))], 1.0);
  // Without weights the same region is reduced.
  SimplifyOptions plain = options;
  plain.protect_weights.clear();
  const SimplifyResult p = simplify(grid, plain);
  EXPECT_GT(check_protected(grid, w, p.mesh).moved, 50u);
}

// Everything at weight 1: nothing may merge, the mesh comes back as it was, and the note names the
// protection as the constraint that held the count up.
TEST(Protect, WhollyProtectedMeshComesBackUnchangedAndTheNoteSaysWhy) {
  const PolyMesh grid = bumpy_grid(6);
  SimplifyOptions options;
  options.ratio = 0.3;
  options.protect_weights.assign(grid.num_vertices(), 1.0);
  const SimplifyResult r = simplify(grid, options);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.mesh.positions, grid.positions);
  EXPECT_EQ(r.mesh.corner_vertex, grid.corner_vertex);
  EXPECT_NE(r.note.find("protect: 84 edges pinned between weight-1 vertices"), std::string::npos) << r.note;
}

// Weight-1 vertices scattered over a curved mesh whose coordinates are not float32 values (the
// decisions run on float32, the output gets the input's doubles back), with the surface fit on.
TEST(Protect, WeightOneVerticesAreBitExactAfterReductionWithTheSurfaceFit) {
  const PolyMesh vase = make_demo_vase(48, 40);
  std::vector<double> w(vase.num_vertices(), 0.0);
  std::mt19937 rng(7);
  std::uniform_int_distribution<Index> pick(0, vase.num_vertices() - 1);
  for (int k = 0; k < 200; ++k) w[pick(rng)] = 1.0;
  for (const int fit : {0, 2, 6}) {
    SimplifyOptions options;
    options.ratio = 0.3;
    options.surface_fit_iterations = fit;
    options.protect_weights = w;
    const SimplifyResult r = simplify(vase, options);
    ASSERT_TRUE(r.ok()) << r.error;
    const Untouched u = check_protected(vase, w, r.mesh);
    EXPECT_EQ(u.moved, 0u) << "surface fit " << fit;
    EXPECT_EQ(u.lost, 0u) << "surface fit " << fit;
    EXPECT_NEAR(double(r.achieved), double(r.target), 0.03 * double(r.target));
    if (fit > 0) EXPECT_GT(r.report["surface_fit"]["moved_vertices"].get<int>(), 0);
  }
}

// A symmetric grid, weight 0.5 on its left half: fewer of the left half's vertices move than of
// the right half's, and than of the left half without weights.
TEST(Protect, PartialWeightsShiftCollapsesAwayFromARegion) {
  PolyMesh grid = make_grid(20, 20, 2.0, 2.0);
  for (Vec3& p : grid.positions) {
    p.x() -= 1.0;
    p.y() -= 1.0;
    p.z() = 0.2 * (p.x() * p.x() + p.y() * p.y());  // mirror symmetric in x
  }
  auto left = [](const Vec3& p) { return p.x() < -1e-9; };
  auto right = [](const Vec3& p) { return p.x() > 1e-9; };
  std::vector<double> w(grid.num_vertices(), 0.0);
  for (Index v = 0; v < grid.num_vertices(); ++v) w[v] = left(grid.positions[v]) ? 0.5 : 0.0;
  for (const auto objective : {SimplifyOptions::Objective::Shape, SimplifyOptions::Objective::Paper}) {
    SimplifyOptions options;
    options.ratio = 0.5;
    options.objective = objective;
    options.time_limit_seconds = 0.0;  // paper: the greedy selection, deterministic
    const SimplifyResult plain = simplify(grid, options);
    options.protect_weights = w;
    const SimplifyResult weighted = simplify(grid, options);
    ASSERT_TRUE(plain.ok() && weighted.ok());
    const Index plain_left = moved_where(grid, plain.mesh, left), plain_right = moved_where(grid, plain.mesh, right);
    const Index left_moved = moved_where(grid, weighted.mesh, left), right_moved = moved_where(grid, weighted.mesh, right);
    // Symmetric without weights (within a tenth: ties are broken by id) ...
    EXPECT_NEAR(double(plain_left), double(plain_right), 0.1 * double(plain_right)) << to_string(objective);
    // ... and the weighted half loses far fewer vertices.
    EXPECT_LT(double(left_moved), 0.6 * double(plain_left)) << to_string(objective);
    EXPECT_LT(double(left_moved), 0.6 * double(right_moved)) << to_string(objective);
    EXPECT_NEAR(double(weighted.achieved), double(weighted.target), 0.03 * double(weighted.target));
  }
}

// The collapse's rule by hand: a cluster with one protected member lands exactly on it; a cluster
// joining two protected vertices through an unprotected one is refused.
TEST(Protect, CollapseLandsOnTheProtectedMemberAndRefusesTwo) {
  const PolyMesh grid = bumpy_grid(4);
  const Connectivity conn = build_connectivity(grid);
  auto id = [](Index i, Index j) { return j * 5 + i; };
  auto edge = [&](Index a, Index b) {
    for (Index e = 0; e < conn.num_edges; ++e)
      if ((conn.edge_vertices[e][0] == a && conn.edge_vertices[e][1] == b) ||
          (conn.edge_vertices[e][0] == b && conn.edge_vertices[e][1] == a))
        return e;
    return kInvalidIndex;
  };
  std::vector<std::uint8_t> prot(grid.num_vertices(), 0);
  prot[id(1, 2)] = 1;
  ClusterCollapseParams params;
  params.protected_vertices = &prot;
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  kept[edge(id(1, 2), id(2, 2))] = 0;
  const ClusterCollapseResult one = collapse_clusters(grid, conn, kept, params);
  ASSERT_EQ(one.stats.clusters, 1u);
  EXPECT_EQ(one.stats.placements_at_protected, 1u);
  EXPECT_EQ(one.mesh.positions[one.vertex_map[id(2, 2)]], grid.positions[id(1, 2)]);
  EXPECT_EQ(one.vertex_map[id(1, 2)], one.vertex_map[id(2, 2)]);

  prot[id(3, 2)] = 1;
  kept[edge(id(2, 2), id(3, 2))] = 0;
  const ClusterCollapseResult two = collapse_clusters(grid, conn, kept, params);
  EXPECT_GE(two.stats.refusals(CollapseRefusal::Protected), 1u);
  EXPECT_NE(two.vertex_map[id(1, 2)], two.vertex_map[id(3, 2)]);
  EXPECT_EQ(two.mesh.positions[two.vertex_map[id(1, 2)]], grid.positions[id(1, 2)]);
  EXPECT_EQ(two.mesh.positions[two.vertex_map[id(3, 2)]], grid.positions[id(3, 2)]);
}

// A protected vertex keeps a face: a cluster that would drop the last face around it (here the
// seven other corners of a cube merged into one, which leaves no face; feature rules off, so
// nothing else refuses it) is refused; unprotected, the same collapse leaves vertex 0 unused.
TEST(Protect, ClusterThatDropsTheLastFaceOfAProtectedVertexIsRefused) {
  const PolyMesh cube = make_cube(1, 1.0);
  ASSERT_EQ(cube.num_vertices(), 8u);
  const Connectivity conn = build_connectivity(cube);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  for (Index e = 0; e < conn.num_edges; ++e)
    if (conn.edge_vertices[e][0] != 0 && conn.edge_vertices[e][1] != 0) kept[e] = 0;
  ClusterCollapseParams params;
  params.respect_features = false;
  const ClusterCollapseResult plain = collapse_clusters(cube, conn, kept, params);
  ASSERT_EQ(plain.vertex_map[0], kInvalidIndex) << "the collapse must drop vertex 0's faces";
  std::vector<std::uint8_t> prot(cube.num_vertices(), 0);
  prot[0] = 1;
  params.protected_vertices = &prot;
  const ClusterCollapseResult guarded = collapse_clusters(cube, conn, kept, params);
  ASSERT_NE(guarded.vertex_map[0], kInvalidIndex);
  EXPECT_EQ(guarded.mesh.positions[guarded.vertex_map[0]], cube.positions[0]);
  EXPECT_GE(guarded.stats.refusals(CollapseRefusal::Protected), 1u);
}

// LOD chains carry the weights from level to level (level ℓ is reduced from level ℓ − 1).
TEST(Protect, LodChainKeepsProtectedVerticesAtEveryLevel) {
  const PolyMesh grid = bumpy_grid(24);
  LodChainParams params;
  params.ratios = {0.5, 0.25};
  params.measure_hausdorff = false;
  params.simplify.protect_weights.assign(grid.num_vertices(), 0.0);
  for (Index v = 0; v < grid.num_vertices(); ++v)
    if (grid.positions[v].y() < 0.15) params.simplify.protect_weights[v] = 1.0;
  const LodChainResult chain = lod_chain(grid, params);
  ASSERT_TRUE(chain.ok()) << chain.error;
  for (const LodLevel& level : chain.levels) {
    const Untouched u = check_protected(grid, params.simplify.protect_weights, level.mesh);
    EXPECT_EQ(u.moved, 0u) << level.ratio;
    EXPECT_EQ(u.lost, 0u) << level.ratio;
  }
}

// Weights from a colour channel are the same weights: the same output as from the array.
TEST(Protect, ColourChannelGivesTheSameReductionAsTheWeights) {
  PolyMesh grid = bumpy_grid(16);
  std::vector<double> w(grid.num_vertices(), 0.0);
  grid.vertex_colors.assign(grid.num_vertices(), Vec3(0.2, 0.0, 0.7));
  for (Index v = 0; v < grid.num_vertices(); ++v)
    if (grid.positions[v].x() < 0.3) {
      w[v] = 1.0;
      grid.vertex_colors[v].y() = 1.0;
    }
  SimplifyOptions by_weights;
  by_weights.ratio = 0.4;
  by_weights.protect_weights = w;
  SimplifyOptions by_colour;
  by_colour.ratio = 0.4;
  by_colour.protect_channel = *parse_protect_channel("color:g");
  const SimplifyResult a = simplify(grid, by_weights), b = simplify(grid, by_colour);
  ASSERT_TRUE(a.ok() && b.ok()) << b.error;
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.corner_vertex, b.mesh.corner_vertex);
  EXPECT_EQ(b.report["protect"]["source"], "color:g");
  EXPECT_EQ(check_protected(grid, w, b.mesh).moved, 0u);
  // No colours: an error saying so.
  grid.vertex_colors.clear();
  const SimplifyResult none = simplify(grid, by_colour);
  EXPECT_NE(none.error.find("no vertex colours"), std::string::npos) << none.error;
  // Bad weights: an error naming the vertex.
  by_weights.protect_weights[5] = 1.5;
  EXPECT_NE(simplify(grid, by_weights).error.find("vertex 5"), std::string::npos);
  by_weights.protect_weights.pop_back();
  EXPECT_NE(simplify(grid, by_weights).error.find("protect weights for"), std::string::npos);
}

class ProtectFile : public testing::ScratchDirTest {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    const auto path = dir / name;
    std::ofstream(path) << text;
    return path.string();
  }
};

TEST_F(ProtectFile, CommentsAndBlankLinesAreSkipped) {
  const std::string path = write("w.txt", "# header\n0\n\n  1 \n0.25\r\n# end\n");
  const ProtectWeightsRead r = read_protect_weights(path, 3);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.weights, (std::vector<double>{0.0, 1.0, 0.25}));
}

TEST_F(ProtectFile, BadFilesGiveOneLineErrorsNamingFileAndLine) {
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {"0\n1\nabc\n", ":3: 'abc' is not a number (one weight in [0, 1] per line)"},
      {"0\n# c\n1.5\n", ":3: weight 1.5 is outside [0, 1]"},
      {"0\n-0.1\n0\n", ":2: weight -0.1 is outside [0, 1]"},
      {"0\n1\n", ": 2 weights, the mesh has 3 vertices"},
      {"0\n1\n0\n\n1\n", ":5: weight for vertex 3, the mesh has 3 vertices"},
      {"0 1\n1\n0\n", ":1: '0 1' is not a number (one weight in [0, 1] per line)"},
  };
  for (const Case& c : cases) {
    const std::string path = write("bad.txt", c.text);
    const ProtectWeightsRead r = read_protect_weights(path, 3);
    EXPECT_EQ(r.error, path + c.expected);
  }
  EXPECT_NE(read_protect_weights((dir / "missing.txt").string()).error.find("missing.txt: cannot read"), std::string::npos);
}

// The CLI: --protect on simplify, lod and batch; the errors are one line naming the file, exit 2.
TEST_F(ProtectFile, CliSimplifyLodAndBatchTakeProtectFiles) {
  // The input as an OBJ file writes it (9 digits), read back: the values the output must repeat.
  const std::string mesh = (dir / "grid.obj").string();
  ASSERT_TRUE(write_mesh(bumpy_grid(12), mesh).ok());
  const PolyMesh grid = read_mesh(mesh).mesh;
  ASSERT_EQ(grid.num_vertices(), 169u);
  std::string text = "# protect x > 0.6\n";
  std::vector<double> w;
  for (const Vec3& p : grid.positions) {
    w.push_back(p.x() > 0.6 ? 1.0 : 0.0);
    text += p.x() > 0.6 ? "1\n" : "0\n";
  }
  const std::string weights = write("w.txt", text);
  const std::string out = (dir / "out.obj").string();
  CliRun run = run_cli("-q simplify '" + mesh + "' -o '" + out + "' --ratio 0.3 --protect '" + weights + "'", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ReadResult read = read_mesh(out);
  ASSERT_TRUE(read.ok());
  EXPECT_EQ(check_protected(grid, w, read.mesh).moved, 0u);
  EXPECT_EQ(check_protected(grid, w, read.mesh).lost, 0u);

  run = run_cli("-q lod '" + mesh + "' -o '" + (dir / "lods").string() + "' --levels 0.5,0.25 --no-hausdorff --protect '" + weights + "'", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const char* level : {"grid.lod1.obj", "grid.lod2.obj"}) {
    read = read_mesh((dir / "lods" / level).string());
    ASSERT_TRUE(read.ok()) << level;
    EXPECT_EQ(check_protected(grid, w, read.mesh).moved, 0u) << level;
  }

  std::ofstream(dir / "jobs.jsonl") << "{\"input\": \"grid.obj\", \"output\": \"b.obj\", \"ratio\": 0.3, \"protect\": \"w.txt\"}\n"
                                    << "{\"input\": \"grid.obj\", \"output\": \"c.obj\", \"ratio\": 0.3, \"protect\": \"short.txt\"}\n";
  write("short.txt", "1\n0\n");
  run = run_cli("batch '" + (dir / "jobs.jsonl").string() + "'", dir);
  read = read_mesh((dir / "b.obj").string());
  ASSERT_TRUE(read.ok()) << run.out << run.err;
  EXPECT_EQ(check_protected(grid, w, read.mesh).moved, 0u);
  EXPECT_NE(run.out.find("short.txt: 2 weights, the mesh has 169 vertices"), std::string::npos) << run.out;

  for (const auto& [body, expected] : std::vector<std::pair<std::string, std::string>>{
           {"0\nx\n", "bad.txt:2: 'x' is not a number"},
           {"2\n", "bad.txt:1: weight 2 is outside [0, 1]"},
           {"1\n1\n", "bad.txt: 2 weights, the mesh has 169 vertices"}}) {
    const std::string bad = write("bad.txt", body);
    for (const std::string& command :
         {"-q simplify '" + mesh + "' -o '" + out + "' --ratio 0.3", "-q lod '" + mesh + "' -o '" + (dir / "l2").string() + "' --count 1"}) {
      run = run_cli(command + " --protect '" + bad + "'", dir);
      EXPECT_EQ(run.exit_code, 2) << command;
      EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
      EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
    }
  }
}

// glTF COLOR_0 through assimp (issue 34, item 2): a .glb scene of a grid with red = 1 on a region
// and a torus without colours; `--protect-from color:r` keeps the grid's red vertices exactly and
// leaves the torus unprotected; a file for the whole scene (mesh after mesh) must hold one weight
// per vertex of both meshes.
TEST_F(ProtectFile, GlbColourChannelProtectsThroughTheScenePath) {
  Scene scene;
  PolyMesh grid = bumpy_grid(16);
  for (const Vec3& p : grid.positions) grid.vertex_colors.emplace_back(p.x() > 0.7 ? 1.0 : 0.0, 0.5, 0.5);
  scene.meshes = {{"grid", std::move(grid)}, {"torus", make_torus(24, 12)}};
  scene.nodes = {SceneNode{"root", kInvalidIndex, Eigen::Matrix4d::Identity(), {}},
                 SceneNode{"grid", 0, Eigen::Matrix4d::Identity(), {0}},
                 SceneNode{"torus", 0, Eigen::Matrix4d::Identity(), {1}}};
  scene.nodes[2].local(0, 3) = 3.0;  // beside the grid
  const std::string in = (dir / "in.glb").string(), out = (dir / "out.glb").string();
  ASSERT_TRUE(write_scene(scene, in).ok());
  const SceneReadResult before = read_scene(in);
  ASSERT_TRUE(before.ok()) << before.error;
  ASSERT_EQ(before.scene.meshes.size(), 2u);
  const PolyMesh& read_grid = before.scene.meshes[0].mesh.vertex_colors.empty() ? before.scene.meshes[1].mesh
                                                                                : before.scene.meshes[0].mesh;
  const std::vector<double> w = protect_weights_from_colors(read_grid, SimplifyOptions::ProtectChannel::Red);
  ASSERT_GT(std::count(w.begin(), w.end(), 1.0), 40);

  CliRun run = run_cli("-q simplify '" + in + "' -o '" + out + "' --ratio 0.3 --protect-from color:r", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const SceneReadResult after = read_scene(out);
  ASSERT_TRUE(after.ok()) << after.error;
  PolyMesh all;
  for (const SceneMesh& m : after.scene.meshes) all.positions.insert(all.positions.end(), m.mesh.positions.begin(), m.mesh.positions.end());
  const auto at = exact_positions(all);
  Index moved = 0;
  for (Index v = 0; v < read_grid.num_vertices(); ++v) moved += w[v] >= 1.0 && !at.count(key(read_grid.positions[v]));
  EXPECT_EQ(moved, 0u);

  std::size_t vertices = 0;
  for (const SceneMesh& m : before.scene.meshes) vertices += m.mesh.num_vertices();
  std::string text;
  for (std::size_t v = 0; v + 1 < vertices; ++v) text += "0\n";
  const std::string weights = write("scene_w.txt", text);
  run = run_cli("-q simplify '" + in + "' -o '" + out + "' --ratio 0.3 --protect '" + weights + "'", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("scene_w.txt: " + std::to_string(vertices - 1) + " weights, the mesh has " +
                         std::to_string(vertices) + " vertices"),
            std::string::npos)
      << run.err;
}

}  // namespace
}  // namespace quadlod
