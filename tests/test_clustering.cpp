// Quadrics (geometry/quadric.h), medial-curve clustering (§3.2.3) and triangle-region
// clustering (§3.2.4): known answers on flat, creased and curved meshes, the partition
// invariants on generated and corpus meshes, and the analysis stage with its export.
#include "geometry/medial_clustering.h"
#include "geometry/quadric.h"
#include "geometry/triangle_clustering.h"
#include "topology/analysis.h"

#include "topology_test_util.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

using namespace quadlod;
using namespace quadlod::topo_test;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct MedialRun {
  PolyChordResult chords;
  MedialClusteringResult medial;
};

MedialRun run_medial(const Fixture& f, const MedialClusteringParams& params = {}) {
  MedialRun r;
  r.chords = extract_polychords(f.mesh, f.conn);
  r.medial = cluster_medial_curves(f.mesh, f.conn, r.chords, params);
  expect_medial_invariants(f, r.chords, r.medial);
  return r;
}

Index clusters_of_chord(const MedialRun& r, Index c) {
  return r.medial.chord_cluster_begin[c + 1] - r.medial.chord_cluster_begin[c];
}

// Largest angle between the quad normals of a cluster and its normal.
double cluster_spread(const Fixture& f, const PolyChord& ch, const EdgeCluster& cl) {
  const std::vector<Vec3> normals = chord_quad_normals(f.mesh, f.conn, ch);
  double worst = 0;
  for (Index i = cl.first;; i = (i + 1) % ch.size()) {
    worst = std::max(worst, std::acos(std::clamp(normals[i].dot(cl.normal), -1.0, 1.0)));
    if (i == cl.last) break;
  }
  return worst;
}

}  // namespace

// --- quadrics ------------------------------------------------------------------------------------

TEST(ClusterQuadric, PlaneQuadricIsSquaredDistance) {
  const Vec3 n = Vec3(1, 2, 2).normalized();
  const Quadric q = Quadric::plane(Vec3(1, 1, 1), n);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 20; ++i) {
    const Vec3 x(u(rng), u(rng), u(rng));
    const double d = n.dot(x - Vec3(1, 1, 1));
    EXPECT_NEAR(q(x), d * d, 1e-12);
  }
  const Quadric sum = q + 2.0 * Quadric::plane(Vec3::Zero(), Vec3::UnitZ());
  EXPECT_NEAR(sum(Vec3(0, 0, 1)), q(Vec3(0, 0, 1)) + 2.0, 1e-12);
}

TEST(ClusterQuadric, EdgeQuadricOfEquation5) {
  // Edge from (0,0,0) to (2,0,0) on a face with normal +z: w_n = 2, tangent-plane term 2·z²,
  // in-plane term w_f·y² (the plane through the edge containing the normal).
  const Quadric q = edge_quadric(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3::UnitZ(), 0.01);
  EXPECT_NEAR(q(Vec3(5, 0, 0)), 0.0, 1e-15);  // along the edge: no error
  EXPECT_NEAR(q(Vec3(0, 0, 1)), 2.0, 1e-12);
  EXPECT_NEAR(q(Vec3(0, 1, 0)), 0.01, 1e-12);
  EXPECT_NEAR(q(Vec3(0, 3, 1)), 2.0 + 0.09, 1e-12);
}

TEST(ClusterQuadric, SegmentMinimum) {
  // Distance² to the plane z = 1 along the segment (0,0,0)–(0,0,4): minimum at z = 1 (t = 1/4).
  const Quadric q = Quadric::plane(Vec3(0, 0, 1), Vec3::UnitZ());
  const Quadric::Minimum m = q.minimize_on_segment(Vec3(0, 0, 0), Vec3(0, 0, 4));
  EXPECT_NEAR(m.t, 0.25, 1e-12);
  EXPECT_NEAR(m.error, 0.0, 1e-12);
  // Clamped to the segment's end.
  const Quadric::Minimum c = q.minimize_on_segment(Vec3(0, 0, 3), Vec3(0, 0, 5));
  EXPECT_EQ(c.t, 0.0);
  EXPECT_NEAR(c.error, 4.0, 1e-12);
  // Constant along the segment: the middle.
  const Quadric::Minimum flat = q.minimize_on_segment(Vec3(0, 0, 1), Vec3(3, 0, 1));
  EXPECT_EQ(flat.t, 0.5);
}

