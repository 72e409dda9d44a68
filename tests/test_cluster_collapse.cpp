// Tests of src/post/cluster_collapse.h (paper §3.3.2): hand-built selections with known answers
// (identity, one grid column, one edge, a cube ring, a flip, a boundary, a crease, the singular
// quadric), then the guarantees as invariants over random selections on the generated meshes.
#include "post/cluster_collapse.h"

#include "geometry/bvh.h"
#include "mesh/connectivity.h"
#include "mesh/validation.h"
#include "feature_test_util.h"
#include "quadlod/generators.h"
#include "quadlod/mesh.h"
#include "quadlod/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace quadlod {
namespace {

Index edge_between(const Connectivity& conn, Index a, Index b) {
  for (Index c : conn.corners_at_vertex(a))
    for (Index ec : {c, conn.corner_prev[c]}) {
      const Index e = conn.corner_edge[ec];
      if (conn.other_vertex(e, a) == b) return e;
    }
  return kInvalidIndex;
}

// One entry per edge, all kept, then the listed vertex pairs collapsed.
std::vector<std::uint8_t> select(const Connectivity& conn,
                                 const std::vector<std::pair<Index, Index>>& collapse) {
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  for (const auto& [a, b] : collapse) {
    const Index e = edge_between(conn, a, b);
    EXPECT_NE(e, kInvalidIndex) << a << "-" << b;
    if (e != kInvalidIndex) kept[e] = 0;
  }
  return kept;
}

double signed_volume(const PolyMesh& m) {
  double v = 0.0;
  for (Index f = 0; f < m.num_faces(); ++f) {
    const auto vs = m.face_vertices(f);
    for (std::size_t i = 1; i + 1 < vs.size(); ++i)
      v += m.positions[vs[0]].dot(m.positions[vs[i]].cross(m.positions[vs[i + 1]])) / 6.0;
  }
  return v;
}

// The output checks every result must pass, relative to its input.
void expect_valid_output(const PolyMesh& in, const ClusterCollapseResult& r) {
  ASSERT_EQ(r.status, ClusterCollapseStatus::Ok) << r.error;
  ASSERT_EQ(r.mesh.check_layout(), "");
  const Connectivity cin = build_connectivity(in);
  const Connectivity cout = build_connectivity(r.mesh);
  const MeshStats sin = compute_stats(in, cin);
  const MeshStats sout = compute_stats(r.mesh, cout);
  EXPECT_EQ(sout.degenerate_faces, 0u);
  EXPECT_EQ(sout.repeated_index_faces, 0u);
  EXPECT_EQ(sout.duplicate_faces, 0u);
  EXPECT_EQ(sout.unused_vertices, 0u);
  EXPECT_EQ(sout.nonfinite_vertices, 0u);
  EXPECT_LE(sout.nonmanifold_edges, sin.nonmanifold_edges);
  EXPECT_LE(sout.nonmanifold_vertices, sin.nonmanifold_vertices);
  EXPECT_LE(sout.boundary_edges, sin.boundary_edges);
  EXPECT_EQ(r.stats.faces_out, r.mesh.num_faces());
  EXPECT_EQ(r.stats.tri_equivalent_out, tri_equivalent_count(r.mesh));
  EXPECT_EQ(r.stats.quads_out, sout.quads);
  EXPECT_EQ(r.stats.triangles_out, sout.triangles);
  // Refusals account for every tri-equivalent kept beyond what the selection asked for.
  std::int64_t kept = 0;
  for (auto k : r.stats.refused_tri_equivalents) kept += k;
  EXPECT_EQ(std::int64_t(r.stats.tri_equivalent_out) - std::int64_t(r.stats.tri_equivalent_wanted), kept);
  // vertex_map and edge_collapsed_final agree with each other.
  ASSERT_EQ(r.vertex_map.size(), in.num_vertices());
  ASSERT_EQ(r.edge_collapsed_final.size(), cin.num_edges);
  for (Index e = 0; e < cin.num_edges; ++e) {
    const auto [a, b] = cin.edge_vertices[e];
    if (a == b || r.vertex_map[a] == kInvalidIndex) continue;
    EXPECT_EQ(r.edge_collapsed_final[e] != 0, r.vertex_map[a] == r.vertex_map[b]) << "edge " << e;
  }
  // Each surviving corner keeps a UV of one of the input corners at a vertex that maps to it
  // (generators give corner_uv[c] == some lattice index; here only: indices stay in the pool).
  ASSERT_EQ(r.mesh.uv_sets.size(), in.uv_sets.size());
  for (std::size_t k = 0; k < in.uv_sets.size(); ++k) {
    ASSERT_EQ(r.mesh.uv_sets[k].corner.size(), r.mesh.num_corners());
    for (Index t : r.mesh.uv_sets[k].corner)
      EXPECT_TRUE(t == kInvalidIndex || t < r.mesh.uv_sets[k].values.size());
  }
}

// The chord of column i of make_grid(n, m): its horizontal edges (i, j)–(i + 1, j), j = 0..m, whose
// collapse merges the vertical lines x = i/n and x = (i+1)/n.
std::vector<std::pair<Index, Index>> column_chord(Index n, Index m, Index i) {
  std::vector<std::pair<Index, Index>> chord;
  for (Index j = 0; j <= m; ++j) chord.emplace_back(j * (n + 1) + i, j * (n + 1) + i + 1);
  return chord;
}

// --- known answers -------------------------------------------------------------------------------

TEST(ClusterCollapse, NothingCollapsedIsIdentity) {
  PolyMesh in = make_demo_vase(12, 5);
  in.material_names = {"glaze", "clay"};
  in.face_material.assign(in.num_faces(), 0);
  in.face_material[3] = 1;
  const Connectivity conn = build_connectivity(in);
  const std::vector<std::uint8_t> kept(conn.num_edges, 1);
  const ClusterCollapseResult r = collapse_clusters(in, conn, kept);
  expect_valid_output(in, r);
  EXPECT_EQ(r.mesh.positions, in.positions);
  EXPECT_EQ(r.mesh.face_offsets, in.face_offsets);
  EXPECT_EQ(r.mesh.corner_vertex, in.corner_vertex);
  EXPECT_EQ(r.mesh.uv_sets[0].corner, in.uv_sets[0].corner);
  EXPECT_EQ(r.mesh.uv_sets[0].values, in.uv_sets[0].values);
  EXPECT_EQ(r.mesh.face_material, in.face_material);
  EXPECT_EQ(r.mesh.material_names, in.material_names);
  for (Index v = 0; v < in.num_vertices(); ++v) EXPECT_EQ(r.vertex_map[v], v);
  EXPECT_EQ(r.stats.clusters, 0u);
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  EXPECT_EQ(r.stats.rounds, 1u);
  for (auto c : r.edge_collapsed_final) EXPECT_EQ(c, 0);
}

TEST(ClusterCollapse, UnusedInputVerticesAreRemoved) {
  PolyMesh in = make_grid(2, 2);
  in.add_vertex(Vec3(5, 5, 5));  // used by no face
  const Connectivity conn = build_connectivity(in);
  const ClusterCollapseResult r = collapse_clusters(in, conn, std::vector<std::uint8_t>(conn.num_edges, 1));
  EXPECT_EQ(r.mesh.num_vertices(), 9u);
  EXPECT_EQ(r.vertex_map[9], kInvalidIndex);
  EXPECT_EQ(r.stats.vertices_removed_unused, 1u);
  EXPECT_EQ(r.mesh.corner_vertex, in.corner_vertex);
}

// make_grid(6, 4): vertex id(i, j) = j·7 + i at (i/6, j/4). The chord of column 2 (quads (2, j))
// crosses the horizontal edges id(2,j)–id(3,j), j = 0..4: collapsing them merges the vertical
// lines x = 2/6 and x = 3/6, removing one column of quads.
TEST(ClusterCollapse, GridColumnChordRemovesOneColumn) {
  const Index n = 6, m = 4;
  const PolyMesh in = make_grid(n, m);
  const Connectivity conn = build_connectivity(in);
  auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  const auto chord = column_chord(n, m, 2);
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, chord));
  expect_valid_output(in, r);
  EXPECT_EQ(r.mesh.num_faces(), (n - 1) * m);
  EXPECT_EQ(r.stats.quads_out, (n - 1) * m);
  EXPECT_EQ(r.stats.triangles_out, 0u);
  EXPECT_EQ(r.mesh.num_vertices(), in.num_vertices() - (m + 1));
  EXPECT_EQ(r.stats.clusters, m + 1);
  EXPECT_EQ(r.stats.faces_dropped, m);
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  EXPECT_EQ(r.stats.tri_equivalent_out, 2u * (n - 1) * m);
  for (Index j = 0; j <= m; ++j) {
    const Index a = r.vertex_map[id(2, j)];
    ASSERT_EQ(a, r.vertex_map[id(3, j)]);
    const Vec3& p = r.mesh.positions[a];
    EXPECT_NEAR(p.z(), 0.0, 1e-12);
    EXPECT_NEAR(p.y(), double(j) / m, 1e-12);  // boundary rows stay on the boundary
    EXPECT_GE(p.x(), 2.0 / 6 - 1e-12);
    EXPECT_LE(p.x(), 3.0 / 6 + 1e-12);
    EXPECT_NEAR(p.x(), 2.5 / 6, 1e-9);  // symmetric: the middle
  }
  // The grid's UV is its position (unit square): unmoved corners keep their own UV index, the
  // merged ones get the UV of their new position, projected into the one chart around them.
  for (Index c = 0; c < r.mesh.num_corners(); ++c) {
    const Index v = r.mesh.corner_vertex[c];
    const Vec2 uv = r.mesh.uv_sets[0].values[r.mesh.uv_sets[0].corner[c]];
    EXPECT_NEAR(uv.x(), r.mesh.positions[v].x(), 1e-12) << "corner " << c;
    EXPECT_NEAR(uv.y(), r.mesh.positions[v].y(), 1e-12) << "corner " << c;
  }
  EXPECT_EQ(r.stats.uv_values_projected, m + 1);  // one wedge per merged vertex
  EXPECT_EQ(r.stats.placements_on_feature_line, 2u);  // the two rungs on the boundary
}

