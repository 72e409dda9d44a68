// The stages that run on several threads (issue 20: "threads change only the speed"): the
// feature classification, the segmentation and the whole pipeline, with UVs and normals, give
// the same result for 1, 2 and 3 threads. The meshes are above the stages' thresholds for going
// parallel (20 000 items).
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"
#include "quadlod/simplify.h"
#include "topology/polychords.h"
#include "topology/segmentation.h"

#include "io_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace quadlod {
namespace {

// 180 × 120 segments: 21 600+ vertices, 43 000+ edges.
PolyMesh big_vase() { return make_demo_vase(180, 120); }

// Smooth per-vertex normals (one pool entry per vertex), so that the projection recomputes them.
void add_vertex_normals(PolyMesh& mesh) {
  mesh.normals.assign(mesh.num_vertices(), Vec3::Zero());
  for (Index f = 0; f < mesh.num_faces(); ++f)
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) mesh.normals[mesh.corner_vertex[c]] += face_area_vector(mesh, f);
  for (Vec3& n : mesh.normals) n = n.norm() > 0.0 ? Vec3(n.normalized()) : Vec3(0, 0, 1);
  mesh.corner_normal = mesh.corner_vertex;
}

TEST(ThreadedStages, FeatureEdgesDoNotDependOnThreads) {
  PolyMesh vase = big_vase();
  add_vertex_normals(vase);
  vase.material_names = {"glaze", "rim"};
  vase.face_material.assign(vase.num_faces(), 0);
  for (Index f = 0; f < vase.num_faces(); f += 7) vase.face_material[f] = 1;
  const Connectivity conn = build_connectivity(vase);
  FeatureParams one;
  const FeatureEdges ref = find_feature_edges(vase, conn, one);
  EXPECT_GT(ref.edges_with_bit[4], 0u);  // material borders
  EXPECT_GT(ref.edges_with_bit[2], 0u);  // UV seams
  for (int threads : {2, 3}) {
    FeatureParams p;
    p.threads = threads;
    const FeatureEdges fe = find_feature_edges(vase, conn, p);
    EXPECT_EQ(fe.edge_bits, ref.edge_bits);
    EXPECT_EQ(fe.edge_uv_seam_sets, ref.edge_uv_seam_sets);
    EXPECT_EQ(fe.vertex_bits, ref.vertex_bits);
    EXPECT_EQ(fe.vertex_corner, ref.vertex_corner);
    EXPECT_EQ(fe.edge_line, ref.edge_line);
    EXPECT_EQ(fe.edges_with_bit, ref.edges_with_bit);
  }
}

TEST(ThreadedStages, SegmentsDoNotDependOnThreads) {
  const PolyMesh cube = make_cube(60);  // 21 600 quads; every chord turns at the cube's edges
  const Connectivity conn = build_connectivity(cube);
  const PolyChordResult chords = extract_polychords(cube, conn);
  const SegmentationResult ref = segment_polychords(cube, conn, chords);
  ASSERT_GT(ref.stats.num_dihedral, 0u);
  for (int threads : {2, 3}) {
    SegmentationParams p;
    p.threads = threads;
    const SegmentationResult r = segment_polychords(cube, conn, chords, p);
    ASSERT_EQ(r.segments.size(), ref.segments.size());
    for (std::size_t i = 0; i < r.segments.size(); ++i) {
      EXPECT_EQ(r.segments[i].chord, ref.segments[i].chord);
      EXPECT_EQ(r.segments[i].opposing_edges, ref.segments[i].opposing_edges);
    }
    EXPECT_EQ(r.edge_segment, ref.edge_segment);
    EXPECT_EQ(r.chord_segment_begin, ref.chord_segment_begin);
    ASSERT_EQ(r.breakpoints.size(), ref.breakpoints.size());
    for (std::size_t i = 0; i < r.breakpoints.size(); ++i) {
      EXPECT_EQ(r.breakpoints[i].edge, ref.breakpoints[i].edge);
      EXPECT_EQ(r.breakpoints[i].reasons, ref.breakpoints[i].reasons);
    }
    EXPECT_EQ(r.stats.num_breakpoints, ref.stats.num_breakpoints);
    EXPECT_EQ(r.stats.num_degenerate_skipped, ref.stats.num_degenerate_skipped);
  }
}

// The whole pipeline with UVs and normals projected on the threaded path: the same bytes.
TEST(ThreadedStages, SimplifyWithUvsAndNormalsGivesTheSameBytes) {
  PolyMesh vase = big_vase();
  add_vertex_normals(vase);
  auto bytes = [&](int threads) {
    SimplifyOptions options;
    options.ratio = 0.5;
    options.threads = threads;
    const SimplifyResult r = simplify(vase, options);
    EXPECT_TRUE(r.ok()) << r.error;
    EXPECT_GT(r.report["collapse"]["uv_values_projected"].get<long>(), 0);
    EXPECT_GT(r.report["collapse"]["normals_recomputed"].get<long>(), 0);
    return io_test::obj_bytes(r.mesh, "threaded_" + std::to_string(threads));
  };
  const std::string one = bytes(1);
  EXPECT_NE(one.find("\nvn "), std::string::npos);
  EXPECT_EQ(one, bytes(2));
  EXPECT_EQ(one, bytes(3));
}

}  // namespace
}  // namespace quadlod