// --- medial-curve clustering -----------------------------------------------------------------------

TEST(MedialCluster, FlatGridMergesEveryChordIntoOneCluster) {
  // Straight, flat medial curves: every collapse costs nothing and deviates nowhere.
  const Fixture f = make_fixture("grid", make_grid(8, 5));
  const MedialRun r = run_medial(f);
  ASSERT_EQ(r.medial.clusters.size(), r.chords.chords.size());
  for (Index c = 0; c < r.chords.chords.size(); ++c) {
    const EdgeCluster& cl = r.medial.clusters[c];
    EXPECT_EQ(cl.edges.size(), 2 * r.chords.chords[c].size());
    EXPECT_NEAR(std::abs(cl.normal.z()), 1.0, 1e-12);
  }
}

TEST(MedialCluster, CubeRingsKeepOneClusterPerSide) {
  // k = 4: every ring (16 quads) crosses 4 creases of 90°; the sides are flat and straight.
  // Clusters never cross a crease and each side merges into one cluster.
  const Fixture f = make_fixture("cube", make_cube(4));
  const MedialRun r = run_medial(f);
  for (Index c = 0; c < r.chords.chords.size(); ++c) {
    EXPECT_EQ(clusters_of_chord(r, c), 4u) << "chord " << c;
    for (Index k = r.medial.chord_cluster_begin[c]; k < r.medial.chord_cluster_begin[c + 1]; ++k)
      EXPECT_LT(cluster_spread(f, r.chords.chords[c], r.medial.clusters[k]), 1e-9);
  }
}

TEST(MedialCluster, SquarePrismDoesNotMergeAcrossItsCreases) {
  // make_cylinder(4, 6) is a square tube: rings of 4 quads with a 90° crease between any two,
  // axial chords flat and straight. Rings: 4 clusters; axial chords: 1 cluster.
  const Fixture f = make_fixture("prism", make_cylinder(4, 6));
  const MedialRun r = run_medial(f);
  for (Index c = 0; c < r.chords.chords.size(); ++c) {
    const PolyChord& ch = r.chords.chords[c];
    EXPECT_EQ(clusters_of_chord(r, c), ch.closed ? 4u : 1u) << "chord " << c;
  }
  EXPECT_GT(r.medial.stats.rejected_normal_deviation + r.medial.stats.rejected_spatial_deviation, 0u);
}

TEST(MedialCluster, SmoothCylinderRingsSplitByNormalVariation) {
  // 64 quads round a cylinder: each ring turns 360°; with the default limits no cluster may span
  // more than 2·30° of normals, so every ring keeps at least 6 clusters; the straight axial
  // chords merge into one.
  const Fixture f = make_fixture("cylinder", make_cylinder(64, 3));
  const MedialClusteringParams params;
  const MedialRun r = run_medial(f, params);
  for (Index c = 0; c < r.chords.chords.size(); ++c) {
    const PolyChord& ch = r.chords.chords[c];
    if (!ch.closed) {
      EXPECT_EQ(clusters_of_chord(r, c), 1u);
      continue;
    }
    EXPECT_GE(clusters_of_chord(r, c), 6u);
    EXPECT_LT(clusters_of_chord(r, c), 64u) << "a smooth ring must merge somewhere";
    for (Index k = r.medial.chord_cluster_begin[c]; k < r.medial.chord_cluster_begin[c + 1]; ++k)
      EXPECT_LE(cluster_spread(f, ch, r.medial.clusters[k]), params.max_normal_variation + 1e-9);
  }
}

