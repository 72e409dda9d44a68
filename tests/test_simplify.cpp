// quadlod::simplify end to end (paper Fig. 2): generated meshes with known answers and corpus
// meshes against the output guarantees (issue: post-processing and `quadlod simplify`).
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "mesh/validation.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"
#include "quadlod/metrics.h"
#include "quadlod/simplify.h"
#include "topology/polychords.h"

#include "cli_runner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <tuple>
#include <filesystem>

namespace quadlod {
namespace {

MeshStats stats_of(const PolyMesh& mesh) { return compute_stats(mesh, build_connectivity(mesh)); }

// The output guarantees of §3.3 (docs/cluster_collapse.md) that can be read off the output alone.
void expect_valid(const PolyMesh& in, const PolyMesh& out, const std::string& what) {
  const MeshStats a = stats_of(in), b = stats_of(out);
  EXPECT_LE(b.nonmanifold_edges, a.nonmanifold_edges) << what;
  EXPECT_LE(b.degenerate_faces, a.degenerate_faces) << what;
  EXPECT_LE(b.duplicate_faces, a.duplicate_faces) << what;
  EXPECT_LE(b.zero_length_edges, a.zero_length_edges) << what;
  EXPECT_EQ(b.nonfinite_vertices, 0u) << what;
  EXPECT_EQ(b.unused_vertices, 0u) << what;
  // No face facing away from the input surface (docs/metrics.md §6b; the collapse's
  // `orientation` refusal enforces eval's rule).
  EvalParams ep;
  ep.samples = 1000;
  ep.curve_samples = 1000;
  EXPECT_EQ(evaluate(in, out, ep).flipped_faces, 0u) << what;
}

SimplifyOptions quick(double ratio) {
  SimplifyOptions o;
  o.ratio = ratio;
  o.time_limit_seconds = 1.0;
  return o;
}

// The scenarios of the paper's objective (Eq. 9 with the MIP search): its solver statistics,
// its greedy fallback and its known answers (tests/test_shape_selection.cpp has the default
// objective's).
SimplifyOptions quick_paper(double ratio) {
  SimplifyOptions o = quick(ratio);
  o.objective = SimplifyOptions::Objective::Paper;
  o.place_on_hard_edges = true;
  return o;
}

TEST(Simplify, RegularGridAtHalfLosesWholeChordsAndStaysAllQuads) {
  const PolyMesh grid = make_grid(8, 8, 1.0, 1.0);
  const SimplifyResult r = simplify(grid, quick_paper(0.5));
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.target, 64u);
  EXPECT_NEAR(double(r.achieved), 64.0, 0.03 * 64.0);
  EXPECT_EQ(r.triangles, 0u);
  EXPECT_EQ(r.ngons, 0u);
  expect_valid(grid, r.mesh, "grid");
  // Whole chords went: the result is again a regular a×b grid (every interior vertex has four
  // quads), with a·b = quads and (a + b) open chords instead of 16.
  const Connectivity conn = build_connectivity(r.mesh);
  const PolyChordResult chords = extract_polychords(r.mesh, conn);
  Index a_plus_b = 0;
  for (const PolyChord& c : chords.chords) a_plus_b += c.closed ? 0 : 1;
  EXPECT_LT(a_plus_b, 16u);
  bool found = false;
  for (Index a = 1; a <= 8; ++a)
    if (r.quads % a == 0 && a + r.quads / a == a_plus_b) found = true;
  EXPECT_TRUE(found) << r.quads << " quads, " << a_plus_b << " chords";
  // Geometry: a flat square stays the same flat square.
  const MeshStats s = stats_of(r.mesh);
  EXPECT_NEAR(s.bbox.min.x(), 0.0, 1e-9);
  EXPECT_NEAR(s.bbox.max.x(), 1.0, 1e-9);
  EXPECT_NEAR(s.bbox.max.z() - s.bbox.min.z(), 0.0, 1e-9);
  EXPECT_EQ(s.boundary_loops, 1u);
}

TEST(Simplify, CubeStaysAValidClosedMesh) {
  const PolyMesh cube = make_cube(4, 1.0);
  for (double ratio : {0.8, 0.5, 0.3}) {
    const SimplifyResult r = simplify(cube, quick(ratio));
    ASSERT_TRUE(r.ok()) << r.error;
    const MeshStats s = stats_of(r.mesh);
    EXPECT_EQ(s.boundary_edges, 0u) << ratio;
    EXPECT_EQ(s.nonmanifold_edges, 0u) << ratio;
    EXPECT_EQ(s.nonmanifold_vertices, 0u) << ratio;
    EXPECT_EQ(s.components, 1u) << ratio;
    expect_valid(cube, r.mesh, "cube " + std::to_string(ratio));
    // Within the band, or the miss is explained.
    const double dev = std::abs(double(r.achieved) - double(r.target)) / double(r.target);
    if (dev > 0.03) {
      EXPECT_FALSE(r.note.empty()) << ratio;
    }
    // Euler characteristic of a sphere.
    const Connectivity conn = build_connectivity(r.mesh);
    EXPECT_EQ(std::int64_t(r.mesh.num_vertices()) - std::int64_t(conn.num_edges) + std::int64_t(r.mesh.num_faces()), 2)
        << ratio;
  }
}

TEST(Simplify, NothingToDoAtFullSize) {
  const PolyMesh torus = make_torus(12, 8);
  const SimplifyResult r = simplify(torus, quick(1.0));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.achieved, r.input_tri_equivalent);
  EXPECT_NE(r.note.find("nothing to do"), std::string::npos) << r.note;
  EXPECT_EQ(r.mesh.num_faces(), torus.num_faces());
}