TEST(ClusterCollapse, SingleEdgeBetweenTwoQuadsMakesTwoTriangles) {
  PolyMesh in = make_grid(6, 4);
  in.group_names = {"g0", "g1"};
  in.face_group.resize(in.num_faces());
  for (Index f = 0; f < in.num_faces(); ++f) in.face_group[f] = f % 2;
  const Connectivity conn = build_connectivity(in);
  auto id = [](Index i, Index j) { return j * 7 + i; };
  // The vertical edge x = 3/6, y in [1/4, 2/4] is shared by quads (2, 1) and (3, 1).
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, {{id(3, 1), id(3, 2)}}));
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.triangles_out, 2u);
  EXPECT_EQ(r.stats.quads_out, 22u);
  EXPECT_EQ(r.stats.quads_to_triangles, 2u);
  EXPECT_EQ(r.stats.tri_equivalent_in - r.stats.tri_equivalent_out, 2u);
  EXPECT_EQ(r.mesh.num_vertices(), in.num_vertices() - 1);
  // Faces keep their input order and tags (no face was dropped).
  ASSERT_EQ(r.mesh.num_faces(), in.num_faces());
  EXPECT_EQ(r.mesh.face_group, in.face_group);
  EXPECT_EQ(r.mesh.face_size(1 * 6 + 2), 3u);
  EXPECT_EQ(r.mesh.face_size(1 * 6 + 3), 3u);
  const Vec3& p = r.mesh.positions[r.vertex_map[id(3, 1)]];
  EXPECT_NEAR(p.x(), 0.5, 1e-9);
  EXPECT_NEAR(p.y(), 0.375, 1e-9);
  EXPECT_NEAR(p.z(), 0.0, 1e-12);
}

// make_cube(3): vertices at ±1/2, ±1/6. The closed chord of the middle band around Z crosses the
// 12 edges that run from z = −1/6 to z = +1/6. Collapsing them leaves a 1 × 1 × 2/3 box.
TEST(ClusterCollapse, CubeClosedChordStaysClosedManifold) {
  const PolyMesh in = make_cube(3);
  const Connectivity conn = build_connectivity(in);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  Index chord_edges = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const Vec3& a = in.positions[conn.edge_vertices[e][0]];
    const Vec3& b = in.positions[conn.edge_vertices[e][1]];
    if (std::abs(std::abs(a.z()) - 1.0 / 6) < 1e-9 && std::abs(std::abs(b.z()) - 1.0 / 6) < 1e-9 &&
        std::abs(a.z() - b.z()) > 0.1) {
      kept[e] = 0;
      ++chord_edges;
    }
  }
  ASSERT_EQ(chord_edges, 12u);
  const ClusterCollapseResult r = collapse_clusters(in, conn, kept);
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  const Connectivity co = build_connectivity(r.mesh);
  const MeshStats s = compute_stats(r.mesh, co);
  EXPECT_EQ(s.boundary_edges, 0u);
  EXPECT_EQ(s.nonmanifold_edges, 0u);
  EXPECT_EQ(s.nonmanifold_vertices, 0u);
  EXPECT_EQ(s.components, 1u);
  EXPECT_EQ(s.quads, 54u - 12u);
  const long euler = long(r.mesh.num_vertices()) - long(co.num_edges) + long(r.mesh.num_faces());
  EXPECT_EQ(euler, 2);
  const double volume = signed_volume(r.mesh);
  EXPECT_GT(volume, 0.0);
  // The band's vertices land on z = 0 and the sides stay planar: the shape (and the volume) of
  // the unit cube is unchanged, only its middle row of quads is gone.
  EXPECT_NEAR(volume, 1.0, 1e-9);
  for (Index v = 0; v < r.mesh.num_vertices(); ++v) {
    const Vec3& p = r.mesh.positions[v];
    EXPECT_NEAR(p.cwiseAbs().maxCoeff(), 0.5, 1e-12);  // every vertex on the cube's surface
    // z levels −1/2, −1/6, 1/6, 1/2 become −1/2, 0, 1/2.
    EXPECT_TRUE(std::abs(p.z()) < 1e-12 || std::abs(std::abs(p.z()) - 0.5) < 1e-12) << p.transpose();
  }
}

// A flat disk around the edge a–b: a thin triangle T = (a, s, t) whose edge s–t, extended, crosses
// the x axis at x ≈ 0.27. Any merged position past that line (the quadric places it well inside
// the disk, x ≈ 0.7) turns T over, so the collapse is refused under "flip".
TEST(ClusterCollapse, CollapseThatFlipsAFaceIsRefused) {
  PolyMesh in;
  const Index a = in.add_vertex({0, 0, 0}), b = in.add_vertex({2, 0, 0});
  const Index s = in.add_vertex({0.1, 0.3, 0}), t = in.add_vertex({-0.3, 1.0, 0});
  const Index w = in.add_vertex({-1, -0.2, 0}), l = in.add_vertex({1, -1.2, 0});
  const Index q = in.add_vertex({3, 0, 0});
  in.add_face({a, b, s});
  in.add_face({a, s, t});
  in.add_face({a, t, w});
  in.add_face({a, w, l});
  in.add_face({a, l, b});
  in.add_face({b, q, s});
  in.add_face({b, l, q});
  const Connectivity conn = build_connectivity(in);
  ASSERT_EQ(compute_stats(in, conn).degenerate_faces, 0u);
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, {{a, b}}));
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.refusals(CollapseRefusal::Flip), 1u);
  EXPECT_EQ(r.stats.total_refusals(), 1u);
  EXPECT_EQ(r.stats.refused_tri_equivalents[std::size_t(CollapseRefusal::Flip)], 2);
  EXPECT_EQ(r.stats.tri_equivalent_wanted, 5u);
  EXPECT_EQ(r.stats.edges_restored, 1u);
  EXPECT_EQ(r.edge_collapsed_final[edge_between(conn, a, b)], 0);
  EXPECT_EQ(r.mesh.corner_vertex, in.corner_vertex);
  EXPECT_EQ(r.mesh.positions, in.positions);
  EXPECT_EQ(r.stats.rounds, 2u);

  // Without the refusal the merged vertex would really have turned T over (the surface check
  // sees it too: it must be off as well).
  ClusterCollapseParams lax;
  lax.flip_angle_deg = 180.0;
  EXPECT_EQ(collapse_clusters(in, conn, select(conn, {{a, b}}), lax).stats.refusals(CollapseRefusal::Orientation), 1u);
  lax.check_surface_orientation = false;
  const ClusterCollapseResult bad = collapse_clusters(in, conn, select(conn, {{a, b}}), lax);
  ASSERT_EQ(bad.mesh.num_faces(), 5u);
  EXPECT_LT(face_area_vector(bad.mesh, 0).z(), 0.0);  // (x, s, t) now faces down
}

