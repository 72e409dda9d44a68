// The stages that run on several threads (issue 20: "threads change only the speed"): the
// vertex quadrics against a one-thread oracle written the obvious way (a loop over the faces),
// bit for bit; the feature classification and the whole pipeline, with UVs and normals, for 1, 2
// and 3 threads. The meshes are above the stages' thresholds for going parallel (20 000 items).
#include "geometry/cluster_quadric.h"
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"
#include "quadlod/simplify.h"
#include "topology/polychords.h"
#include "topology/segmentation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
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

void add_plane(Quadric& q, double w, const Vec3& p, const Vec3& n) {
  const double d = -n.dot(p);
  q.A.noalias() += (w * n) * n.transpose();
  q.b += (w * d) * n;
  q.c += w * d * d;
}

// The vertex terms the way docs/cluster_collapse.md states them: every face adds, corner by
// corner, its plane (the corner's share of the area, split by interior angle) and the edge plane
// of the corner's edge, at both ends of that edge.
std::vector<VertexTerms> face_loop_oracle(const PolyMesh& mesh, const Connectivity& conn, const QuadricPlacementParams& params) {
  const double pi = std::numbers::pi;
  std::vector<Vec3> face_n(mesh.num_faces());
  std::vector<double> face_area(mesh.num_faces());
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Vec3 av = face_area_vector(mesh, f);
    face_area[f] = av.norm();
    face_n[f] = face_area[f] > 0.0 ? Vec3(av / face_area[f]) : Vec3::Zero();
  }
  double sum = 0.0;
  Index counted = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    const double len = (mesh.positions[a] - mesh.positions[b]).norm();
    if (len > 0.0) {
      sum += len;
      ++counted;
    }
  }
  const double mean_edge = sum / counted;
  const double feature_cos = std::cos(params.feature_angle_deg * pi / 180.0);
  std::vector<double> kind_w(conn.num_edges);
  for (Index e = 0; e < conn.num_edges; ++e) {
    const Index count = conn.edge_face_count(e);
    double w = params.min_edge_weight;
    if (count == 1) w = params.boundary_edge_weight;
    else if (count > 2) w = params.nonmanifold_edge_weight;
    else {
      const auto cs = conn.corners_of_edge(e);
      const Vec3& n0 = face_n[conn.corner_face[cs[0]]];
      const Vec3& n1 = face_n[conn.corner_face[cs[1]]];
      if (n0.squaredNorm() > 0.0 && n1.squaredNorm() > 0.0) {
        const double cosang = std::clamp(n0.dot(n1), -1.0, 1.0);
        w = std::max(w, std::acos(cosang) / pi);
        if (cosang <= feature_cos) w = std::max(w, params.feature_edge_weight);
      }
    }
    kind_w[e] = std::max(0.0, std::max(w, params.min_edge_weight));
  }
  std::vector<VertexTerms> terms(mesh.num_vertices());
  const double edge_scale = params.edge_plane_weight * mean_edge / (2.0 * pi);
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    if (!(face_area[f] > 0.0)) continue;
    const Index b = mesh.face_begin(f), k = mesh.face_size(f);
    std::vector<double> angles(k);
    double angle_sum = 0.0;
    for (Index i = 0; i < k; ++i) {
      const Vec3& p = mesh.positions[mesh.corner_vertex[b + i]];
      const Vec3 e0 = mesh.positions[mesh.corner_vertex[b + (i + k - 1) % k]] - p;
      const Vec3 e1 = mesh.positions[mesh.corner_vertex[b + (i + 1) % k]] - p;
      angles[i] = std::atan2(e0.cross(e1).norm(), e0.dot(e1));
      angle_sum += angles[i];
    }
    for (Index i = 0; i < k; ++i) {
      const Index c = b + i, v = mesh.corner_vertex[c];
      const Vec3& p = mesh.positions[v];
      const double wc = angle_sum > 0.0 ? face_area[f] * angles[i] / angle_sum : face_area[f] / k;
      add_plane(terms[v].q, params.face_plane_weight * wc, p, face_n[f]);
      terms[v].g += wc * face_n[f];
      terms[v].h += wc * face_n[f].dot(p);
      terms[v].w += wc;
      const Index w = conn.tip_vertex(c);
      if (w == v) continue;
      const Vec3 d = mesh.positions[w] - p;
      Vec3 m = face_n[f].cross(d);
      if (!(d.norm() > 0.0) || !(m.norm() > 0.0)) continue;
      m /= m.norm();
      const double weight = edge_scale * kind_w[conn.corner_edge[c]] * d.norm();
      if (!(weight > 0.0)) continue;
      add_plane(terms[v].q, weight, p, m);
      add_plane(terms[w].q, weight, p, m);
    }
  }
  return terms;
}

bool same_bits(const VertexTerms& a, const VertexTerms& b) {
  return std::memcmp(a.q.A.data(), b.q.A.data(), sizeof(double) * 9) == 0 &&
         std::memcmp(a.q.b.data(), b.q.b.data(), sizeof(double) * 3) == 0 && std::memcmp(&a.q.c, &b.q.c, sizeof(double)) == 0 &&
         std::memcmp(a.g.data(), b.g.data(), sizeof(double) * 3) == 0 && std::memcmp(&a.h, &b.h, sizeof(double)) == 0 &&
         std::memcmp(&a.w, &b.w, sizeof(double)) == 0;
}

TEST(ThreadedStages, VertexQuadricsMatchTheFaceLoopBitForBit) {
  PolyMesh vase = big_vase();
  // A degenerate face (a repeated corner) and a zero-area face among them: their edges with
  // both ends at one vertex add no edge plane, a face without area adds nothing.
  const Index a = vase.add_vertex({5, 5, 5}), b = vase.add_vertex({6, 5, 5}), c = vase.add_vertex({6, 6, 5});
  vase.add_face({a, b, b, c});
  const Index d = vase.add_vertex({7, 7, 7}), e = vase.add_vertex({8, 8, 8}), g = vase.add_vertex({9, 9, 9});
  vase.add_face({d, e, g});
  const Connectivity conn = build_connectivity(vase);
  ASSERT_GT(vase.num_vertices(), 20000u);
  const QuadricPlacementParams params;
  const std::vector<VertexTerms> oracle = face_loop_oracle(vase, conn, params);
  for (int threads : {1, 2, 3}) {
    const VertexQuadrics q = build_vertex_quadrics(vase, conn, params, threads);
    ASSERT_EQ(q.terms.size(), oracle.size());
    Index differ = 0;
    for (Index v = 0; v < vase.num_vertices(); ++v) differ += !same_bits(q.terms[v], oracle[v]);
    EXPECT_EQ(differ, 0u) << threads << " threads";
  }
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
    const auto path = std::filesystem::temp_directory_path() /
                      ("quadlod_threaded_" + std::to_string(threads * 1000000 + ::getpid() % 1000000) + ".obj");
    EXPECT_TRUE(write_mesh(r.mesh, path.string()).ok());
    std::ifstream in(path, std::ios::binary);
    std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::filesystem::remove(path);
    return data;
  };
  const std::string one = bytes(1);
  EXPECT_NE(one.find("\nvn "), std::string::npos);
  EXPECT_EQ(one, bytes(2));
  EXPECT_EQ(one, bytes(3));
}

}  // namespace
}  // namespace quadlod
