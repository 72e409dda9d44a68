// Feature edges, corners, lines and UV islands (src/mesh/features.h) on hand-made meshes whose
// answers are counted by hand in each test.
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "feature_test_util.h"
#include "quadlod/generators.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <numbers>

using namespace quadlod;
using quadlod::feature_test::grid_with_seam_column;

namespace {

struct Found {
  Connectivity conn;
  FeatureEdges fe;
};

Found features_of(const PolyMesh& m, const FeatureParams& p = {}) {
  EXPECT_EQ(m.check_layout(), "");
  Found r{build_connectivity(m), {}};
  r.fe = find_feature_edges(m, r.conn, p);
  return r;
}

Index bit_count(const FeatureEdges& fe, FeatureBit bit) { return fe.edges_with_bit[std::countr_zero(unsigned(bit))]; }

/// Edge between grid vertices (i0, j0) and (i1, j1) of a make_grid(n, ·) mesh.
Index grid_edge(const Connectivity& conn, Index n, Index i0, Index j0, Index i1, Index j1) {
  const Index a = j0 * (n + 1) + i0, b = j1 * (n + 1) + i1;
  for (Index e = 0; e < conn.num_edges; ++e)
    if (conn.edge_vertices[e] == std::array<Index, 2>{std::min(a, b), std::max(a, b)}) return e;
  return kInvalidIndex;
}

}  // namespace

TEST(Features, GridWithSeamColumn) {
  const Index n = 4, m = 3, split = 2;
  const PolyMesh g = grid_with_seam_column(n, m, split, 0.5);
  const Found f = features_of(g);
  // Seam: the m vertical edges at i = split; boundary 2(n + m); nothing else on a flat grid.
  EXPECT_EQ(bit_count(f.fe, kFeatureUvSeam), m);
  EXPECT_EQ(bit_count(f.fe, kFeatureBoundary), 2 * (n + m));
  EXPECT_EQ(bit_count(f.fe, kFeatureHardEdge), 0u);
  EXPECT_EQ(f.fe.feature_edges, 2 * (n + m) + m);
  for (Index j = 0; j < m; ++j) {
    const Index e = grid_edge(f.conn, n, split, j, split, j + 1);
    ASSERT_NE(e, kInvalidIndex);
    EXPECT_EQ(f.fe.edge_bits[e], kFeatureUvSeam);
    EXPECT_EQ(f.fe.edge_uv_seam_sets[e], 1u);
  }
  // Corners: the seam's two ends on the boundary (valence 3) and the grid's four corners (90°
  // turns). The seam's inner vertices have valence 2 and run straight.
  EXPECT_EQ(f.fe.corners, 6u);
  auto v = [&](Index i, Index j) { return j * (n + 1) + i; };
  EXPECT_TRUE(f.fe.vertex_corner[v(split, 0)]);
  EXPECT_TRUE(f.fe.vertex_corner[v(split, m)]);
  EXPECT_EQ(f.fe.vertex_valence[v(split, 0)], 3u);
  EXPECT_FALSE(f.fe.vertex_corner[v(split, 1)]);
  EXPECT_EQ(f.fe.vertex_bits[v(split, 1)], kFeatureUvSeam);
  EXPECT_EQ(f.fe.vertex_bits[v(1, 1)], 0);
  for (Index c : {v(0, 0), v(n, 0), v(0, m), v(n, m)}) EXPECT_TRUE(f.fe.vertex_corner[c]);
  // Lines: the boundary cut at 6 corners, plus the seam.
  EXPECT_EQ(f.fe.num_lines, 7u);
  const Index seam_line = f.fe.edge_line[grid_edge(f.conn, n, split, 0, split, 1)];
  for (Index j = 0; j < m; ++j) EXPECT_EQ(f.fe.edge_line[grid_edge(f.conn, n, split, j, split, j + 1)], seam_line);
  for (Index e = 0; e < f.conn.num_edges; ++e) EXPECT_EQ(f.fe.edge_line[e] != kInvalidIndex, f.fe.is_feature(e));

  const UvIslands is = find_uv_islands(g, f.conn, 0);
  EXPECT_EQ(is.num_islands, 2u);
  EXPECT_EQ(is.face_island[0], 0u);       // face (0, 0), left of the seam
  EXPECT_EQ(is.face_island[split], 1u);   // face (split, 0), right of it
  EXPECT_EQ(is.face_island[n - 1], 1u);
  EXPECT_TRUE(is.uv_min[0].isApprox(Vec2(0.0, 0.0)));
  EXPECT_TRUE(is.uv_max[0].isApprox(Vec2(0.5, 1.0)));
  EXPECT_TRUE(is.uv_min[1].isApprox(Vec2(1.0, 0.0)));
  EXPECT_TRUE(is.uv_max[1].isApprox(Vec2(1.5, 1.0)));
  EXPECT_NEAR(is.area_3d[0], 0.5, 1e-12);
  EXPECT_NEAR(is.area_3d[1], 0.5, 1e-12);
}