// An open grid bent upward (z = 0.3 y²): collapsing a boundary edge keeps the merged vertex on the
// straight boundary line y = 0, z = 0 (boundary constraint planes, consistent face planes).
// The orientation guarantee measures against the *reference* surface (simplify passes the
// original input's): against a copy of the grid with every face reversed, each face the column
// collapse changes faces away from the surface under it, so every cluster is refused for that
// reason and nothing is lost; without the check the same selection removes the column.
TEST(ClusterCollapse, FaceFacingAwayFromTheReferenceSurfaceIsRefused) {
  const Index n = 6, m = 4;
  const PolyMesh in = make_grid(n, m);
  PolyMesh reversed = in;
  for (Index f = 0; f < reversed.num_faces(); ++f)
    std::reverse(reversed.corner_vertex.begin() + reversed.face_begin(f),
                 reversed.corner_vertex.begin() + reversed.face_end(f));
  const SurfaceReference against_reversed = make_surface_reference(reversed);
  const SurfaceReference against_itself = make_surface_reference(in);
  const Connectivity conn = build_connectivity(in);
  const auto kept = select(conn, column_chord(n, m, 2));

  ClusterCollapseParams params;
  params.surface_reference = &against_reversed;
  const ClusterCollapseResult refused = collapse_clusters(in, conn, kept, params);
  expect_valid_output(in, refused);
  EXPECT_EQ(refused.mesh.num_faces(), n * m);
  EXPECT_EQ(refused.stats.clusters, 0u);
  EXPECT_GT(refused.stats.refusals(CollapseRefusal::Orientation), 0u);
  EXPECT_EQ(refused.stats.total_refusals(), refused.stats.refusals(CollapseRefusal::Orientation));

  params.surface_reference = &against_itself;
  const ClusterCollapseResult accepted = collapse_clusters(in, conn, kept, params);
  EXPECT_EQ(accepted.mesh.num_faces(), (n - 1) * m);
  EXPECT_EQ(accepted.stats.total_refusals(), 0u);

  params.surface_reference = &against_reversed;
  params.check_surface_orientation = false;
  EXPECT_EQ(collapse_clusters(in, conn, kept, params).mesh.num_faces(), (n - 1) * m);
}

TEST(ClusterCollapse, BoundaryEdgeCollapseKeepsBoundaryStraight) {
  PolyMesh in = make_grid(6, 4);
  for (Vec3& p : in.positions) p.z() = 0.3 * p.y() * p.y();
  const Connectivity conn = build_connectivity(in);
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, {{2, 3}}));
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  const Vec3& p = r.mesh.positions[r.vertex_map[2]];
  EXPECT_NEAR(p.y(), 0.0, 1e-12);
  EXPECT_NEAR(p.z(), 0.0, 1e-12);
  EXPECT_NEAR(p.x(), 2.5 / 6, 1e-9);
  const MeshStats s = compute_stats(r.mesh, build_connectivity(r.mesh));
  EXPECT_EQ(s.boundary_edges, 2u * (6 + 4) - 1);
}

// A grid folded 90° along x = 1/2 (the right half turned up into the plane x = 1/2).
PolyMesh folded_grid() {
  PolyMesh in = make_grid(4, 4);
  for (Vec3& p : in.positions)
    if (p.x() > 0.5) p = Vec3(0.5, p.y(), p.x() - 0.5);
  return in;
}

TEST(ClusterCollapse, CreaseVerticesStayOnTheCrease) {
  const PolyMesh in = folded_grid();
  const Connectivity conn = build_connectivity(in);
  auto id = [](Index i, Index j) { return j * 5 + i; };
  // An edge along the crease.
  {
    const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, {{id(2, 1), id(2, 2)}}));
    expect_valid_output(in, r);
    EXPECT_EQ(r.stats.total_refusals(), 0u);
    const Vec3& p = r.mesh.positions[r.vertex_map[id(2, 1)]];
    EXPECT_NEAR(p.x(), 0.5, 1e-12);
    EXPECT_NEAR(p.z(), 0.0, 1e-12);
    EXPECT_NEAR(p.y(), 0.375, 1e-9);
  }
  // The chord of the column left of the crease: the crease vertices pull the merged vertices onto
  // the crease (face planes of both sides, sharp-edge planes), not half-way into the flat side.
  // Not exactly: Knodt's tangential edge planes of the flat vertex (weight 0.01) pull toward its
  // old line x = 1/4, and the volume constraint trades that for a dip in z. Both stay within 1% of
  // the edge length h = 1/4.
  {
    std::vector<std::pair<Index, Index>> chord;
    for (Index j = 0; j <= 4; ++j) chord.emplace_back(id(1, j), id(2, j));
    const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, chord));
    expect_valid_output(in, r);
    EXPECT_EQ(r.stats.total_refusals(), 0u);
    for (Index j = 0; j <= 4; ++j) {
      const Vec3& p = r.mesh.positions[r.vertex_map[id(2, j)]];
      EXPECT_NEAR(p.x(), 0.5, 0.01 * 0.25) << j;
      EXPECT_NEAR(p.z(), 0.0, 0.01 * 0.25) << j;
      EXPECT_LE(p.x(), 0.5);
      EXPECT_NEAR(p.y(), j / 4.0, 1e-9) << j;
    }
  }
}

// Clusters whose only feature is a hard edge (the 90° crease above) follow their quadric unless
// place_on_hard_edges (issue 19): with it they sit exactly on the crease line (issue 7's rule),
// without it exactly where the plain quadric puts them (the collapse without features), which is
// off the line by Knodt's tangential planes. The boundary ends of the chord (j = 0, 4) are on a
// strict line either way and are left out.
TEST(ClusterCollapse, HardEdgePlacementIsOptional) {
  const PolyMesh in = folded_grid();
  const Connectivity conn = build_connectivity(in);
  auto id = [](Index i, Index j) { return j * 5 + i; };
  std::vector<std::pair<Index, Index>> chord;
  for (Index j = 0; j <= 4; ++j) chord.emplace_back(id(1, j), id(2, j));
  ClusterCollapseParams pinned, free, plain;
  pinned.place_on_hard_edges = true;
  plain.respect_features = false;
  const ClusterCollapseResult on = collapse_clusters(in, conn, select(conn, chord), pinned);
  const ClusterCollapseResult off = collapse_clusters(in, conn, select(conn, chord), free);
  const ClusterCollapseResult bare = collapse_clusters(in, conn, select(conn, chord), plain);
  expect_valid_output(in, on);
  expect_valid_output(in, off);
  for (Index j = 1; j <= 3; ++j) {
    const Vec3& a = on.mesh.positions[on.vertex_map[id(2, j)]];
    EXPECT_NEAR(a.x(), 0.5, 1e-12) << j;
    EXPECT_NEAR(a.z(), 0.0, 1e-12) << j;
    const Vec3& b = off.mesh.positions[off.vertex_map[id(2, j)]];
    const Vec3& c = bare.mesh.positions[bare.vertex_map[id(2, j)]];
    EXPECT_NEAR((b - c).norm(), 0.0, 1e-12) << j;
    EXPECT_GT(std::abs(b.x() - 0.5) + std::abs(b.z()), 1e-9) << j;
  }
}