// n separate unit right triangles on a 20-wide lattice: every edge is a boundary.
PolyMesh lone_triangles(int n) {
  PolyMesh lone;
  for (int k = 0; k < n; ++k) {
    const double x = 2.0 * (k % 20), y = 2.0 * (k / 20);
    const Index a = lone.add_vertex({x, y, 0}), b = lone.add_vertex({x + 1, y, 0}),
                c = lone.add_vertex({x + 1, y + 1, 0});
    lone.add_face({a, b, c});
  }
  return lone;
}

// Lone triangles: every edge is a boundary, and collapsing any of them would take a whole part
// away. With --seams strict no part vanishes: the first pass finds nothing it may remove, and the
// run ends there rather than repeating the same nothing in every planned pass; the note says how
// far from the target it stopped.
TEST(Simplify, AMeshWithNothingToRemoveEndsAfterOnePass) {
  const PolyMesh lone = lone_triangles(200);
  SimplifyOptions o;
  o.ratio = 0.2;  // several passes planned
  o.seams = SimplifyOptions::SeamPolicy::Strict;
  const SimplifyResult r = simplify(lone, o);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_GT(r.report["passes_planned"].get<int>(), 1);
  EXPECT_EQ(r.passes_used, 1);
  EXPECT_EQ(r.achieved, r.input_tri_equivalent);
  EXPECT_EQ(r.mesh.num_faces(), lone.num_faces());
  EXPECT_NE(r.note.find("after 1 pass:"), std::string::npos) << r.note;
}

// The same lone triangles with --seams auto (the default): the first pass stalls, so parts below
// the crossing bound may vanish (issue 32), and the run reaches the target; the report says which
// bound each pass ran with.
TEST(Simplify, AStalledPassLetsSmallPartsVanish) {
  const PolyMesh lone = lone_triangles(200);
  SimplifyOptions o;
  o.ratio = 0.2;
  const SimplifyResult r = simplify(lone, o);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_NEAR(double(r.achieved), 40.0, 0.03 * 40.0) << r.note;
  const auto& passes = r.report["passes"];
  EXPECT_EQ(passes[0]["vanishing_part_area"].get<double>(), 0.0);
  EXPECT_GT(passes.back()["vanishing_part_area"].get<double>(), 0.5);  // a triangle's area
  // Whatever survives is a whole input triangle.
  for (Index f = 0; f < r.mesh.num_faces(); ++f) EXPECT_EQ(r.mesh.face_size(f), 3u);
}

// A mesh and its float32-rounded copy (what FBX and glTF store) reduce to the same faces, and
// the vertices that did not move keep the input's own coordinates.
TEST(Simplify, DecisionsAreOnFloat32SoTheStoragePrecisionDoesNotMatter) {
  PolyMesh vase = make_demo_vase(40, 30);
  for (Vec3& p : vase.positions) p += Vec3(1e-9, -3e-9, 2e-9).cwiseProduct(p);  // off the float32 grid
  // Through a volatile: g++ 12.2 -O2 vectorizes double(float(x)) of two lanes into a plain copy.
  auto to_float32 = [](double x) {
    volatile float f = static_cast<float>(x);
    return static_cast<double>(f);
  };
  PolyMesh as_float = vase;
  Index moved = 0;
  for (Vec3& p : as_float.positions)
    for (int i = 0; i < 3; ++i) {
      const double r = to_float32(p[i]);
      moved += r != p[i];
      p[i] = r;
    }
  ASSERT_GT(moved, 2 * as_float.num_vertices());  // x, y and z off the float32 grid before
  SimplifyOptions o;
  o.ratio = 0.3;
  // Kept vertices keep their input coordinates in the collapse; the final fit then moves them
  // (it runs on the float32 input of both runs alike: tests/test_surface_fit.cpp).
  o.surface_fit_iterations = 0;
  const SimplifyResult a = simplify(vase, o), b = simplify(as_float, o);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.mesh.corner_vertex, b.mesh.corner_vertex);
  EXPECT_EQ(a.mesh.face_offsets, b.mesh.face_offsets);
  EXPECT_EQ(a.report["float32_decisions"], true);
  // Kept vertices: exactly an input vertex's position, of the input each run was given.
  std::set<std::tuple<double, double, double>> input_points, float_points;
  for (const Vec3& p : vase.positions) input_points.insert({p.x(), p.y(), p.z()});
  for (const Vec3& p : as_float.positions) float_points.insert({p.x(), p.y(), p.z()});
  Index kept = 0;
  for (Index v = 0; v < a.mesh.num_vertices(); ++v) {
    const Vec3& p = a.mesh.positions[v];
    const Vec3& q = b.mesh.positions[v];
    if (float_points.count({q.x(), q.y(), q.z()})) {
      ++kept;
      EXPECT_TRUE(input_points.count({p.x(), p.y(), p.z()})) << "vertex " << v << " lost its input coordinates";
    }
    EXPECT_LT((p - q).norm(), 1e-6) << v;
  }
  EXPECT_GT(kept, 10u);  // 27 of 368 at this ratio: the rest were merged
  // In place: the same output bytes, and the input is given back unchanged.
  PolyMesh own = vase;
  const SimplifyResult c = simplify_in_place(own, o);
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(own.positions, vase.positions);
  EXPECT_EQ(own.uv_sets[0].values, vase.uv_sets[0].values);
  EXPECT_EQ(c.mesh.positions, a.mesh.positions);
  EXPECT_EQ(c.mesh.corner_vertex, a.mesh.corner_vertex);
  EXPECT_EQ(c.mesh.uv_sets[0].values, a.mesh.uv_sets[0].values);
  // Deciding on the doubles is still there.
  o.float32_decisions = false;
  EXPECT_FALSE(simplify(vase, o).report.contains("float32_decisions"));
}