TEST(Features, CylinderUnwrappedWithOneSeam) {
  const Index n = 12, m = 3;
  const PolyMesh cyl = make_cylinder(n, m, 0.5, 1.0);
  const Found f = features_of(cyl);
  // The UV lattice has n + 1 columns: column n (u = 1) meets column 0 (u = 0) at vertex i = 0.
  EXPECT_EQ(bit_count(f.fe, kFeatureUvSeam), m);
  EXPECT_EQ(bit_count(f.fe, kFeatureBoundary), 2 * n);
  EXPECT_EQ(bit_count(f.fe, kFeatureHardEdge), 0u);  // 30° between neighbours < 60°
  for (Index j = 0; j < m; ++j) {
    const Index a = j * n, b = (j + 1) * n;  // vertex i = 0 on rings j, j + 1
    for (Index e = 0; e < f.conn.num_edges; ++e)
      if (f.conn.edge_vertices[e] == std::array<Index, 2>{a, b}) {
        EXPECT_EQ(f.fe.edge_bits[e], kFeatureUvSeam);
      }
  }
  // Ring vertices turn by 30° < 45°: the only corners are the seam's ends (valence 3), which also
  // anchor the two boundary rings. Lines: the seam and each ring.
  EXPECT_EQ(f.fe.corners, 2u);
  EXPECT_TRUE(f.fe.vertex_corner[0]);
  EXPECT_TRUE(f.fe.vertex_corner[m * n]);
  EXPECT_EQ(f.fe.num_lines, 3u);

  const UvIslands is = find_uv_islands(cyl, f.conn, 0);
  EXPECT_EQ(is.num_islands, 1u);
  EXPECT_TRUE(is.uv_min[0].isApprox(Vec2(0.0, 0.0)));
  EXPECT_TRUE(is.uv_max[0].isApprox(Vec2(1.0, 1.0)));
  EXPECT_NEAR(is.area_3d[0], n * (2.0 * 0.5 * std::sin(std::numbers::pi / n)) * 1.0, 1e-12);
}

TEST(Features, CubeWithSixIslandsAndHardEdges) {
  PolyMesh cube = make_cube(1);
  // Every side gets its own UV square at u offset 2·face: every cube edge is a seam.
  UvSet& uv = cube.uv_sets[0];
  uv.values.clear();
  for (Index f = 0; f < cube.num_faces(); ++f)
    for (Index k = 0; k < 4; ++k) {
      uv.values.emplace_back(2.0 * f + (k == 1 || k == 2), double(k >= 2));
      uv.corner[cube.face_begin(f) + k] = 4 * f + k;
    }
  const Found f = features_of(cube);
  EXPECT_EQ(bit_count(f.fe, kFeatureHardEdge), 12u);
  EXPECT_EQ(bit_count(f.fe, kFeatureUvSeam), 12u);
  EXPECT_EQ(bit_count(f.fe, kFeatureBoundary), 0u);
  EXPECT_EQ(f.fe.feature_edges, 12u);
  EXPECT_EQ(f.fe.corners, 8u);
  EXPECT_EQ(f.fe.num_lines, 12u);
  for (Index v = 0; v < 8; ++v) EXPECT_EQ(f.fe.vertex_valence[v], 3u);
  const UvIslands is = find_uv_islands(cube, f.conn, 0);
  EXPECT_EQ(is.num_islands, 6u);
  for (Index k = 0; k < 6; ++k) {
    EXPECT_NEAR(is.area_3d[k], 1.0, 1e-12);
    EXPECT_TRUE(is.uv_max[k].isApprox(is.uv_min[k] + Vec2(1.0, 1.0)));
  }

  // 90° is below a 100° threshold: no hard edges; enabling only seams keeps the seams.
  FeatureParams blunt;
  blunt.hard_angle_deg = 100.0;
  EXPECT_EQ(bit_count(features_of(cube, blunt).fe, kFeatureHardEdge), 0u);
  FeatureParams seams_only;
  seams_only.enabled = kFeatureUvSeam;
  const Found s = features_of(cube, seams_only);
  EXPECT_EQ(bit_count(s.fe, kFeatureHardEdge), 0u);
  EXPECT_EQ(bit_count(s.fe, kFeatureUvSeam), 12u);
  // Without UVs only the hard edges remain.
  cube.uv_sets.clear();
  const Found h = features_of(cube);
  EXPECT_EQ(h.fe.feature_edges, 12u);
  for (Index e = 0; e < h.conn.num_edges; ++e) EXPECT_EQ(h.fe.edge_bits[e], kFeatureHardEdge);
}