TEST(MedialCluster, ThresholdsBoundTheMerging) {
  const Fixture f = make_fixture("cylinder", make_cylinder(32, 4));
  // Nothing allowed: a curved ring keeps every quad as its own cluster.
  MedialClusteringParams none;
  none.max_spatial_deviation = 0;
  none.max_normal_deviation = 0;
  none.max_normal_variation = 0;
  const MedialRun strict = run_medial(f, none);
  // Everything allowed: an open chord becomes one cluster, a closed one two (a closed curve
  // keeps two medial edges).
  MedialClusteringParams all;
  all.max_spatial_deviation = 10;
  all.max_normal_deviation = std::numbers::pi;
  all.max_normal_variation = std::numbers::pi;
  const MedialRun loose = run_medial(f, all);
  for (Index c = 0; c < strict.chords.chords.size(); ++c) {
    const PolyChord& ch = strict.chords.chords[c];
    if (ch.closed) {
      EXPECT_EQ(clusters_of_chord(strict, c), ch.size());
    }
    EXPECT_EQ(clusters_of_chord(loose, c), ch.closed ? 2u : 1u);
  }
}

TEST(MedialCluster, SelfCrossingAndNonOrientableChords) {
  for (const char* name : {"self_crossing", "moebius", "book3"}) {
    for (const Fixture& f : generated_fixtures())
      if (f.name == name) run_medial(f);
  }
}

TEST(MedialCluster, InvariantsOnEveryGeneratedMesh) {
  for (const Fixture& f : generated_fixtures()) run_medial(f);
}

TEST(MedialCluster, InvariantsOnCorpusSample) {
  Index loaded = 0;
  for (const std::string& file : corpus_sample()) {
    PolyMesh mesh;
    if (!load_corpus(file, mesh)) continue;
    ++loaded;
    const Fixture f = make_fixture(file, std::move(mesh));
    const MedialRun r = run_medial(f);
    EXPECT_LT(r.medial.clusters.size(), r.medial.stats.num_medial_edges) << file << ": nothing merged";
  }
  if (loaded == 0) GTEST_SKIP() << "corpus not found";
}

// --- triangle-region clustering ----------------------------------------------------------------------

TEST(TriangleCluster, FlatTrianglePatchMergesAndPartitions) {
  // A triangulated flat 6×6 grid: one region of 36·2 triangles and 6·7·2 + 36 = 120 edges;
  // every collapse is free (one plane), so the edges merge into a handful of clusters.
  const Fixture f = make_fixture("tri_grid", triangulate_quads(make_grid(6, 6)));
  const TriangleClusteringResult r = cluster_triangle_regions(f.mesh, f.conn);
  expect_triangle_invariants(f, r);
  EXPECT_EQ(r.stats.num_regions, 1u);
  EXPECT_EQ(r.stats.num_triangles, 72u);
  EXPECT_EQ(r.stats.num_region_edges, 120u);
  EXPECT_LE(r.clusters.size(), 4u);
  EXPECT_GE(r.clusters.size(), 1u);
}

TEST(TriangleCluster, NegativeThresholdKeepsEveryEdgeAlone) {
  const Fixture f = make_fixture("tri_grid", triangulate_quads(make_grid(3, 2)));
  TriangleClusteringParams none;
  none.epsilon_tri_relative = -1;
  const TriangleClusteringResult r = cluster_triangle_regions(f.mesh, f.conn, none);
  expect_triangle_invariants(f, r);
  EXPECT_EQ(r.clusters.size(), f.conn.num_edges);
  EXPECT_EQ(r.stats.num_collapses, 0u);
}

TEST(TriangleCluster, TriangleFanOfTheVase) {
  // make_demo_vase(8, 3): the bottom is a fan of 8 triangles round a pole: one region with
  // 8 spokes and 8 rim edges.
  const Fixture f = make_fixture("vase", make_demo_vase(8, 3));
  const TriangleClusteringResult r = cluster_triangle_regions(f.mesh, f.conn);
  expect_triangle_invariants(f, r);
  EXPECT_EQ(r.stats.num_regions, 1u);
  EXPECT_EQ(r.stats.num_triangles, 8u);
  EXPECT_EQ(r.stats.num_region_edges, 16u);
}