TEST(Simplify, BadInputIsAnErrorNotACrash) {
  PolyMesh torus = make_torus(6, 4);
  torus.positions[3].x() = std::nan("");
  const SimplifyResult r = simplify(torus, quick(0.5));
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.error.find("vertex"), std::string::npos) << r.error;
}

TEST(Simplify, ReportHasStagesRoundsAndSolverStatistics) {
  const SimplifyResult r = simplify(make_demo_vase(24, 16), quick_paper(0.5));
  ASSERT_TRUE(r.ok()) << r.error;
  const auto& rep = r.report;
  for (const char* key : {"analysis", "selection", "dual_repair", "collapse", "rounds", "stage_seconds",
                          "target", "achieved", "options"})
    EXPECT_TRUE(rep.contains(key)) << key;
  ASSERT_GE(rep["rounds"].size(), 1u);
  int chosen = 0;
  for (const auto& round : rep["rounds"]) chosen += round["chosen"].get<bool>();
  EXPECT_EQ(chosen, 1);
  EXPECT_EQ(rep["achieved"].get<std::uint64_t>(), r.achieved);
  EXPECT_TRUE(rep["selection"].contains("formulation_rows"));
  EXPECT_TRUE(rep["selection"]["solver"].contains("status"));
}

TEST(Simplify, RoundsPinRefusedCollapsesAndReAim) {
  // The best round is the result, so allowing more rounds never moves the output away from
  // the target; with one round the report lists exactly one.
  const PolyMesh cube = make_cube(4, 1.0);
  SimplifyOptions one = quick(0.3);
  one.max_rounds = 1;
  SimplifyOptions four = quick(0.3);
  const SimplifyResult a = simplify(cube, one), b = simplify(cube, four);
  ASSERT_TRUE(a.ok() && b.ok());
  const double dev_a = std::abs(double(a.achieved) - double(a.target));
  const double dev_b = std::abs(double(b.achieved) - double(b.target));
  EXPECT_LE(dev_b, dev_a);  // the best round is kept, so more rounds never do worse
  EXPECT_EQ(a.report["rounds"].size(), 1u);
}

TEST(Simplify, LargeReductionsRunInPassesOfEqualRatio) {
  // 0.2 with pass_ratio 0.5: k = ⌈log 0.2 / log 0.5⌉ = 3 planned passes aiming at N0·0.2^(i/3).
  const PolyMesh torus = make_torus(32, 20);
  const SimplifyResult r = simplify(torus, quick_paper(0.2));
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.report["passes_planned"].get<int>(), 3);
  const auto& passes = r.report["passes"];
  ASSERT_GE(passes.size(), 1u);
  const double n0 = double(r.input_tri_equivalent), n = double(r.target);
  for (std::size_t i = 0; i + 1 < passes.size() && i < 2; ++i)
    EXPECT_EQ(passes[i]["target"].get<std::uint64_t>(),
              static_cast<std::uint64_t>(std::llround(n0 * std::pow(n / n0, double(i + 1) / 3))));
  // Each pass starts from the previous one's output.
  for (std::size_t i = 1; i < passes.size(); ++i)
    EXPECT_EQ(passes[i]["input_tri_equivalent"], passes[i - 1]["achieved"]);
  EXPECT_EQ(r.passes_used, static_cast<int>(passes.size()));
  const double dev = std::abs(double(r.achieved) - n) / n;
  if (dev > 0.03) {
    EXPECT_FALSE(r.note.empty());
  }
  expect_valid(torus, r.mesh, "torus 0.2");
  // One pass is the paper's single selection.
  SimplifyOptions one = quick(0.2);
  one.max_passes = 1;
  const SimplifyResult s = simplify(torus, one);
  ASSERT_TRUE(s.ok()) << s.error;
  EXPECT_EQ(s.passes_used, 1);
  EXPECT_EQ(s.report["passes"].size(), 1u);
}