TEST(Features, MaterialBordersCompareNames) {
  const Index n = 4, m = 2;
  PolyMesh g = make_grid(n, m);
  g.uv_sets.clear();
  feature_test::paint_columns(g, n, {"red", "blue", "red"}, {0, 0, 1, 1});
  Found f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureMaterialBorder), m);
  for (Index j = 0; j < m; ++j)
    EXPECT_EQ(f.fe.edge_bits[grid_edge(f.conn, n, 2, j, 2, j + 1)], kFeatureMaterialBorder);
  // Index 2 is another entry named "red": no border between it and index 0.
  for (Index j = 0; j < m; ++j) g.face_material[j * n + 0] = 2;
  f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureMaterialBorder), m);
  // A face without a material next to one with a material is a border.
  g.face_material[0] = kInvalidIndex;
  f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureMaterialBorder), m + 2);
}

TEST(Features, DuplicateUvPoolEntriesWithEqualValuesAreNoSeam) {
  const Index n = 3, m = 3;
  PolyMesh g = make_grid(n, m);
  UvSet& uv = g.uv_sets[0];
  // Faces of column 1 and up point at copies of the same values (split pool, equal values).
  const Index base = static_cast<Index>(uv.values.size());
  for (Index k = 0; k < base; ++k) uv.values.push_back(uv.values[k]);
  for (Index f = 0; f < g.num_faces(); ++f)
    if (f % n >= 1)
      for (Index c = g.face_begin(f); c < g.face_end(f); ++c) uv.corner[c] += base;
  Found f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureUvSeam), 0u);
  EXPECT_EQ(find_uv_islands(g, f.conn, 0).num_islands, 1u);

  // One corner without a UV: the two interior edges at that corner become seams (one side has a
  // UV, the other none), and the face drops out of every island.
  const Index centre_face = 1 * n + 1;
  uv.corner[g.face_begin(centre_face)] = kInvalidIndex;  // its corner at grid vertex (1, 1)
  f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureUvSeam), 2u);
  const UvIslands is = find_uv_islands(g, f.conn, 0);
  EXPECT_EQ(is.face_island[centre_face], kInvalidIndex);
  EXPECT_EQ(is.num_islands, 1u);
  EXPECT_NEAR(is.area_3d[0], 8.0 / 9.0, 1e-12);
}

TEST(Features, SecondUvSetSeamsAreTheirOwnBit) {
  const Index n = 4, m = 2;
  PolyMesh g = make_grid(n, m);
  g.uv_sets.push_back(grid_with_seam_column(n, m, 1, 3.0).uv_sets[0]);
  g.uv_sets[1].name = "lightmap";
  const Found f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureUvSeam), m);
  EXPECT_EQ(f.fe.edge_uv_seam_sets[grid_edge(f.conn, n, 1, 0, 1, 1)], 2u);
  EXPECT_EQ(find_uv_islands(g, f.conn, 0).num_islands, 1u);
  EXPECT_EQ(find_uv_islands(g, f.conn, 1).num_islands, 2u);
}