TEST(TriangleCluster, CurvedPatchClustersShrinkAsTheThresholdGrows) {
  // A triangulated cylinder (curved): more tolerance, fewer clusters. (Collapses along the axis
  // are free even at 0: the rulings lie in every adjacent plane.)
  const Fixture f = make_fixture("tri_cylinder", triangulate_quads(make_cylinder(24, 6)));
  Index previous = ~Index{0};
  for (double eps : {0.0, 1e-6, 1e-4, 1e-2, 1.0}) {
    TriangleClusteringParams p;
    p.epsilon_tri_relative = eps;
    const TriangleClusteringResult r = cluster_triangle_regions(f.mesh, f.conn, p);
    expect_triangle_invariants(f, r);
    EXPECT_LE(r.clusters.size(), previous) << eps;
    previous = static_cast<Index>(r.clusters.size());
  }
  EXPECT_LT(previous, f.conn.num_edges / 4);
}

TEST(TriangleCluster, InvariantsOnEveryGeneratedMesh) {
  for (const Fixture& f : generated_fixtures()) expect_triangle_invariants(f, cluster_triangle_regions(f.mesh, f.conn));
  const Fixture torus = make_fixture("tri_torus", triangulate_quads(make_torus(12, 8)));
  expect_triangle_invariants(torus, cluster_triangle_regions(torus.mesh, torus.conn));
}

TEST(TriangleCluster, InvariantsOnCorpusSample) {
  Index loaded = 0;
  for (const std::string& file : corpus_sample()) {
    PolyMesh mesh;
    if (!load_corpus(file, mesh)) continue;
    ++loaded;
    const Fixture f = make_fixture(file, std::move(mesh));
    expect_triangle_invariants(f, cluster_triangle_regions(f.mesh, f.conn));
  }
  if (loaded == 0) GTEST_SKIP() << "corpus not found";
}

// --- the analysis stage -------------------------------------------------------------------------------

TEST(AnalysisCluster, AnalyzeRunsEveryStageConsistently) {
  const Fixture f = make_fixture("vase", make_demo_vase(16, 10));
  const AnalysisResult a = analyze(f.mesh, f.conn);
  expect_polychord_invariants(f, a.polychords);
  expect_segmentation_invariants(f, a.polychords, a.segmentation, {});
  expect_medial_invariants(f, a.polychords, a.medial);
  expect_triangle_invariants(f, a.triangles);
  EXPECT_EQ(a.polychords.chords.size(), 26u);  // 16 columns + 10 rings
  EXPECT_GE(a.timings.total_ms, 0.0);
  EXPECT_NE(analysis_summary(f.mesh, a).find("26 chords"), std::string::npos);
}

// Without the geometric clusters (the shape objective does not read them) the chords and
// segments are the same and the clusters are empty.
TEST(AnalysisCluster, ClustersCanBeSkipped) {
  const Fixture f = make_fixture("vase", make_demo_vase(16, 10));
  const AnalysisResult all = analyze(f.mesh, f.conn);
  AnalysisParams ap;
  ap.clusters = false;
  const AnalysisResult some = analyze(f.mesh, f.conn, ap);
  EXPECT_FALSE(all.medial.clusters.empty());
  EXPECT_FALSE(all.triangles.clusters.empty());
  EXPECT_TRUE(some.medial.clusters.empty());
  EXPECT_TRUE(some.triangles.clusters.empty());
  EXPECT_EQ(some.polychords.chords.size(), all.polychords.chords.size());
  ASSERT_EQ(some.segmentation.segments.size(), all.segmentation.segments.size());
  for (std::size_t i = 0; i < all.segmentation.segments.size(); ++i)
    EXPECT_EQ(some.segmentation.segments[i].opposing_edges, all.segmentation.segments[i].opposing_edges);
}