// A flat 3×3 block of vertices merged into one. With every term that makes the system regular
// turned off, the quadric is rank one (only the plane z = 0): the pseudo-inverse around the
// centroid must still give a finite point inside the block.
TEST(ClusterCollapse, SingularQuadricOnFlatGridGivesFinitePositionInsideCluster) {
  const PolyMesh in = make_grid(6, 6);
  const Connectivity conn = build_connectivity(in);
  auto id = [](Index i, Index j) { return j * 7 + i; };
  std::vector<std::pair<Index, Index>> block;
  for (Index j = 2; j <= 4; ++j)
    for (Index i = 2; i <= 4; ++i) {
      if (i < 4) block.emplace_back(id(i, j), id(i + 1, j));
      if (j < 4) block.emplace_back(id(i, j), id(i, j + 1));
    }
  for (bool regular : {true, false}) {
    ClusterCollapseParams params;
    if (!regular) {
      params.placement.regularization = 0.0;
      params.placement.edge_plane_weight = 0.0;
    }
    const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, block), params);
    expect_valid_output(in, r);
    EXPECT_EQ(r.stats.clusters, 1u);
    EXPECT_EQ(r.stats.largest_cluster, 9u);
    EXPECT_EQ(r.stats.placements_pseudo_inverse, regular ? 0u : 1u);
    const Vec3& p = r.mesh.positions[r.vertex_map[id(3, 3)]];
    ASSERT_TRUE(p.allFinite());
    EXPECT_GE(p.x(), 2.0 / 6 - 1e-12);
    EXPECT_LE(p.x(), 4.0 / 6 + 1e-12);
    EXPECT_GE(p.y(), 2.0 / 6 - 1e-12);
    EXPECT_LE(p.y(), 4.0 / 6 + 1e-12);
    EXPECT_NEAR(p.z(), 0.0, 1e-12);
    EXPECT_NEAR(p.x(), 0.5, 1e-9);  // symmetric block
    EXPECT_NEAR(p.y(), 0.5, 1e-9);
  }
}

// The bare Garland–Heckbert quadric (no edge planes, no regulariser, no cutoff, no volume
// constraint) of a bumpy grid has minimisers far outside some clusters: those fall back to the
// best of centroid / members. With the default terms nothing needs the fallback. Either way every
// merged vertex stays inside its members' box grown by the margin.
TEST(ClusterCollapse, UntrustedMinimiserFallsBackInsideTheCluster) {
  PolyMesh in = make_grid(12, 12);
  std::mt19937_64 g(7);
  for (Vec3& p : in.positions) p.z() = 0.01 * double(g() % 1000) / 1000.0;
  const Connectivity conn = build_connectivity(in);
  std::mt19937_64 h(11);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  for (auto& k : kept) k = (double(h() >> 11) * 0x1.0p-53) < 0.2 ? 0 : 1;
  ClusterCollapseParams bare;
  bare.placement.regularization = 0.0;
  bare.placement.edge_plane_weight = 0.0;
  bare.placement.eigen_cutoff = 0.0;
  bare.placement.preserve_volume = false;
  const double mean_edge = 1.0 / 12;
  for (bool use_bare : {true, false}) {
    const ClusterCollapseParams params = use_bare ? bare : ClusterCollapseParams{};
    const ClusterCollapseResult r = collapse_clusters(in, conn, kept, params);
    expect_valid_output(in, r);
    if (use_bare) {
      EXPECT_GT(r.stats.placements_fallback, 0u);
    } else {
      EXPECT_EQ(r.stats.placements_fallback, 0u);
    }
    EXPECT_GT(r.stats.clusters, 10u);
    std::vector<BoundingBox> boxes(r.mesh.num_vertices());
    for (Index v = 0; v < in.num_vertices(); ++v)
      if (r.vertex_map[v] != kInvalidIndex) boxes[r.vertex_map[v]].extend(in.positions[v]);
    for (Index o = 0; o < r.mesh.num_vertices(); ++o) {
      const double margin = params.placement.bbox_margin * std::max(boxes[o].diagonal(), mean_edge) * 1.01;
      const Vec3& p = r.mesh.positions[o];
      EXPECT_TRUE((p.array() >= boxes[o].min.array() - margin).all() &&
                  (p.array() <= boxes[o].max.array() + margin).all())
          << "vertex " << o << " at " << p.transpose();
    }
  }
}

TEST(ClusterCollapse, HausdorffBoundRefusesFarPlacements) {
  const PolyMesh in = make_torus(12, 8);
  const Connectivity conn = build_connectivity(in);
  // Collapse the ring of edges i = 0 → 1 around the tube (a closed chord of the torus).
  std::vector<std::pair<Index, Index>> chord;
  for (Index j = 0; j < 8; ++j) chord.emplace_back(0 * 8 + j, 1 * 8 + j);
  const auto kept = select(conn, chord);
  ClusterCollapseParams strict;
  strict.max_hausdorff = 1e-6;
  const ClusterCollapseResult r = collapse_clusters(in, conn, kept, strict);
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.refusals(CollapseRefusal::Hausdorff), 8u);
  EXPECT_EQ(r.stats.clusters, 0u);
  const ClusterCollapseResult loose = collapse_clusters(in, conn, kept);
  expect_valid_output(in, loose);
  EXPECT_EQ(loose.stats.total_refusals(), 0u);
  EXPECT_EQ(loose.stats.clusters, 8u);
  EXPECT_EQ(loose.mesh.num_faces(), 11u * 8u);
}

TEST(ClusterCollapse, MismatchedSelectionIsInvalidInput) {
  const PolyMesh in = make_grid(2, 2);
  const Connectivity conn = build_connectivity(in);
  const ClusterCollapseResult r = collapse_clusters(in, conn, std::vector<std::uint8_t>(3, 0));
  EXPECT_EQ(r.status, ClusterCollapseStatus::InvalidInput);
  EXPECT_FALSE(r.error.empty());
  EXPECT_EQ(r.mesh.corner_vertex, in.corner_vertex);
}

// --- invariants over random selections -----------------------------------------------------------

struct NamedMesh {
  const char* name;
  PolyMesh mesh;
};

std::vector<NamedMesh> invariant_meshes() {
  std::vector<NamedMesh> ms;
  ms.push_back({"vase", make_demo_vase(16, 10)});
  ms.push_back({"torus", make_torus(12, 8)});
  ms.push_back({"cube", make_cube(4)});
  ms.push_back({"cylinder", make_cylinder(10, 5)});
  ms.push_back({"grid", make_grid(9, 7)});
  PolyMesh bumpy = make_grid(10, 10);
  std::mt19937_64 g(7);
  for (Vec3& p : bumpy.positions) p.z() = 0.05 * double(g() % 1000) / 1000.0;
  ms.push_back({"bumpy", std::move(bumpy)});
  return ms;
}

TEST(ClusterCollapseInvariants, RandomSelectionsGiveValidMeshes) {
  for (const NamedMesh& nm : invariant_meshes()) {
    const Connectivity conn = build_connectivity(nm.mesh);
    for (double fraction : {0.05, 0.2, 0.5}) {
      for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        SCOPED_TRACE(std::string(nm.name) + " fraction " + std::to_string(fraction) + " seed " +
                     std::to_string(seed));
        std::mt19937_64 g(seed * 977 + static_cast<std::uint64_t>(fraction * 100));
        std::vector<std::uint8_t> kept(conn.num_edges, 1);
        for (auto& k : kept) k = (double(g() >> 11) * 0x1.0p-53) < fraction ? 0 : 1;
        for (Index rounds : {Index{8}, Index{0}}) {
          ClusterCollapseParams params;
          params.max_bisect_rounds = rounds;
          const ClusterCollapseResult r = collapse_clusters(nm.mesh, conn, kept, params);
          expect_valid_output(nm.mesh, r);
          // The collapse's orientation rule is the one `eval` counts by (docs/metrics.md §6b).
          EvalParams ep;
          ep.samples = 1000;
          ep.curve_samples = 1000;
          EXPECT_EQ(evaluate(nm.mesh, r.mesh, ep).flipped_faces, 0u);
          EXPECT_LE(r.stats.tri_equivalent_out, r.stats.tri_equivalent_in);
          EXPECT_GE(r.stats.tri_equivalent_out, r.stats.tri_equivalent_wanted);
          if (seed == 1) {  // deterministic, and the same when the face checks run on threads
            const ClusterCollapseResult again = collapse_clusters(nm.mesh, conn, kept, params);
            EXPECT_EQ(again.mesh.corner_vertex, r.mesh.corner_vertex);
            EXPECT_EQ(again.mesh.positions, r.mesh.positions);
            ClusterCollapseParams threaded = params;
            threaded.threads = 3;
            threaded.min_parallel_faces = 0;
            const ClusterCollapseResult par = collapse_clusters(nm.mesh, conn, kept, threaded);
            EXPECT_EQ(par.mesh.corner_vertex, r.mesh.corner_vertex);
            EXPECT_EQ(par.mesh.positions, r.mesh.positions);
            EXPECT_EQ(par.stats.refused_tri_equivalents, r.stats.refused_tri_equivalents);
          }
        }
      }
    }
  }
}