TEST(Simplify, UvSeamsSurviveAndUvsFollowTheMovedVertices) {
  // The demo vase has a cylindrical chart with a seam, a disc chart and an n-gon lid chart.
  const PolyMesh vase = make_demo_vase(24, 16);
  for (double ratio : {0.5, 0.25}) {
    const SimplifyResult r = simplify(vase, quick(ratio));
    ASSERT_TRUE(r.ok()) << r.error;
    EvalParams ep;
    ep.samples = 20000;
    const EvalResult e = evaluate(vase, r.mesh, ep);
    ASSERT_TRUE(e.ok()) << e.error;
    EXPECT_EQ(e.seams_torn, 0u) << ratio;
    EXPECT_EQ(e.uv_islands_out, e.uv_islands_in) << ratio;
    EXPECT_LT(e.uv_error_mean, 0.01) << ratio;
    EXPECT_GT(r.report["collapse"]["uv_values_projected"].get<Index>(), 0u) << ratio;
    // The exact accounting from provenance (composed over the passes at 0.25) agrees: every
    // island survives whole, none merged or split.
    const auto& u = r.report["uv_islands"];
    EXPECT_EQ(u["in"].get<Index>(), e.uv_islands_in) << ratio;
    EXPECT_EQ(u["out"].get<Index>(), u["in"].get<Index>()) << ratio;
    EXPECT_EQ(u["vanished"].get<Index>() + u["merged"].get<Index>() + u["split"].get<Index>(), 0u) << ratio;
  }
}

// The output's UV seam edges (set 0) as vertex pairs, and the number of distinct vertices on them.
struct SeamGraph {
  std::vector<std::array<Index, 2>> edges;
  Index vertices = 0;
};
SeamGraph uv_seams(const PolyMesh& m) {
  const Connectivity conn = build_connectivity(m);
  const FeatureEdges fe = find_feature_edges(m, conn);
  SeamGraph g;
  std::vector<std::uint8_t> on(m.num_vertices(), 0);
  for (Index e = 0; e < conn.num_edges; ++e)
    if (fe.edge_bits[e] & kFeatureUvSeam) {
      g.edges.push_back(conn.edge_vertices[e]);
      for (Index v : conn.edge_vertices[e]) on[v] = 1;
    }
  for (auto x : on) g.vertices += x;
  return g;
}

// Issue 32: a UV-split cylinder (make_cylinder's seam at u = 0 | 1, 25 vertices from the bottom
// rim to the top one) reduced to a tenth: far fewer rings than the seam has vertices, so the seam
// must shorten. It stays one seam: a single path of seam edges from one rim to the other, every
// inner vertex on two of them, its two ends on the rims, none of it torn, one island.
TEST(Simplify, AUvSplitCylinderSeamShortensAndStaysOneSeam) {
  const PolyMesh cylinder = make_cylinder(16, 24);
  ASSERT_EQ(uv_seams(cylinder).vertices, 25u);
  SimplifyOptions o;
  o.ratio = 0.1;
  const SimplifyResult r = simplify(cylinder, o);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_LE(std::abs(double(r.achieved) - double(r.target)), 0.03 * double(r.target)) << r.note;
  const SeamGraph seam = uv_seams(r.mesh);
  ASSERT_GE(seam.edges.size(), 1u);
  EXPECT_LT(seam.vertices, 25u);
  EXPECT_EQ(seam.vertices, seam.edges.size() + 1);  // a path: one more vertex than edges ...
  std::vector<Index> degree(r.mesh.num_vertices(), 0);
  for (const auto& e : seam.edges)
    for (Index v : e) ++degree[v];
  Index ends = 0;
  for (Index v = 0; v < r.mesh.num_vertices(); ++v) {
    EXPECT_LE(degree[v], 2u) << v;  // ... that never branches
    if (degree[v] == 1) {
      ++ends;
      const double z = r.mesh.positions[v].z();
      EXPECT_TRUE(z == 0.0 || z == 1.0) << "end " << v << " at z = " << z;  // on a rim
    }
  }
  EXPECT_EQ(ends, 2u);
  EvalParams ep;
  ep.samples = 20000;
  const EvalResult e = evaluate(cylinder, r.mesh, ep);
  EXPECT_EQ(e.seams_torn, 0u);
  EXPECT_EQ(e.uv_islands_out, 1u);
}