TEST(AnalysisCluster, ExportWritesColouredEdgeFiles) {
  const Fixture f = make_fixture("vase", make_demo_vase(8, 4));
  const AnalysisResult a = analyze(f.mesh, f.conn);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("quadlod-analysis-export-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" + std::to_string(reinterpret_cast<std::uintptr_t>(&a)));
  ASSERT_EQ(write_analysis_export(f.mesh, f.conn, a, dir), "");
  for (const char* name : {"mesh.ply", "mesh.obj", "chords.ply", "chords.obj", "segments.ply", "segments.obj",
                           "quad_clusters.ply", "quad_clusters.obj", "triangle_clusters.ply", "triangle_clusters.obj"})
    EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;

  // chords.ply: one edge record per opposing edge, each with a colour.
  std::ifstream in(dir / "chords.ply");
  std::string line;
  std::size_t vertices = 0, edges = 0;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream s(line);
    std::string a0, a1;
    std::size_t n = 0;
    s >> a0 >> a1 >> n;
    if (a0 == "element" && a1 == "vertex") vertices = n;
    if (a0 == "element" && a1 == "edge") edges = n;
  }
  std::size_t expected_edges = 0;
  for (const PolyChord& c : a.polychords.chords) expected_edges += c.opposing_edges.size();
  EXPECT_EQ(vertices, f.mesh.positions.size());
  EXPECT_EQ(edges, expected_edges);
  for (std::size_t i = 0; i < vertices; ++i) std::getline(in, line);
  std::size_t records = 0;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    long v1 = -1, v2 = -1, r = -1, g = -1, b = -1;
    s >> v1 >> v2 >> r >> g >> b;
    EXPECT_TRUE(v1 >= 0 && v2 >= 0 && r >= 0 && r < 256 && g >= 0 && g < 256 && b >= 0 && b < 256) << line;
    ++records;
  }
  EXPECT_EQ(records, expected_edges);

  // chords.obj: one group per chord.
  std::ifstream obj(dir / "chords.obj");
  std::size_t groups = 0;
  while (std::getline(obj, line)) groups += line.rfind("g chord_", 0) == 0;
  EXPECT_EQ(groups, a.polychords.chords.size());
  std::filesystem::remove_all(dir);
}

TEST(AnalysisCluster, ExportReportsAnUnwritableDirectory) {
  const Fixture f = make_fixture("grid", make_grid(2, 2));
  const AnalysisResult a = analyze(f.mesh, f.conn);
  const std::string error = write_analysis_export(f.mesh, f.conn, a, "/proc/quadlod-no-such-dir/x");
  EXPECT_FALSE(error.empty());
}

// --- threshold measurements (docs/parameters.md) -------------------------------------------------
//
// Not regular tests: they print the tables docs/parameters.md records and assert nothing about
// the numbers. Run on a Release build with
//   quadlod_tests --gtest_also_run_disabled_tests --gtest_filter='*DISABLED_Measure*'