// Every closed chord-ring collapse on the cube and torus (the pipeline's typical input: whole
// chords) keeps the surface closed and orientable with positive volume.
TEST(ClusterCollapseInvariants, ClosedMeshesStayClosed) {
  for (const NamedMesh& nm : invariant_meshes()) {
    const Connectivity conn = build_connectivity(nm.mesh);
    const MeshStats sin = compute_stats(nm.mesh, conn);
    if (sin.boundary_edges != 0) continue;
    std::mt19937_64 g(42);
    std::vector<std::uint8_t> kept(conn.num_edges, 1);
    for (auto& k : kept) k = g() % 4 == 0 ? 0 : 1;
    const ClusterCollapseResult r = collapse_clusters(nm.mesh, conn, kept);
    SCOPED_TRACE(nm.name);
    expect_valid_output(nm.mesh, r);
    const MeshStats s = compute_stats(r.mesh, build_connectivity(r.mesh));
    EXPECT_EQ(s.boundary_edges, 0u);
    EXPECT_EQ(s.components, sin.components);
    EXPECT_GT(signed_volume(r.mesh), 0.0);
  }
}


// --- features and attributes (issue 7) -------------------------------------------------------------


// grid_with_seam_column(6, 4, 3, 0.5): the line x = 3/6 is a UV seam; left island UV = position,
// right island UV = position + (0.5, 0). Collapsing the chord of column 2 merges x = 2/6 into the
// seam line: the merged vertices must sit exactly on it, the left faces' corners there get the
// left chart's UV of the seam point and the right faces keep the right chart's.
TEST(ClusterCollapseFeatures, MergedVerticesStayOnTheSeamAndGetTheUvOfTheirSide) {
  const Index n = 6, m = 4;
  const PolyMesh in = feature_test::grid_with_seam_column(n, m, 3, 0.5);
  const Connectivity conn = build_connectivity(in);
  auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  const auto chord = column_chord(n, m, 2);
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, chord));
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  for (Index j = 0; j <= m; ++j) {
    const Vec3& p = r.mesh.positions[r.vertex_map[id(3, j)]];
    EXPECT_NEAR(p.x(), 3.0 / 6, 1e-12) << "row " << j;  // on the seam, not in the middle
    EXPECT_NEAR(p.y(), double(j) / m, 1e-12);
  }
  // Every output corner's UV is its position in its face's chart: left faces (centroid x < 3/6)
  // unshifted, right faces shifted by 0.5.
  for (Index f = 0; f < r.mesh.num_faces(); ++f) {
    const double shift = face_centroid(r.mesh, f).x() < 3.0 / 6 ? 0.0 : 0.5;
    for (Index c = r.mesh.face_begin(f); c < r.mesh.face_end(f); ++c) {
      const Vec3& p = r.mesh.positions[r.mesh.corner_vertex[c]];
      const Vec2 uv = r.mesh.uv_sets[0].values[r.mesh.uv_sets[0].corner[c]];
      EXPECT_NEAR(uv.x(), p.x() + shift, 1e-12) << "face " << f;
      EXPECT_NEAR(uv.y(), p.y(), 1e-12) << "face " << f;
    }
  }
  // Two wedges per merged vertex (one per side of the seam).
  EXPECT_EQ(r.stats.uv_values_projected, 2 * (m + 1));

  // Without feature handling the vertices go to the middle and keep stale UVs.
  ClusterCollapseParams plain;
  plain.respect_features = false;
  plain.project_attributes = false;
  const ClusterCollapseResult p = collapse_clusters(in, conn, select(conn, chord), plain);
  EXPECT_NEAR(p.mesh.positions[p.vertex_map[id(3, 2)]].x(), 2.5 / 6, 1e-9);
  EXPECT_EQ(p.stats.uv_values_projected, 0u);
}

// The provenance behind simplify's island accounting: grid(6, 4) with column 2 its own UV island
// (one face wide). Collapsing that column's chord without feature rules drops its four faces:
// face_source maps every output face to its input face, and the accounting finds the island
// vanished (4 faces, area 1/6) and the two others whole.
TEST(ClusterCollapseFeatures, FaceSourceTracksInputFacesAndAccountsAVanishedIsland) {
  const Index n = 6, m = 4;
  const PolyMesh in =
      feature_test::grid_with_face_uvs(n, m, [&](Index f) { return f % n == 2 ? 2.0 : f % n > 2 ? 4.0 : 0.0; });
  const Connectivity conn = build_connectivity(in);
  ClusterCollapseParams plain;
  plain.respect_features = false;
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, column_chord(n, m, 2)), plain);
  expect_valid_output(in, r);
  ASSERT_EQ(r.face_source.size(), r.mesh.num_faces());
  ASSERT_EQ(r.mesh.num_faces(), (n - 1) * m);
  for (Index f = 0; f < r.mesh.num_faces(); ++f) {
    const Index src = r.face_source[f];
    EXPECT_NE(src % n, 2u) << "face " << f;  // the collapsed column left nothing
    const Index row = f / (n - 1), t = f % (n - 1);
    EXPECT_EQ(src, row * n + (t < 2 ? t : t + 1));  // input order, column 2 skipped
  }
  const UvIslandAccount a = account_uv_islands(in, r.mesh, r.face_source);
  EXPECT_EQ(a.in, 3u);
  EXPECT_EQ(a.out, 2u);
  EXPECT_EQ(a.vanished, 1u);
  EXPECT_EQ(a.merged + a.split, 0u);
  ASSERT_EQ(a.vanished_islands.size(), 1u);
  EXPECT_EQ(a.vanished_islands[0].faces, m);
  EXPECT_NEAR(a.vanished_islands[0].area, 1.0 / n, 1e-12);
}

// A closed part without any strict feature line (one UV island, no boundary, no seam: an
// eyeball) whose every edge is collapsed would vanish whole, texture and all. The island keeps a
// face: the cluster is refused as `island` (split until a face survives). With the
// protection off (min_kept_island_area < 0) the cube is gone.
TEST(ClusterCollapseFeatures, IslandDoesNotVanishWhole) {
  PolyMesh in = make_cube(1);
  in.uv_sets.assign(1, UvSet{});
  for (const Vec3& p : in.positions) in.uv_sets[0].values.push_back(Vec2(p.x() + 0.5 * p.z(), p.y() + 0.25 * p.z()));
  in.uv_sets[0].corner = in.corner_vertex;  // one value per vertex: no seam, one island
  const Connectivity conn = build_connectivity(in);
  ASSERT_EQ(find_uv_islands(in, conn, 0).num_islands, 1u);
  const std::vector<std::uint8_t> none_kept(conn.num_edges, 0);

  ClusterCollapseParams off;
  off.min_kept_island_area = -1.0;
  off.max_vanishing_part_area = 100.0;  // the part may vanish (issue 32's part rule, tested below)
  const ClusterCollapseResult gone = collapse_clusters(in, conn, none_kept, off);
  EXPECT_EQ(gone.mesh.num_faces(), 0u);

  const ClusterCollapseResult kept = collapse_clusters(in, conn, none_kept);
  expect_valid_output(in, kept);
  EXPECT_GE(kept.mesh.num_faces(), 1u);
  EXPECT_GE(kept.stats.refusals(CollapseRefusal::Island), 1u);
  EXPECT_EQ(find_uv_islands(kept.mesh, build_connectivity(kept.mesh), 0).num_islands, 1u);
  // An island smaller than the bound may vanish (6 unit faces: area 6).
  ClusterCollapseParams small;
  small.min_kept_island_area = 7.0;
  small.max_vanishing_part_area = 100.0;
  EXPECT_EQ(collapse_clusters(in, conn, none_kept, small).mesh.num_faces(), 0u);
  // ... unless it had more area in the original input of a multi-pass reduction.
  const std::vector<double> original_area(in.num_faces(), 8.0);
  small.face_island_area = &original_area;
  EXPECT_GE(collapse_clusters(in, conn, none_kept, small).mesh.num_faces(), 1u);
}