// The same cylinder cut into eight UV islands by ring seams every 3 rings: the vertical seam meets
// them at 7 junctions (corners of the strict lines; until issue 32 every edge between two of
// them was pinned, and the run stopped at +10.4 % of a tenth). At a tenth the run lands on its
// target without crossing a line: every island keeps its faces, none splits, no seam is torn,
// and the vertical seam has shortened through its junctions.
TEST(Simplify, SeamsShortenThroughTheirJunctions) {
  PolyMesh cylinder = make_cylinder(16, 24);
  UvSet& uv = cylinder.uv_sets[0];
  const Index base = static_cast<Index>(uv.values.size());
  for (int band = 1; band < 8; ++band)
    for (Index k = 0; k < base; ++k) uv.values.push_back(uv.values[k] + Vec2(0.0, 2.0 * band));
  for (Index f = 0; f < cylinder.num_faces(); ++f)
    for (Index c = cylinder.face_begin(f); c < cylinder.face_end(f); ++c) uv.corner[c] += (f / 16 / 3) * base;
  const Connectivity conn = build_connectivity(cylinder);
  const FeatureEdges fe = find_feature_edges(cylinder, conn);
  ASSERT_EQ(find_uv_islands(cylinder, conn, 0).num_islands, 8u);
  for (Index ring = 3; ring < 24; ring += 3) ASSERT_TRUE(fe.vertex_corner[ring * 16]) << ring;
  SimplifyOptions o;
  o.ratio = 0.1;
  const SimplifyResult r = simplify(cylinder, o);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_LE(std::abs(double(r.achieved) - double(r.target)), 0.03 * double(r.target)) << r.note;
  EXPECT_EQ(r.report["seams"]["line_crossings"], 0);
  const auto& u = r.report["uv_islands"];
  EXPECT_EQ(u["out"], 8);
  EXPECT_EQ(u["split"].get<int>() + u["merged"].get<int>() + u["vanished"].get<int>(), 0);
  EvalParams ep;
  ep.samples = 20000;
  const EvalResult e = evaluate(cylinder, r.mesh, ep);
  EXPECT_EQ(e.seams_torn, 0u);
  EXPECT_EQ(e.uv_islands_out, 8u);
  // Vertices on the vertical seam (x = 0.5, y = 0): 25 in the input, 9 of them corners.
  Index on_seam = 0;
  for (const Vec3& p : r.mesh.positions) on_seam += std::abs(p.y()) < 1e-9 && p.x() > 0.0;
  EXPECT_LT(on_seam, 9u);
}

// Far LODs (issue 32): below SimplifyOptions::bend_lines_below_ratio, once crossing islands no
// longer helps, a stalled run lets lines bend. The cylinder's rims are 16-gons (radius 0.5): an
// output edge over k of their edges leaves them by (r − r cos(kπ/16)) / (2r sin(kπ/16)) of its
// length at its midpoint, 0.134 for k = 3 and 0.207 for k = 4, so within the strict tolerance
// (0.2) each rim keeps at least ⌈16/3⌉ = 6 edges and a 2 % budget (15 tri-equivalents) is out of
// reach. Bent, the rims shorten further and the run gets closer.
int boundary_edges(const PolyMesh& mesh) {
  const Connectivity conn = build_connectivity(mesh);
  int n = 0;
  for (std::size_t e = 0; e + 1 < conn.edge_corner_offsets.size(); ++e)
    n += conn.edge_corner_offsets[e + 1] - conn.edge_corner_offsets[e] == 1;
  return n;
}

TEST(Simplify, FarBelowTheBendRatioCurvedLinesBendAndTheRunGetsCloser) {
  const PolyMesh cylinder = make_cylinder(16, 24);
  SimplifyOptions kept;
  kept.ratio = 0.02;
  kept.bend_lines_below_ratio = 0.0;
  const SimplifyResult a = simplify(cylinder, kept);
  ASSERT_TRUE(a.ok()) << a.error;
  EXPECT_EQ(a.report["seams"]["line_tolerance"].get<double>(), 0.2);
  EXPECT_GE(boundary_edges(a.mesh), 12);
  SimplifyOptions bend;
  bend.ratio = 0.02;
  const SimplifyResult b = simplify(cylinder, bend);
  ASSERT_TRUE(b.ok()) << b.error;
  EXPECT_GT(b.report["seams"]["line_tolerance"].get<double>(), 0.2);
  EXPECT_LE(b.report["seams"]["line_tolerance"].get<double>(), bend.max_line_tolerance);
  EXPECT_LT(boundary_edges(b.mesh), 12);
  EXPECT_LT(b.achieved, a.achieved);
  expect_valid(cylinder, b.mesh, "bent");
  // Passes before the bend ran at the strict tolerance; the report shows where it rose.
  const auto& passes = b.report["passes"];
  EXPECT_EQ(passes[0]["line_tolerance"].get<double>(), 0.2);
  EXPECT_GT(passes.back()["line_tolerance"].get<double>(), 0.2);
  // --seams strict never bends; neither does a target at or above the bend ratio.
  SimplifyOptions strict = bend;
  strict.seams = SimplifyOptions::SeamPolicy::Strict;
  const SimplifyResult c = simplify(cylinder, strict);
  ASSERT_TRUE(c.ok()) << c.error;
  EXPECT_EQ(c.report["seams"]["line_tolerance"].get<double>(), 0.2);
  EXPECT_GE(boundary_edges(c.mesh), 12);
  SimplifyOptions tenth;
  tenth.ratio = 0.1;
  const SimplifyResult d = simplify(cylinder, tenth);
  ASSERT_TRUE(d.ok()) << d.error;
  EXPECT_EQ(d.report["seams"]["line_tolerance"].get<double>(), 0.2);
  EXPECT_GE(boundary_edges(d.mesh), 12);
}