namespace {

const std::vector<std::string>& measure_meshes() {
  static const std::vector<std::string> files = {
      "blender_suzanne.obj", "opensubdiv_car_cage.obj", "tpsdemo_door_reactor.obj",
      "makehuman_base_body.obj", "flightgear_kc130.obj", "standard_shaderball_surface.obj"};
  return files;
}

double angle_of(const Vec3& a, const Vec3& b) {
  if (a.isZero(0.0) || b.isZero(0.0)) return -1.0;
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// Medial clustering quality along the chords: of the sharp crease transitions between
// consecutive quads (normals > 60° apart) and of the bends (15°–60°), how many are cluster
// boundaries ("kept"); of the flat straight transitions (normals and chord direction both turning
// < 2°), how many are inside a cluster ("merged").
struct MedialMeasure {
  std::size_t clusters = 0, steps = 0, creases = 0, creases_kept = 0, bends = 0, bends_kept = 0, flats = 0,
              flats_merged = 0;
  double ms = 0;
};

MedialMeasure measure_medial(const Fixture& f, const PolyChordResult& chords, const MedialClusteringParams& p) {
  MedialMeasure m;
  const auto t0 = std::chrono::steady_clock::now();
  const MedialClusteringResult r = cluster_medial_curves(f.mesh, f.conn, chords, p);
  m.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  m.clusters = r.clusters.size();
  m.steps = r.stats.num_medial_edges;
  std::vector<Index> cluster_of;
  for (Index c = 0; c < chords.chords.size(); ++c) {
    const PolyChord& ch = chords.chords[c];
    const Index n = ch.size();
    cluster_of.assign(n, kInvalidIndex);
    for (Index k = r.chord_cluster_begin[c]; k < r.chord_cluster_begin[c + 1]; ++k)
      for (Index i = r.clusters[k].first;; i = (i + 1) % n) {
        cluster_of[i] = k;
        if (i == r.clusters[k].last) break;
      }
    bool wrap_flip = false;
    const std::vector<Vec3> normals = chord_quad_normals(f.mesh, f.conn, ch, &wrap_flip);
    const std::vector<Vec3> pts = medial_curve(f.mesh, f.conn, ch);
    const Index transitions = ch.closed ? n : n - 1;
    for (Index i = 0; i < transitions; ++i) {
      const Index j = (i + 1) % n;
      const double s = (j == 0 && wrap_flip) ? -1.0 : 1.0;
      const double an = angle_of(normals[i], s * normals[j]);
      const Vec3 di = pts[(i + 1) % pts.size()] - pts[i], dj = pts[(j + 1) % pts.size()] - pts[j];
      const double ad = angle_of(di, dj);
      if (an < 0 || ad < 0) continue;
      const bool boundary = cluster_of[i] != cluster_of[j];
      if (an > 60 * kDeg) {
        ++m.creases;
        m.creases_kept += boundary;
      } else if (an > 15 * kDeg) {
        ++m.bends;
        m.bends_kept += boundary;
      } else if (an < 2 * kDeg && ad < 2 * kDeg) {
        ++m.flats;
        m.flats_merged += !boundary;
      }
    }
  }
  return m;
}

std::string pct(std::size_t a, std::size_t b) {
  char buf[32];
  std::snprintf(buf, sizeof buf, b ? "%.1f%%" : "-", b ? 100.0 * double(a) / double(b) : 0.0);
  return buf;
}

}  // namespace

TEST(ClusterMeasure, DISABLED_MeasureMedialThresholds) {
  const MedialClusteringParams base;
  struct Setting {
    std::string name;
    MedialClusteringParams p;
  };
  std::vector<Setting> settings{{"defaults", base}};
  for (double s : {0.0025, 0.005, 0.02, 0.05}) {
    Setting st{"spatial " + std::to_string(s).substr(0, 6), base};
    st.p.max_spatial_deviation = s;
    settings.push_back(st);
  }
  for (double a : {10.0, 15.0, 30.0, 45.0}) {
    Setting st{"deviation " + std::to_string(int(a)) + "°", base};
    st.p.max_normal_deviation = a * kDeg;
    settings.push_back(st);
  }
  for (double a : {15.0, 20.0, 45.0, 60.0}) {
    Setting st{"variation " + std::to_string(int(a)) + "°", base};
    st.p.max_normal_variation = a * kDeg;
    settings.push_back(st);
  }
  std::printf("| mesh | setting | medial edges | clusters | quads/cluster | creases kept | bends kept | flat merged | ms |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const std::string& file : measure_meshes()) {
    PolyMesh mesh;
    if (!load_corpus(file, mesh)) GTEST_SKIP() << "corpus not found";
    const Fixture f = make_fixture(file, std::move(mesh));
    const PolyChordResult chords = extract_polychords(f.mesh, f.conn);
    for (const Setting& st : settings) {
      const MedialMeasure m = measure_medial(f, chords, st.p);
      std::printf("| %s | %s | %zu | %zu | %.2f | %s (%zu) | %s (%zu) | %s (%zu) | %.1f |\n", file.c_str(),
                  st.name.c_str(), m.steps, m.clusters, double(m.steps) / double(std::max<std::size_t>(m.clusters, 1)),
                  pct(m.creases_kept, m.creases).c_str(), m.creases, pct(m.bends_kept, m.bends).c_str(), m.bends,
                  pct(m.flats_merged, m.flats).c_str(), m.flats, m.ms);
    }
  }
}

TEST(ClusterMeasure, DISABLED_MeasureTriangleThreshold) {
  static const std::vector<std::string> files = {
      "blender_suzanne.obj", "tpsdemo_door_reactor.obj", "flightgear_kc130.obj", "tpsdemo_red_robot.obj",
      "flightgear_human_outfit_default_m.obj", "flightgear_g164a_agcat.obj"};
  std::printf("| mesh | epsilon_tri_relative | region edges | clusters | edges/cluster | largest | neighbour pairs | crease edges collapsed | flat edges collapsed | ms |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const std::string& file : files) {
    PolyMesh mesh;
    if (!load_corpus(file, mesh)) GTEST_SKIP() << "corpus not found";
    const Fixture f = make_fixture(file, std::move(mesh));
    // Dihedral angle of each two-face edge.
    std::vector<double> dihedral(f.conn.num_edges, -1.0);
    for (Index e = 0; e < f.conn.num_edges; ++e) {
      if (f.conn.edge_face_count(e) != 2) continue;
      const auto cs = f.conn.corners_of_edge(e);
      dihedral[e] = angle_of(face_normal(f.mesh, f.conn.corner_face[cs[0]]), face_normal(f.mesh, f.conn.corner_face[cs[1]]));
    }
    for (double eps : {0.0, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3}) {
      TriangleClusteringParams p;
      p.epsilon_tri_relative = eps;
      const auto t0 = std::chrono::steady_clock::now();
      const TriangleClusteringResult r = cluster_triangle_regions(f.mesh, f.conn, p);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      std::vector<std::uint8_t> representative(f.conn.num_edges, 0);
      for (const TriangleCluster& c : r.clusters) representative[c.representative] = 1;
      std::size_t creases = 0, creases_gone = 0, flats = 0, flats_gone = 0;
      for (Index e = 0; e < f.conn.num_edges; ++e) {
        if (r.edge_cluster[e] == kInvalidIndex || dihedral[e] < 0) continue;
        if (dihedral[e] > 60 * kDeg) {
          ++creases;
          creases_gone += !representative[e];
        } else if (dihedral[e] < 2 * kDeg) {
          ++flats;
          flats_gone += !representative[e];
        }
      }
      std::printf("| %s | %g | %u | %zu | %.2f | %u | %zu | %s (%zu) | %s (%zu) | %.1f |\n", file.c_str(), eps,
                  r.stats.num_region_edges, r.clusters.size(),
                  double(r.stats.num_region_edges) / double(std::max<std::size_t>(r.clusters.size(), 1)),
                  r.stats.largest_cluster, r.neighbours.size() / 2, pct(creases_gone, creases).c_str(), creases,
                  pct(flats_gone, flats).c_str(), flats, ms);
    }
  }
}

TEST(ClusterMeasure, DISABLED_MeasureAnalysisTime) {
  // The speed target of issue 3: the whole analysis of the two largest corpus meshes.
  for (const char* file : {"assimp_suzanne_subdiv.obj", "flightgear_cg57_cruiser_hd.obj"}) {
    PolyMesh mesh;
    if (!load_corpus(file, mesh)) GTEST_SKIP() << "corpus not found";
    const auto t0 = std::chrono::steady_clock::now();
    const Connectivity conn = build_connectivity(mesh);
    const double conn_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (int rep = 0; rep < 3; ++rep) {
      const AnalysisResult a = analyze(mesh, conn);
      std::printf("%s: connectivity %.1f ms; %s\n", file, conn_ms, analysis_summary(mesh, a).c_str());
    }
  }
}

TEST(AnalysisCluster, DISABLED_WholeCorpusInvariants) {
  // Every corpus mesh through analyze() with all invariant checks (slow under sanitizers):
  //   quadlod_tests --gtest_also_run_disabled_tests --gtest_filter='*DISABLED_WholeCorpus*'
#ifdef QUADLOD_CORPUS_DIR
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(QUADLOD_CORPUS_DIR))
    if (entry.path().extension() == ".obj") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) GTEST_SKIP() << "corpus not found";
  for (const auto& path : files) {
    PolyMesh mesh;
    ASSERT_TRUE(load_corpus(path.filename().string(), mesh)) << path;
    const Fixture f = make_fixture(path.filename().string(), std::move(mesh));
    const AnalysisResult a = analyze(f.mesh, f.conn);
    expect_polychord_invariants(f, a.polychords);
    expect_segmentation_invariants(f, a.polychords, a.segmentation, {});
    expect_medial_invariants(f, a.polychords, a.medial);
    expect_triangle_invariants(f, a.triangles);
    std::printf("%s\n", (f.name + ": " + analysis_summary(f.mesh, a)).c_str());
  }
#else
  GTEST_SKIP() << "no corpus";
#endif
}