// Issue 32: a part (connected component) keeps a face unless ClusterCollapseParams::
// max_vanishing_part_area allows more: a vanished part takes its whole extent out of the output.
// A cube without UVs (no island to protect it) with every edge collapsed is refused as `part`;
// at a bound above its area (6) it vanishes.
TEST(ClusterCollapseFeatures, PartDoesNotVanishWhole) {
  const PolyMesh in = [] {
    PolyMesh m = make_cube(1);
    m.uv_sets.clear();
    return m;
  }();
  const Connectivity conn = build_connectivity(in);
  const std::vector<std::uint8_t> none_kept(conn.num_edges, 0);
  const ClusterCollapseResult kept = collapse_clusters(in, conn, none_kept);
  expect_valid_output(in, kept);
  EXPECT_GE(kept.mesh.num_faces(), 1u);
  EXPECT_GE(kept.stats.refusals(CollapseRefusal::Part), 1u);
  ClusterCollapseParams small;
  small.max_vanishing_part_area = 6.5;
  EXPECT_EQ(collapse_clusters(in, conn, none_kept, small).mesh.num_faces(), 0u);
  small.max_vanishing_part_area = 5.5;
  EXPECT_GE(collapse_clusters(in, conn, none_kept, small).mesh.num_faces(), 1u);
}

// Issue 32: a hole never closes to a point unless parts may vanish. A 4 × 4 grid without its
// middle 2 × 2 faces has an inner boundary loop of 8 vertices; collapsing its 8 edges would close
// the hole (no new boundary, no non-manifold edge: only the loop rule sees it).
TEST(ClusterCollapseFeatures, AHoleDoesNotCloseToAPoint) {
  const PolyMesh grid = make_grid(4, 4);
  PolyMesh in;
  in.positions = grid.positions;
  for (Index f = 0; f < grid.num_faces(); ++f) {
    const Index i = f % 4, j = f / 4;
    if ((i == 1 || i == 2) && (j == 1 || j == 2)) continue;
    in.add_face(grid.face_vertices(f));
  }
  const Connectivity conn = build_connectivity(in);
  auto id = [](Index i, Index j) { return j * 5 + i; };
  const std::vector<Index> loop = {id(1, 1), id(2, 1), id(3, 1), id(3, 2), id(3, 3), id(2, 3), id(1, 3), id(1, 2)};
  std::vector<std::pair<Index, Index>> ring;
  for (std::size_t k = 0; k < loop.size(); ++k) ring.emplace_back(loop[k], loop[(k + 1) % loop.size()]);
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, ring));
  expect_valid_output(in, r);
  EXPECT_GE(r.stats.refusals(CollapseRefusal::Feature), 1u);
  EXPECT_GT(compute_stats(r.mesh, build_connectivity(r.mesh)).boundary_edges, 16u);  // still open
  ClusterCollapseParams may;
  may.max_vanishing_part_area = 1.0;
  const ClusterCollapseResult closed = collapse_clusters(in, conn, select(conn, ring), may);
  EXPECT_EQ(compute_stats(closed.mesh, build_connectivity(closed.mesh)).boundary_edges, 16u);
}

// Issue 32: lines shorten through their junctions. grid(6, 4) with a seam column at x = 3/6 and a
// UV seam along row y = 2/4 to its right: (3, 2) is a junction (seam valence 3) and (3, 0), (3,
// 4) are where the column meets the boundary. Collapsing the column's seam edges between rows 1
// and 3 merges the junction with its two neighbours along the seam: accepted (it used to be
// refused as two strict corners), placed on the junction, so both seams keep their input lines.
TEST(ClusterCollapseFeatures, ALineShortensThroughAJunction) {
  const Index n = 6, m = 4;
  PolyMesh in = feature_test::grid_with_face_uvs(n, m, [&](Index f) {
    const Index i = f % n, j = f / n;
    return i < 3 ? 0.0 : j < 2 ? 2.0 : 4.0;
  });
  const Connectivity conn = build_connectivity(in);
  const FeatureEdges fe = find_feature_edges(in, conn);
  auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  ASSERT_TRUE(fe.vertex_corner[id(3, 2)]);
  ASSERT_FALSE(fe.vertex_corner[id(3, 1)]);
  const ClusterCollapseResult r =
      collapse_clusters(in, conn, select(conn, {{id(3, 1), id(3, 2)}, {id(3, 2), id(3, 3)}}));
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  const Index v = r.vertex_map[id(3, 2)];
  EXPECT_EQ(r.vertex_map[id(3, 1)], v);
  EXPECT_EQ(r.vertex_map[id(3, 3)], v);
  EXPECT_EQ(r.mesh.positions[v], in.positions[id(3, 2)]);
  const EvalResult q = evaluate(in, r.mesh);
  EXPECT_EQ(q.seams_torn, 0u);
  EXPECT_EQ(q.uv_islands_out, 3u);
}

// Issue 32: a collapse across a line stays forbidden. grid(6, 4) with column 2 its own island
// (one quad wide, area 1/6): its row edges join the seam at x = 2/6 to the seam at x = 3/6.
// Collapsing them would merge the two lines across the island: refused (`feature`) while the
// island must keep a face; when the island is below the crossing bound its lines may merge
// through it, and it vanishes between them.
TEST(ClusterCollapseFeatures, ACollapseAcrossALineIsRefusedUnlessItsIslandMayCross) {
  const Index n = 6, m = 4;
  const PolyMesh in =
      feature_test::grid_with_face_uvs(n, m, [&](Index f) { return f % n == 2 ? 2.0 : f % n > 2 ? 4.0 : 0.0; });
  const Connectivity conn = build_connectivity(in);
  auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  std::vector<std::pair<Index, Index>> across;
  for (Index j = 1; j < m; ++j) across.emplace_back(id(2, j), id(3, j));
  ClusterCollapseParams keep;
  keep.min_kept_island_area = 0.1;  // the strip (1/6) must keep a face
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, across), keep);
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.refusals(CollapseRefusal::Feature), m - 1);
  for (Index j = 1; j < m; ++j) EXPECT_NE(r.vertex_map[id(2, j)], r.vertex_map[id(3, j)]) << j;

  ClusterCollapseParams cross = keep;
  cross.crossing_island_area = 0.2;
  const ClusterCollapseResult c = collapse_clusters(in, conn, select(conn, column_chord(n, m, 2)), cross);
  expect_valid_output(in, c);
  EXPECT_EQ(c.stats.refusals(CollapseRefusal::Feature), 0u);
  EXPECT_EQ(c.mesh.num_faces(), (n - 1) * m);
  const EvalResult q = evaluate(in, c.mesh);
  EXPECT_EQ(q.seams_torn, 0u);
}