TEST(Features, SquareOutlineCornersByTurnAngle) {
  const Index n = 3;
  PolyMesh g = make_grid(n, n);
  g.uv_sets.clear();
  Found f = features_of(g);
  EXPECT_EQ(f.fe.feature_edges, 4 * n);
  EXPECT_EQ(bit_count(f.fe, kFeatureBoundary), 4 * n);
  EXPECT_EQ(f.fe.corners, 4u);  // 90° turns; the sides run straight
  for (Index v : {Index{0}, n, n * (n + 1), (n + 1) * (n + 1) - 1}) EXPECT_TRUE(f.fe.vertex_corner[v]);
  EXPECT_EQ(f.fe.num_lines, 4u);
  // With corners only beyond 95° the outline is one closed loop anchored at its smallest vertex.
  FeatureParams loose;
  loose.corner_angle_deg = 95.0;
  f = features_of(g, loose);
  EXPECT_EQ(f.fe.corners, 1u);
  EXPECT_TRUE(f.fe.vertex_corner[0]);
  EXPECT_EQ(f.fe.num_lines, 1u);
  for (Index e = 0; e < f.conn.num_edges; ++e)
    EXPECT_EQ(f.fe.edge_line[e], f.fe.is_feature(e) ? 0u : kInvalidIndex);
}

TEST(Features, InconsistentOrientationIsNotAHardEdge) {
  // Two coplanar quads, the second listed clockwise: the normals are opposite, the surface is
  // flat, so the dihedral angle is 0°. Its edge runs the same way in both faces.
  PolyMesh m;
  for (int i = 0; i < 3; ++i) {
    m.add_vertex(Vec3(i, 0, 0));
    m.add_vertex(Vec3(i, 1, 0));
  }
  m.add_face({0, 2, 3, 1});
  m.add_face({2, 3, 5, 4});
  const Found f = features_of(m);
  EXPECT_EQ(bit_count(f.fe, kFeatureHardEdge), 0u);
  EXPECT_EQ(f.fe.feature_edges, 6u);  // the boundary only
  // Folded to 90° the same pair is a hard edge: normals (0,0,1) and (1,0,0), the latter reversed.
  m.positions[4] = Vec3(1, 0, 1);
  m.positions[5] = Vec3(1, 1, 1);
  EXPECT_EQ(bit_count(features_of(m).fe, kFeatureHardEdge), 1u);
}

TEST(Features, ZeroAreaFaceMakesNoHardEdge) {
  PolyMesh m;
  m.add_vertex(Vec3(0, 0, 0));
  m.add_vertex(Vec3(1, 0, 0));
  m.add_vertex(Vec3(1, 1, 0));
  m.add_vertex(Vec3(2, 0, 0));  // (0,0) (1,0) (2,0) collinear: zero area
  m.add_face({0, 1, 2});
  m.add_face({1, 3, 2});
  m.add_face({0, 3, 1});  // zero area; makes 0-1 and 1-3 manifold edges next to it
  const Found f = features_of(m);
  EXPECT_EQ(bit_count(f.fe, kFeatureHardEdge), 0u);
}

TEST(Features, SmoothingGroupsAndNormalSeams) {
  const Index n = 4, m = 1;
  PolyMesh g = make_grid(n, m);
  g.uv_sets.clear();
  g.face_smoothing = {1, 1, 2, 2};
  Found f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureHardEdge), 1u);
  EXPECT_EQ(f.fe.edge_bits[grid_edge(f.conn, n, 2, 0, 2, 1)], kFeatureHardEdge);
  g.face_smoothing = {0, 1, 1, 1};  // smoothing off on face 0: the flat | smooth edge is hard
  EXPECT_EQ(bit_count(features_of(g).fe, kFeatureHardEdge), 1u);
  // Flat-shaded faces next to each other (s off on both): shading is per face on both sides, not
  // a crease line; only the dihedral angle makes such an edge hard. An all-flat coplanar strip has
  // no hard edge (else a faceted model could not be reduced at all: every edge a feature).
  g.face_smoothing = {0, 0, 0, 0};
  EXPECT_EQ(bit_count(features_of(g).fe, kFeatureHardEdge), 0u);
  g.face_smoothing = {0, 0, 1, 1};
  f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureHardEdge), 1u);
  EXPECT_EQ(f.fe.edge_bits[grid_edge(f.conn, n, 2, 0, 2, 1)], kFeatureHardEdge);
  FeatureParams no_groups;
  no_groups.smoothing_groups = false;
  EXPECT_EQ(bit_count(features_of(g, no_groups).fe, kFeatureHardEdge), 0u);
  g.face_smoothing.clear();

  // Per-corner normals: faces 0-1 share values, face 2 onward uses other values at x = 2.
  g.normals = {Vec3(0, 0, 1), Vec3(0, 0.6, 0.8)};
  g.corner_normal.assign(g.num_corners(), 0);
  for (Index fc = 2; fc < n; ++fc)
    for (Index c = g.face_begin(fc); c < g.face_end(fc); ++c) g.corner_normal[c] = 1;
  f = features_of(g);
  EXPECT_EQ(bit_count(f.fe, kFeatureNormalSeam), 1u);
  EXPECT_EQ(f.fe.edge_bits[grid_edge(f.conn, n, 2, 0, 2, 1)], kFeatureNormalSeam);
  // The normal seam meets the boundary: the seam's ends have valence 3.
  EXPECT_EQ(f.fe.corners, 6u);
}