TEST(SimplifyCli, WritesOutputAndReportAndNeverOverwritesTheInput) {
  using namespace quadlod::testing;
  const auto dir = scratch_dir("simplify-cli");
  const auto in = dir / "vase.obj";
  ASSERT_EQ(run_cli("-q generate vase -o '" + in.string() + "'", dir).exit_code, 0);
  const std::string before = slurp(in);
  const CliRun ok = run_cli("-q simplify '" + in.string() + "' -o '" + (dir / "out.obj").string() +
                                "' --ratio 0.5 --time-limit 1 --report '" + (dir / "r.json").string() + "'",
                            dir);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.out.find("simplify: target"), std::string::npos) << ok.out;
  const auto report = nlohmann::json::parse(slurp(dir / "r.json"));
  EXPECT_TRUE(report.contains("stage_seconds"));
  EXPECT_TRUE(report["options"]["greedy_fallback"].get<bool>());
  const ReadResult out = read_mesh(dir / "out.obj");
  ASSERT_TRUE(out.ok()) << out.error;
  EXPECT_EQ(report["achieved"].get<std::uint64_t>(), tri_equivalent_count(out.mesh));
  EXPECT_TRUE(out.mesh.has_uvs());  // the vase's UVs reach the output
  // The output path naming the input is refused, and the input is untouched.
  const CliRun same = run_cli("-q simplify '" + in.string() + "' -o '" + in.string() + "' --ratio 0.5", dir);
  EXPECT_EQ(same.exit_code, 2);
  EXPECT_NE(same.err.find("refusing to overwrite the input"), std::string::npos) << same.err;
  EXPECT_EQ(slurp(in), before);
  // The fallback can be switched off (bench/selection_quality measures the selection alone).
  const CliRun off = run_cli("-q simplify '" + in.string() + "' -o '" + (dir / "off.obj").string() +
                                 "' --ratio 0.5 --time-limit 1 --no-greedy-fallback --report '" + (dir / "off.json").string() + "'",
                             dir);
  EXPECT_EQ(off.exit_code, 0) << off.err;
  const auto off_report = nlohmann::json::parse(slurp(dir / "off.json"));
  EXPECT_FALSE(off_report["options"]["greedy_fallback"].get<bool>());
  EXPECT_FALSE(off_report.contains("fallback"));
  // No target is a usage error.
  EXPECT_EQ(run_cli("-q simplify '" + in.string() + "' -o '" + (dir / "x.obj").string() + "'", dir).exit_code, 1);
  std::filesystem::remove_all(dir);
}

#ifdef QUADLOD_CORPUS_DIR
// Rounds that undo (docs/formulation.md "Rounds"): each may only undo collapses of the closest
// round below N so far, so its count is never below that round's.
void expect_undoing_rounds_only_restore(const nlohmann::json& pass_report, std::int64_t target, const std::string& what) {
  std::int64_t below = -1;
  for (const auto& round : pass_report["rounds"]) {
    const std::int64_t achieved = round["achieved"];
    if (round.value("undoing", false)) {
      EXPECT_GE(below, 0) << what << ": undoing without a round below N";
      EXPECT_GE(achieved, below) << what << " round " << round["round"];
    }
    if (achieved < target) below = std::max(below, achieved);
  }
}

TEST(SimplifyCorpus, SmallCorpusMeshesAreValidAndOnTarget) {
  const std::filesystem::path dir = QUADLOD_CORPUS_DIR;
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << dir << " not present";
  for (const char* name : {"opensubdiv_bishop_cage.obj", "blender_suzanne.obj", "yofrankie_ram.obj"}) {
    const ReadResult in = read_mesh(dir / name);
    ASSERT_TRUE(in.ok()) << in.error;
    for (double ratio : {0.6, 0.3}) {
      const SimplifyResult r = simplify(in.mesh, quick(ratio));
      ASSERT_TRUE(r.ok()) << name << ": " << r.error;
      expect_valid(in.mesh, r.mesh, std::string(name) + " " + std::to_string(ratio));
      const double dev = std::abs(double(r.achieved) - double(r.target)) / double(r.target);
      if (dev > 0.03) {
        EXPECT_FALSE(r.note.empty()) << name << " " << ratio;
      }
      EXPECT_GT(r.quads, 0u) << name;
      const std::string what = std::string(name) + " " + std::to_string(ratio);
      if (r.report.contains("passes")) {
        for (const auto& pass : r.report["passes"])
          expect_undoing_rounds_only_restore(pass["report"], pass["target"], what);
      } else {
        expect_undoing_rounds_only_restore(r.report, std::int64_t(r.target), what);
      }
    }
  }
}