// A thin tube (4 quads around, 3 along, one UV island without seams: one value per vertex) whose
// two inner rings each collapse to a point becomes two cones; the band of faces between them is
// dropped. No new boundary, no non-manifold vertex: only the island check sees that the island
// fell apart (cg57's thin tubes at 0.4). Refused as `island`: the output island stays in one piece.
TEST(ClusterCollapseFeatures, IslandIsNotCutInTwo) {
  const Index n = 4, m = 3;
  PolyMesh in = make_cylinder(n, m, 0.05, 3.0);
  in.uv_sets.assign(1, UvSet{});
  for (const Vec3& p : in.positions) in.uv_sets[0].values.push_back(Vec2(p.x() + p.y(), p.z()));
  in.uv_sets[0].corner = in.corner_vertex;
  const Connectivity conn = build_connectivity(in);
  ASSERT_EQ(find_uv_islands(in, conn, 0).num_islands, 1u);
  // Ring edges of the two inner rings (z = 1 and z = 2) collapsed.
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  Index ring_edges = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const Vec3& a = in.positions[conn.edge_vertices[e][0]];
    const Vec3& b = in.positions[conn.edge_vertices[e][1]];
    if (std::abs(a.z() - b.z()) < 1e-9 && (std::abs(a.z() - 1.0) < 1e-9 || std::abs(a.z() - 2.0) < 1e-9)) {
      kept[e] = 0;
      ++ring_edges;
    }
  }
  ASSERT_EQ(ring_edges, 2 * n);
  auto output_islands = [](const PolyMesh& m) { return find_uv_islands(m, build_connectivity(m), 0).num_islands; };

  ClusterCollapseParams off;
  off.min_kept_island_area = -1.0;
  const ClusterCollapseResult cut = collapse_clusters(in, conn, kept, off);
  expect_valid_output(in, cut);
  EXPECT_EQ(cut.mesh.num_faces(), 2 * n);  // two cones of n triangles
  EXPECT_EQ(output_islands(cut.mesh), 2u);
  EXPECT_EQ(account_uv_islands(in, cut.mesh, cut.face_source).split, 1u);

  const ClusterCollapseResult r = collapse_clusters(in, conn, kept);
  expect_valid_output(in, r);
  EXPECT_GE(r.stats.refusals(CollapseRefusal::Island), 1u);
  EXPECT_EQ(output_islands(r.mesh), 1u);
  EXPECT_EQ(account_uv_islands(in, r.mesh, r.face_source).split, 0u);
  EXPECT_GT(r.mesh.num_faces(), 0u);
}

// A single column of material "B" between two columns of "A": collapsing its chord would make
// the two A|B borders one A|A non-border — refused as `feature`, and nothing collapses.
TEST(ClusterCollapseFeatures, ClusterJoiningTwoMaterialBordersIsRefused) {
  const Index n = 5, m = 3;
  PolyMesh in = make_grid(n, m);
  feature_test::paint_columns(in, n, {"A", "B"}, {0, 0, 1, 0, 0});
  const Connectivity conn = build_connectivity(in);
  auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  const auto chord = column_chord(n, m, 2);
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, chord));
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.refusals(CollapseRefusal::Feature), m + 1);
  EXPECT_EQ(r.stats.collapsed_edges_final, 0u);
  EXPECT_EQ(r.mesh.num_faces(), in.num_faces());
  // The same chord next to the border (column 1, A|A on one side) is fine: the cluster holds one
  // strict run (the border x = 2/5) and lands on it.
  const auto beside = column_chord(n, m, 1);
  const ClusterCollapseResult b = collapse_clusters(in, conn, select(conn, beside));
  expect_valid_output(in, b);
  EXPECT_EQ(b.stats.total_refusals(), 0u);
  for (Index j = 0; j <= m; ++j) EXPECT_NEAR(b.mesh.positions[b.vertex_map[id(2, j)]].x(), 2.0 / 5, 1e-12);
}

// A vertex that is a feature corner (the grid's corner (0, 0)) stays where it is.
TEST(ClusterCollapseFeatures, FeatureCornerDoesNotMove) {
  const Index n = 4, m = 3;
  const PolyMesh in = make_grid(n, m);
  const Connectivity conn = build_connectivity(in);
  auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  const auto chord = column_chord(n, m, 0);
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, chord));
  expect_valid_output(in, r);
  EXPECT_EQ(r.mesh.positions[r.vertex_map[id(0, 0)]], in.positions[id(0, 0)]);
  EXPECT_EQ(r.mesh.positions[r.vertex_map[id(0, m)]], in.positions[id(0, m)]);
  EXPECT_EQ(r.stats.placements_at_feature_corner, 2u);
  // The rows in between stay on the left boundary.
  for (Index j = 1; j < m; ++j) EXPECT_NEAR(r.mesh.positions[r.vertex_map[id(0, j)]].x(), 0.0, 1e-12);
}

// The ring of edges parallel to x between the layers x = -1/6 and x = 1/6 of make_cube(3, 1).
std::vector<std::uint8_t> cube_with_middle_ring_collapsed(const PolyMesh& in, const Connectivity& conn) {
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    const Vec3 &pa = in.positions[a], &pb = in.positions[b];
    if (std::abs(std::abs(pa.x() - pb.x()) - 1.0 / 3) < 1e-12 && std::abs(pa.x() + pb.x()) < 1e-12) kept[e] = 0;
  }
  return kept;
}

// Custom normals travel (issue 32: normals interpolated, not recomputed): a cube whose every
// corner normal points up, as foliage is shaded, keeps every output normal up after a ring of
// its vertices merged — the recomputed normals would be the faces' (5 of 6 sides not up).
TEST(ClusterCollapseFeatures, CustomNormalsAreCarriedNotRecomputed) {
  PolyMesh in = make_cube(3, 1.0);
  in.normals.assign(1, Vec3(0, 0, 1));
  in.corner_normal.assign(in.num_corners(), 0);
  const Connectivity conn = build_connectivity(in);
  const ClusterCollapseResult r = collapse_clusters(in, conn, cube_with_middle_ring_collapsed(in, conn));
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  EXPECT_GT(r.stats.normals_recomputed, 0u);
  for (Index c = 0; c < r.mesh.num_corners(); ++c)
    EXPECT_LT((r.mesh.normals[r.mesh.corner_normal[c]] - Vec3(0, 0, 1)).norm(), 1e-12) << "corner " << c;
}

// A 3×3×3 cube with one normal per side (hard edges): after collapsing a ring chord, every
// corner normal is its output face's normal — a new value per side, the 90° edges stay hard.
TEST(ClusterCollapseFeatures, NormalsAreNewPerSideAndStayHard) {
  PolyMesh in = make_cube(3, 1.0);
  in.normals.clear();
  in.corner_normal.assign(in.num_corners(), kInvalidIndex);
  for (Index f = 0; f < in.num_faces(); ++f) {
    const Vec3 n = face_normal(in, f);
    Index id = kInvalidIndex;
    for (Index k = 0; k < in.normals.size(); ++k)
      if ((in.normals[k] - n).norm() < 1e-12) id = k;
    if (id == kInvalidIndex) {
      id = static_cast<Index>(in.normals.size());
      in.normals.push_back(n);
    }
    for (Index c = in.face_begin(f); c < in.face_end(f); ++c) in.corner_normal[c] = id;
  }
  ASSERT_EQ(in.normals.size(), 6u);
  const Connectivity conn = build_connectivity(in);
  // The ring of edges parallel to x between the layers x = -1/6 and x = 1/6.
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  Index collapsed = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    const Vec3 &pa = in.positions[a], &pb = in.positions[b];
    if (std::abs(std::abs(pa.x() - pb.x()) - 1.0 / 3) < 1e-12 && std::abs(pa.x() + pb.x()) < 1e-12) {
      kept[e] = 0;
      ++collapsed;
    }
  }
  ASSERT_EQ(collapsed, 12u);  // 3 + 3 + 3 + 3 around the ring
  const ClusterCollapseResult r = collapse_clusters(in, conn, kept);
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  EXPECT_GT(r.stats.normals_recomputed, 0u);
  for (Index f = 0; f < r.mesh.num_faces(); ++f) {
    const Vec3 n = face_normal(r.mesh, f);
    for (Index c = r.mesh.face_begin(f); c < r.mesh.face_end(f); ++c)
      EXPECT_LT((r.mesh.normals[r.mesh.corner_normal[c]] - n).norm(), 1e-9) << "face " << f;
  }
}