TEST(Features, NonManifoldEdgeCarriesItsOwnBit) {
  // A "book" of three unit quads around the spine (0,0,0)-(0,0,1), pages 120° apart.
  PolyMesh m;
  m.add_vertex(Vec3(0, 0, 0));
  m.add_vertex(Vec3(0, 0, 1));
  for (int k = 0; k < 3; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 3.0;
    const Index p = m.add_vertex(Vec3(std::cos(a), std::sin(a), 0));
    m.add_vertex(Vec3(std::cos(a), std::sin(a), 1));
    m.add_face({0, p, p + 1, 1});
  }
  const Found f = features_of(m);
  EXPECT_EQ(bit_count(f.fe, kFeatureNonManifold), 1u);
  EXPECT_EQ(bit_count(f.fe, kFeatureBoundary), 9u);
  EXPECT_EQ(bit_count(f.fe, kFeatureHardEdge), 0u);  // only manifold edges can be hard
  const Index spine = f.conn.corner_edge[m.face_begin(0) + 3];
  EXPECT_EQ(f.fe.edge_bits[spine], kFeatureNonManifold);
  EXPECT_TRUE(f.fe.is_strict(spine));
  // Spine ends: valence 4 (the spine and three page edges): corners; page corners turn 90°.
  EXPECT_EQ(f.fe.corners, 8u);
}

// --- exact island accounting from provenance (account_uv_islands) ---------------------------------

namespace {
std::vector<Index> identity_origin(const PolyMesh& m) {
  std::vector<Index> o(m.num_faces());
  for (Index f = 0; f < m.num_faces(); ++f) o[f] = f;
  return o;
}
// out = in − vanished + split_extra − merged_reduction + appeared, the identity the report keeps.
void expect_balanced(const UvIslandAccount& a) {
  EXPECT_EQ(std::int64_t(a.out), std::int64_t(a.in) - a.vanished + a.split_extra - a.merged_reduction + a.appeared);
}
}  // namespace

TEST(UvIslandAccount, UnchangedMeshKeepsEveryIsland) {
  const PolyMesh g = grid_with_seam_column(4, 2, 2, 0.5);
  const UvIslandAccount a = account_uv_islands(g, g, identity_origin(g));
  EXPECT_EQ(a.in, 2u);
  EXPECT_EQ(a.out, 2u);
  EXPECT_EQ(a.vanished + a.merged + a.split + a.appeared, 0u);
  expect_balanced(a);
}

// grid(3, 1), one island. The output is the same mesh with face 2's UVs shifted: a seam between
// faces 1 and 2 that the input did not have, so the input island lies in two output islands.
TEST(UvIslandAccount, NewSeamInsideAnIslandIsOneSplit) {
  const PolyMesh in = make_grid(3, 1);
  PolyMesh out = in;
  UvSet& uv = out.uv_sets[0];
  for (Index c = out.face_begin(2); c < out.face_end(2); ++c) {
    uv.values.push_back(uv.values[uv.corner[c]] + Vec2(2.0, 0.0));
    uv.corner[c] = static_cast<Index>(uv.values.size() - 1);
  }
  const UvIslandAccount a = account_uv_islands(in, out, identity_origin(out));
  EXPECT_EQ(a.in, 1u);
  EXPECT_EQ(a.out, 2u);
  EXPECT_EQ(a.split, 1u);
  EXPECT_EQ(a.split_extra, 1u);
  EXPECT_EQ(a.merged + a.vanished, 0u);
  ASSERT_EQ(a.split_islands.size(), 1u);
  EXPECT_EQ(a.split_islands[0].first, 0u);
  EXPECT_EQ(a.split_islands[0].second, (std::vector<Index>{0, 1}));
  expect_balanced(a);
}