// flightgear_cg57_cruiser_hd at 0.6 with the greedy selection (deterministic): a 24-quad UV
// island used to leave the collapse in two pieces that meet on one output side carrying five
// faces — three of its own, two of a coincident twin sheet — which find_uv_islands does not join
// across. The collapse now counts such sides as cuts and refuses the clusters at their ends
// (docs/attributes.md, "Islands"). Exact accounting from provenance: nothing split or merged.
TEST(SimplifyCorpus, IslandsAreNotCutAtSidesWithMoreThanTwoFaces) {
  const std::filesystem::path file = std::filesystem::path(QUADLOD_CORPUS_DIR) / "flightgear_cg57_cruiser_hd.obj";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not present";
  const ReadResult in = read_mesh(file);
  ASSERT_TRUE(in.ok()) << in.error;
  SimplifyOptions o;
  o.ratio = 0.6;
  o.time_limit_seconds = 0.0;
  const SimplifyResult r = simplify(in.mesh, o);
  ASSERT_TRUE(r.ok()) << r.error;
  const auto& islands = r.report["uv_islands"];
  EXPECT_EQ(islands["in"], 12347);
  EXPECT_EQ(islands["appeared"], 0);
  EXPECT_EQ(islands["vanished"], islands["vanished_below_one_face"]);
  EXPECT_EQ(std::int64_t(islands["out"]), std::int64_t(islands["in"]) - std::int64_t(islands["vanished"]) +
                                              std::int64_t(islands["split_extra"]) -
                                              std::int64_t(islands["merged_reduction"]));
  // No island worth an output face is split. Since issue 32 a line shortens through its
  // junctions, and one island smaller than that (7635: an octagonal cap and its 8-quad rim,
  // 0.045 of the 0.176 an output face has, whose UVs differ across most of the rim) falls apart
  // by its UVs in pass 3 of 5: each pass checks the islands of its own input, and the accounting
  // those of the original.
  const Connectivity conn = build_connectivity(in.mesh);
  const UvIslands input_islands = find_uv_islands(in.mesh, conn, 0);
  double area = 0.0;
  for (double a : input_islands.area_3d) area += a;
  const double one_face = area / double(r.target);
  for (const auto& s : islands["split_islands"])
    EXPECT_LT(input_islands.area_3d[s["input_island"].get<Index>()], one_face) << s;
  EXPECT_LE(islands["split"].get<int>(), 1) << islands["split_islands"];
  // Merged: only pairs of one-face islands that share no vertex in the input (7526 + 7527, ...),
  // which the reduction brought edge to edge with equal UVs along the new edge (find_uv_islands
  // joins only there), so their texture is continuous across it.
  std::vector<Index> faces_of(input_islands.num_islands, 0);
  for (Index f = 0; f < in.mesh.num_faces(); ++f)
    if (input_islands.face_island[f] != kInvalidIndex) ++faces_of[input_islands.face_island[f]];
  for (const auto& m : islands["merged_islands"]) {
    EXPECT_EQ(m["input_islands"].size(), 2u) << m;
    for (const auto& i : m["input_islands"]) EXPECT_EQ(faces_of[i.get<Index>()], 1u) << m;
  }
}

// blender_suzanne at 0.2: the optimised selections meet more `flip` / `folded_corner` refusals
// than the rounds can re-aim for (+9 % to +24 % in the corpus runs of session 6), the greedy
// selection's run (deterministic) ends at 195 of 194. With the fallback the output is within
// Eq. 2's band whichever run the optimised one was; without it, nothing else is tried.
// The scenarios below are those of Eq. 9 with λ_geo = 4 and λ_edge = 0.05 (the defaults until
// session 9): pinned, so that tuning the defaults does not move the known answers (with 2 and
// 0.1 the greedy run on suzanne at 0.2 lands on 194 and nothing falls back).
SimplifyOptions with_old_lambdas(SimplifyOptions o) {
  o.objective = SimplifyOptions::Objective::Paper;
  o.place_on_hard_edges = true;
  o.lambda_geo = 4.0;
  o.lambda_edge = 0.05;
  return o;
}