// An annulus sector: radial lines i = 0..7 at 40° steps, rings r = 1, 1.5, 2 (j = 0..2). The arcs
// turn by 40° per vertex, less than corner_angle_deg, so each arc is one boundary line without
// corners in between. Collapsing columns 2, 3, 4 merges radial lines 2..5 into one: whatever the
// placement, an output arc edge then spans 2.5 or more input segments (a turn of 100°+), whose
// chord leaves the arc by more than 0.2 of its length — refused as `feature`. With a lax tolerance
// it goes through.
TEST(ClusterCollapseFeatures, ChordCuttingACurvedBoundaryTooShortIsRefused) {
  PolyMesh in;
  const Index n = 8, rings = 3;
  for (Index j = 0; j < rings; ++j)
    for (Index i = 0; i < n; ++i) {
      const double a = i * 40.0 * std::numbers::pi / 180.0, r = 1.0 + 0.5 * j;
      in.add_vertex(Vec3(r * std::cos(a), r * std::sin(a), 0.0));
    }
  auto id = [&](Index i, Index j) { return j * n + i; };
  for (Index j = 0; j + 1 < rings; ++j)
    for (Index i = 0; i + 1 < n; ++i) in.add_face({id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)});
  const Connectivity conn = build_connectivity(in);
  std::vector<std::pair<Index, Index>> chords;
  for (Index i = 2; i <= 4; ++i)
    for (Index j = 0; j < rings; ++j) chords.emplace_back(id(i, j), id(i + 1, j));

  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, chords));
  expect_valid_output(in, r);
  EXPECT_GE(r.stats.refusals(CollapseRefusal::Feature), 1u);
  // Every output boundary edge stays within 0.2 of its length of the input boundary.
  const Connectivity out = build_connectivity(r.mesh);
  for (Index e = 0; e < out.num_edges; ++e) {
    if (!out.is_boundary_edge(e)) continue;
    const Vec3 &a = r.mesh.positions[out.edge_vertices[e][0]], &b = r.mesh.positions[out.edge_vertices[e][1]];
    for (double t : {0.25, 0.5, 0.75}) {
      const Vec3 p = a + t * (b - a);
      double best = INFINITY;
      for (Index f = 0; f < conn.num_edges; ++f)
        if (conn.is_boundary_edge(f))
          best = std::min(best, (closest_point_on_segment(p, in.positions[conn.edge_vertices[f][0]],
                                                          in.positions[conn.edge_vertices[f][1]]) - p).norm());
      EXPECT_LE(best, 0.2 * (b - a).norm() + 1e-12) << "output edge " << e;
    }
  }

  ClusterCollapseParams lax;
  lax.feature_tolerance = 1.0;
  const ClusterCollapseResult l = collapse_clusters(in, conn, select(conn, chords), lax);
  expect_valid_output(in, l);
  EXPECT_EQ(l.stats.refusals(CollapseRefusal::Feature), 0u);
  EXPECT_EQ(l.mesh.num_faces(), 2u * (n - 1) - 6u);
}

// Two sheets meeting only at the ends A, B of a slit (flightgear_cg57_cruiser_hd: a wall standing
// on a deck, each with its own boundary along their common line, sharing its two end vertices):
//
//      w0 ─── w1 ─── w2        wall, plane y = 0, UV = (x, z)
//      │      │      │
//      A ──── p1 ─── B         slit: the wall's boundary A–p1–B and the deck's A–q1–B coincide
//      │        q1   │               (q1 at x = 1.2, p1 at x = 1)
//      f0 ───── f1 ─ f2        deck, plane z = 0, UV = (x + 5, −y): another island
//
// Collapsing p1–B and q1–B shortens each boundary run along its own line (one strict corner, B;
// features_valid accepts it), but both sheets then own an edge A–B: the slit is zipped shut into
// a UV seam where the input had a boundary — a torn seam (metrics §6c). Refused as `feature`;
// without feature handling the zip goes through.
TEST(ClusterCollapseFeatures, ZippingASlitBetweenTwoSheetsIsRefused) {
  PolyMesh in;
  const Index A = in.add_vertex({0, 0, 0}), p1 = in.add_vertex({1, 0, 0}), B = in.add_vertex({2, 0, 0});
  const Index w0 = in.add_vertex({0, 0, 1}), w1 = in.add_vertex({1, 0, 1}), w2 = in.add_vertex({2, 0, 1});
  const Index q1 = in.add_vertex({1.2, 0, 0});
  const Index f0 = in.add_vertex({0, -1, 0}), f1 = in.add_vertex({1.2, -1, 0}), f2 = in.add_vertex({2, -1, 0});
  in.add_face({A, p1, w1, w0});
  in.add_face({p1, B, w2, w1});
  in.add_face({A, f0, f1, q1});
  in.add_face({q1, f1, f2, B});
  UvSet uv;
  for (Index f = 0; f < in.num_faces(); ++f)
    for (Index c = in.face_begin(f); c < in.face_end(f); ++c) {
      const Vec3& p = in.positions[in.corner_vertex[c]];
      uv.corner.push_back(static_cast<Index>(uv.values.size()));
      uv.values.push_back(f < 2 ? Vec2(p.x(), p.z()) : Vec2(p.x() + 5.0, -p.y()));
    }
  in.uv_sets = {uv};
  ASSERT_EQ(in.check_layout(), "");
  const Connectivity conn = build_connectivity(in);
  const auto kept = select(conn, {{p1, B}, {q1, B}});
  // Output faces on the output edge between A and B (whichever vertices they became).
  auto faces_on_AB = [](const ClusterCollapseResult& r) {
    const Index a = r.vertex_map[0], b = r.vertex_map[2];
    const Connectivity out = build_connectivity(r.mesh);
    for (Index e = 0; e < out.num_edges; ++e) {
      const auto [x, y] = out.edge_vertices[e];
      if ((x == a && y == b) || (x == b && y == a)) return out.edge_face_count(e);
    }
    return Index{0};
  };

  ClusterCollapseParams plain;
  plain.respect_features = false;
  const ClusterCollapseResult z = collapse_clusters(in, conn, kept, plain);
  ASSERT_EQ(z.status, ClusterCollapseStatus::Ok);
  EXPECT_EQ(z.stats.total_refusals(), 0u);
  EXPECT_EQ(faces_on_AB(z), 2u);  // zipped: one interior edge, a UV seam, from two boundaries
  EXPECT_EQ(compute_stats(z.mesh, build_connectivity(z.mesh)).boundary_edges, 8u);

  const ClusterCollapseResult r = collapse_clusters(in, conn, kept);
  expect_valid_output(in, r);
  EXPECT_EQ(r.stats.refusals(CollapseRefusal::Feature), 1u);
  // The longer collapsed edge (p1–B, 1 against 0.8) is cut: the deck still collapses, the wall
  // keeps its boundary run A–p1–B, and A–B is an edge of the deck alone.
  EXPECT_NE(r.vertex_map[p1], r.vertex_map[B]);
  EXPECT_EQ(r.vertex_map[q1], r.vertex_map[B]);
  EXPECT_EQ(faces_on_AB(r), 1u);
  EXPECT_EQ(compute_stats(r.mesh, build_connectivity(r.mesh)).boundary_edges, 11u);
}

// A per-face UV layout (every face its own island: all seams non-strict, every vertex a feature
// corner). Collapsing the chord of column 2 of a 6×4 grid merges x = 2/6 with x = 3/6: every
// merged vertex lands on one of its two members (a half-edge collapse), never between them, so the
// output's vertical edges are input edges and its horizontal ones run along input edges (two
// collinear ones) — on the input seams. The plain quadric would put them at x = 2.5/6, off every
// input edge.
TEST(ClusterCollapseFeatures, PerFaceLayoutClustersLandOnAMemberCorner) {
  const Index n = 6, m = 4;
  const PolyMesh in = feature_test::grid_with_face_uvs(n, m, [](Index f) { return 2.0 * double(f); });
  const Connectivity conn = build_connectivity(in);
  const FeatureEdges fe = find_feature_edges(in, conn);
  for (Index e = 0; e < conn.num_edges; ++e) ASSERT_FALSE(fe.is_strict(e) && !conn.is_boundary_edge(e)) << e;
  auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  const ClusterCollapseResult r = collapse_clusters(in, conn, select(conn, column_chord(n, m, 2)));
  expect_valid_output(in, r);
  // Rows 0 and m merge two corners along the boundary (a line that shortens, issue 32): they
  // land on one of them too.
  EXPECT_EQ(r.stats.total_refusals(), 0u);
  for (Index j = 0; j <= m; ++j) {
    EXPECT_EQ(r.vertex_map[id(2, j)], r.vertex_map[id(3, j)]) << "row " << j;
    const double x = r.mesh.positions[r.vertex_map[id(2, j)]].x();
    EXPECT_TRUE(x == 2.0 / 6 || x == 3.0 / 6) << "row " << j << ": x = " << x;
    EXPECT_EQ(r.mesh.positions[r.vertex_map[id(2, j)]].y(), double(j) / m);
  }
  EXPECT_GE(r.stats.placements_at_feature_corner, m + 1);
}

}  // namespace
}  // namespace quadlod