// grid_with_seam_column(2, 1, 1, 0.5): two faces, two islands. The output gives the right face
// the left chart's UVs (the seam is gone): one output island with faces from both → merged.
TEST(UvIslandAccount, SeamThatDisappearsIsOneMerge) {
  const PolyMesh in = grid_with_seam_column(2, 1, 1, 0.5);
  const PolyMesh out = make_grid(2, 1);
  const UvIslandAccount a = account_uv_islands(in, out, identity_origin(out));
  EXPECT_EQ(a.in, 2u);
  EXPECT_EQ(a.out, 1u);
  EXPECT_EQ(a.merged, 1u);
  EXPECT_EQ(a.merged_reduction, 1u);
  EXPECT_EQ(a.split + a.vanished, 0u);
  ASSERT_EQ(a.merged_islands.size(), 1u);
  EXPECT_EQ(a.merged_islands[0].second, (std::vector<Index>{0, 1}));
  expect_balanced(a);
}

// Three column islands of grid(6, 2) (columns 0–1, 2, 3–5); an output that keeps only the faces
// of the outer islands (origins say which) loses the middle one: 1 vanished, 2 faces of area 1/6,
// i.e. below one output face when the output's faces are larger.
TEST(UvIslandAccount, IslandWithoutSurvivingFacesVanishesWithItsSize) {
  const PolyMesh in = feature_test::grid_with_face_uvs(6, 2, [](Index f) { return f % 6 == 2 ? 2.0 : f % 6 > 2 ? 4.0 : 0.0; });
  // Output: one big quad per outer island (origins: an input face of that island), face 1 in a
  // chart of its own.
  PolyMesh out = make_grid(2, 1);
  for (Index c = out.face_begin(1); c < out.face_end(1); ++c) {
    out.uv_sets[0].values.push_back(out.uv_sets[0].values[out.uv_sets[0].corner[c]] + Vec2(4.0, 0.0));
    out.uv_sets[0].corner[c] = static_cast<Index>(out.uv_sets[0].values.size() - 1);
  }
  const UvIslandAccount a = account_uv_islands(in, out, {0, 5});
  EXPECT_EQ(a.in, 3u);
  EXPECT_EQ(a.out, 2u);
  EXPECT_EQ(a.vanished, 1u);
  EXPECT_EQ(a.merged + a.split, 0u);
  ASSERT_EQ(a.vanished_islands.size(), 1u);
  EXPECT_EQ(a.vanished_islands[0].island, 1u);
  EXPECT_EQ(a.vanished_islands[0].faces, 2u);
  EXPECT_NEAR(a.vanished_islands[0].area, 1.0 / 6, 1e-12);
  EXPECT_NEAR(a.vanished_islands[0].output_faces, (1.0 / 6) / 0.5, 1e-12);
  EXPECT_EQ(a.vanished_below_one_face, 1u);
  expect_balanced(a);
}

// Merge and split at once: input islands A (faces 0, 1) and B (2, 3) of grid(4, 1); the output
// cuts between 0|1 and 2|3 and joins 1–2: output islands {0}, {1, 2}, {3}. A splits (0 | 1), B
// splits (2 | 3), {1, 2} merges A and B: out 3 = 2 − 0 + 2 − 1.
TEST(UvIslandAccount, MergeAndSplitTogetherStayBalanced) {
  const PolyMesh in = feature_test::grid_with_face_uvs(4, 1, [](Index f) { return f < 2 ? 0.0 : 3.0; });
  const PolyMesh out = feature_test::grid_with_face_uvs(4, 1, [](Index f) { return f == 0 ? 0.0 : f == 3 ? 6.0 : 3.0; });
  const UvIslandAccount a = account_uv_islands(in, out, identity_origin(out));
  EXPECT_EQ(a.in, 2u);
  EXPECT_EQ(a.out, 3u);
  EXPECT_EQ(a.split, 2u);
  EXPECT_EQ(a.split_extra, 2u);
  EXPECT_EQ(a.merged, 1u);
  EXPECT_EQ(a.merged_reduction, 1u);
  expect_balanced(a);
}