TEST(SimplifyCorpus, AMissedTargetFallsBackToTheGreedySelection) {
  const std::filesystem::path file = std::filesystem::path(QUADLOD_CORPUS_DIR) / "blender_suzanne.obj";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not present";
  const ReadResult in = read_mesh(file);
  ASSERT_TRUE(in.ok()) << in.error;
  // The counts below were measured deciding on the OBJ's doubles; rounded to float32 the paper
  // objective takes other paths (193 and 554), the fallback logic under test is the same.
  auto quick = [](double ratio) {
    SimplifyOptions o = with_old_lambdas(quadlod::quick(ratio));
    o.float32_decisions = false;
    return o;
  };
  SimplifyOptions greedy = quick(0.2);
  greedy.time_limit_seconds = 0.0;
  const SimplifyResult g = simplify(in.mesh, greedy);
  ASSERT_TRUE(g.ok()) << g.error;
  ASSERT_EQ(g.target, 194u);
  EXPECT_EQ(g.achieved, 194u);  // 195 before issue 32 let lines shorten through junctions
  EXPECT_FALSE(g.report.contains("fallback"));  // a greedy run has nothing to fall back to

  const SimplifyResult r = simplify(in.mesh, quick(0.2));
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_LE(std::abs(double(r.achieved) - 194.0), 0.03 * 194.0);
  expect_valid(in.mesh, r.mesh, "suzanne 0.2");
  if (r.report.contains("fallback")) {
    const auto& f = r.report["fallback"];
    EXPECT_EQ(f["greedy_achieved"], 194);
    EXPECT_EQ(f["kept"], "greedy");
    EXPECT_EQ(r.achieved, 194u);
    EXPECT_GT(std::abs(f["optimised_achieved"].get<double>() - 194.0), 0.03 * 194.0);
    EXPECT_EQ(r.report["options"]["time_limit_seconds"], 1.0);  // what was asked for
  }
  // One pass of one round misses by far either way (the collapse refuses most of what a single
  // selection at 0.2 asks for), so the fallback always runs: the greedy run ends at 532 (540
  // before issue 32), and
  // the output is whichever of the two is closer to 194.
  SimplifyOptions single = quick(0.2);
  single.max_passes = 1;
  single.max_rounds = 1;
  single.symmetry = SimplifyOptions::Symmetry::Off;  // the scenario as measured (Suzanne is symmetric: issue 34)
  const SimplifyResult s = simplify(in.mesh, single);
  ASSERT_TRUE(s.ok()) << s.error;
  ASSERT_TRUE(s.report.contains("fallback"));
  const auto& f = s.report["fallback"];
  EXPECT_EQ(f["greedy_achieved"], 532);
  const auto optimised = f["optimised_achieved"].get<std::int64_t>();
  EXPECT_EQ(std::int64_t(s.achieved), std::abs(optimised - 194) < std::abs(532 - 194) ? optimised : 532);
  EXPECT_EQ(f["kept"], std::int64_t(s.achieved) == optimised ? "optimised" : "greedy");
  EXPECT_NE(s.note.find("the greedy selection's 532"), std::string::npos) << s.note;
  // The note names what held the count up: the costliest refusal kinds of the last pass.
  EXPECT_NE(s.note.find("triangle-equivalents kept by refusal kind: "), std::string::npos) << s.note;
  expect_valid(in.mesh, s.mesh, "suzanne 0.2, one pass");

  SimplifyOptions off = single;
  off.greedy_fallback = false;
  EXPECT_FALSE(simplify(in.mesh, off).report.contains("fallback"));
}

// makehuman_teeth_base has no edge shorter than 10⁻⁶ of its diagonal; at 0.2 with the greedy
// selection (deterministic) the collapse used to place two clusters on one point three times:
// zero-length edges (in other runs one lay on a seam, and eval counted it as torn). Refused as
// `degenerate_face` now.
TEST(SimplifyCorpus, NoEdgeIsShrunkToAPoint) {
  const std::filesystem::path file = std::filesystem::path(QUADLOD_CORPUS_DIR) / "makehuman_teeth_base.obj";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not present";
  const ReadResult in = read_mesh(file);
  ASSERT_TRUE(in.ok()) << in.error;
  const double zero = 1e-6 * bounding_box(in.mesh).diagonal();
  auto shortest_edge = [](const PolyMesh& m) {
    double shortest = std::numeric_limits<double>::infinity();
    for (Index f = 0; f < m.num_faces(); ++f)
      for (Index c = m.face_begin(f); c < m.face_end(f); ++c) {
        const Index d = c + 1 == m.face_end(f) ? m.face_begin(f) : c + 1;
        shortest = std::min(shortest, (m.positions[m.corner_vertex[c]] - m.positions[m.corner_vertex[d]]).norm());
      }
    return shortest;
  };
  ASSERT_GT(shortest_edge(in.mesh), zero);
  // The scenario of the paper objective with the old lambdas (three shrunk edges before the
  // guard; 9 refusals of the guard now), and the default one.
  for (SimplifyOptions o : {with_old_lambdas({}), SimplifyOptions{}}) {
    o.ratio = 0.2;
    o.time_limit_seconds = 0.0;
    o.symmetry = SimplifyOptions::Symmetry::Off;  // the scenario as measured (the teeth are symmetric: issue 34)
    const SimplifyResult r = simplify(in.mesh, o);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_GT(shortest_edge(r.mesh), zero) << to_string(o.objective);
    int refused = 0;
    for (const auto& pass : r.report["passes"]) refused += pass["report"]["collapse"]["refused"]["degenerate_face"].get<int>();
    if (o.objective == SimplifyOptions::Objective::Paper) {
      EXPECT_GT(refused, 0);  // 9: the guard is what keeps the edges
    }
    expect_valid(in.mesh, r.mesh, std::string("teeth 0.2 ") + to_string(o.objective));
  }
}
#endif

}  // namespace
}  // namespace quadlod
