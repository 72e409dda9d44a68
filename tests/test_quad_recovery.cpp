// Tests of src/mesh/quad_recovery.h (session 16): a fan-triangulated quad mesh (what the .glb
// writer and most exporters produce) comes back as its quads; seams, materials, folds and skewed
// pairs keep their triangles; the pipeline joins all-triangle inputs by default and says so.
#include "mesh/quad_recovery.h"

#include "quadlod/generators.h"
#include "quadlod/simplify.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <vector>

namespace quadlod {
namespace {

// Every face as the fan (c0, c_k, c_k+1), each corner carrying its UV and normal indices, each
// triangle its face's tags: as the .glb writer triangulates.
PolyMesh fan_triangulated(const PolyMesh& m) {
  PolyMesh t = m;
  t.face_offsets = {0};
  t.corner_vertex.clear();
  for (UvSet& s : t.uv_sets) s.corner.clear();
  t.corner_normal.clear();
  std::vector<Index> src_face;
  for (Index f = 0; f < m.num_faces(); ++f) {
    const Index b = m.face_begin(f);
    for (Index k = 1; k + 1 < m.face_size(f); ++k) {
      for (Index c : {b, b + k, b + k + 1}) {
        t.corner_vertex.push_back(m.corner_vertex[c]);
        for (std::size_t s = 0; s < m.uv_sets.size(); ++s) t.uv_sets[s].corner.push_back(m.uv_sets[s].corner[c]);
        if (m.has_normals()) t.corner_normal.push_back(m.corner_normal[c]);
      }
      t.face_offsets.push_back(t.num_corners());
      src_face.push_back(f);
    }
  }
  for (auto tag : {&PolyMesh::face_object, &PolyMesh::face_group, &PolyMesh::face_material, &PolyMesh::face_smoothing}) {
    if ((m.*tag).empty()) continue;
    (t.*tag).clear();
    for (Index f : src_face) (t.*tag).push_back((m.*tag)[f]);
  }
  return t;
}

std::set<std::array<Index, 4>> quads_as_sets(const PolyMesh& m) {
  std::set<std::array<Index, 4>> s;
  for (Index f = 0; f < m.num_faces(); ++f) {
    if (m.face_size(f) != 4) continue;
    std::array<Index, 4> q;
    std::copy_n(m.face_vertices(f).begin(), 4, q.begin());
    std::sort(q.begin(), q.end());
    s.insert(q);
  }
  return s;
}

// A grid whose every corner has its own UV (u, v) = (x, y): one island, no seam.
PolyMesh grid_with_uvs(Index n, Index m) {
  PolyMesh g = make_grid(n, m);
  UvSet uv;
  for (Index c = 0; c < g.num_corners(); ++c) {
    const Vec3& p = g.positions[g.corner_vertex[c]];
    uv.values.push_back(Vec2(p.x(), p.y()));
    uv.corner.push_back(c);
  }
  g.uv_sets.push_back(uv);
  return g;
}

TEST(QuadRecovery, AFanTriangulatedGridComesBackAsItsQuads) {
  const PolyMesh grid = grid_with_uvs(4, 3);
  const PolyMesh tris = fan_triangulated(grid);
  ASSERT_TRUE(all_triangles(tris));
  ASSERT_EQ(tris.num_faces(), 24);
  const QuadRecoveryResult r = recover_quads(tris);
  EXPECT_EQ(r.mesh.check_layout(), "");
  EXPECT_EQ(r.joined, 12);
  EXPECT_EQ(r.mesh.num_faces(), 12);
  EXPECT_EQ(quads_as_sets(r.mesh), quads_as_sets(grid));
  EXPECT_EQ(r.mesh.positions, grid.positions);
  // Each quad keeps the orientation of its triangles (counter-clockwise seen from +z) and every
  // corner the UV its vertex had there.
  for (Index f = 0; f < r.mesh.num_faces(); ++f) {
    EXPECT_GT(face_area_vector(r.mesh, f).z(), 0.0) << "face " << f;
    for (Index c = r.mesh.face_begin(f); c < r.mesh.face_end(f); ++c) {
      const Vec2 uv = r.mesh.uv_sets[0].values[r.mesh.uv_sets[0].corner[c]];
      EXPECT_EQ(uv, r.mesh.positions[r.mesh.corner_vertex[c]].head<2>());
    }
  }
  EXPECT_FALSE(all_triangles(r.mesh));
}

TEST(QuadRecovery, ASeamOrAMaterialBorderAlongTheDiagonalKeepsTheTriangles) {
  PolyMesh tris = fan_triangulated(grid_with_uvs(2, 1));  // two quads, four triangles
  ASSERT_EQ(tris.num_faces(), 4);
  // A UV seam along the first quad's diagonal: its second triangle's corner at the shared vertex
  // c0 gets a UV of its own (the same value: a seam is a split, not a distance).
  PolyMesh seam = tris;
  seam.uv_sets[0].values.push_back(seam.uv_sets[0].values[seam.uv_sets[0].corner[3]]);
  seam.uv_sets[0].corner[3] = static_cast<Index>(seam.uv_sets[0].values.size() - 1);
  QuadRecoveryResult r = recover_quads(seam);
  EXPECT_EQ(r.joined, 1);
  EXPECT_EQ(r.mesh.num_faces(), 3);
  // A material border along the second quad's diagonal.
  PolyMesh material = tris;
  material.face_material = {0, 0, 0, 1};
  material.material_names = {"a", "b"};
  r = recover_quads(material);
  EXPECT_EQ(r.joined, 1);
  EXPECT_EQ(r.mesh.face_material, (std::vector<Index>{0, 0, 1}));
}

TEST(QuadRecovery, AFoldedOrSkewedPairStaysTwoTriangles) {
  // One quad, folded along its diagonal by lifting a corner: the triangles' normals are 45° apart.
  PolyMesh fold = fan_triangulated(make_grid(1, 1));
  const Index lifted = fold.corner_vertex[fold.face_begin(0) + 1];  // a corner off the diagonal
  fold.positions[lifted].z() = 1.0;
  EXPECT_EQ(recover_quads(fold).joined, 0);
  QuadRecoveryParams loose;
  loose.max_fold_deg = 60.0;
  loose.max_corner_deviation_deg = 90.0;
  EXPECT_EQ(recover_quads(fold, loose).joined, 1);
  // A rhombus with 45° and 135° corners: a corner 45° off a right angle.
  PolyMesh skew = fan_triangulated(make_grid(1, 1));
  for (Vec3& p : skew.positions) p.x() += p.y();
  EXPECT_EQ(recover_quads(skew).joined, 0);
  loose.max_corner_deviation_deg = 50.0;
  EXPECT_EQ(recover_quads(skew, loose).joined, 1);
}

TEST(QuadRecovery, EachTriangleJoinsOnceTheBetterPairFirst) {
  // The unit square 1-2-3-4 split by its diagonal 2-4, and a triangle 2-1-0 hung under its side
  // 1-2: the triangle (1, 2, 4) pairs with either. With every pair allowed, the square (corner
  // deviation 0) wins although the other pair's edge 1-2 comes first in edge order, and the hung
  // triangle stays.
  PolyMesh m;
  for (const Vec3& p : {Vec3(0.5, -0.6, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)}) m.add_vertex(p);
  m.add_face({1, 2, 4});
  m.add_face({2, 3, 4});
  m.add_face({2, 1, 0});
  QuadRecoveryParams any;
  any.max_fold_deg = 180.0;
  any.max_corner_deviation_deg = 90.0;
  const QuadRecoveryResult r = recover_quads(m, any);
  EXPECT_EQ(r.candidates, 2);
  EXPECT_EQ(r.joined, 1);
  EXPECT_EQ(quads_as_sets(r.mesh), (std::set<std::array<Index, 4>>{{1, 2, 3, 4}}));
  ASSERT_EQ(r.mesh.num_faces(), 2);
  EXPECT_EQ(r.mesh.face_size(1), 3);
  // At the defaults the other pair is not even a candidate: its quad 2-4-1-0 has a 45° corner at 1.
  EXPECT_EQ(recover_quads(m).candidates, 1);
}

TEST(QuadRecovery, SimplifyJoinsAnAllTriangleInputByDefaultAndSaysSo) {
  const PolyMesh torus = make_torus(24, 12);
  const PolyMesh tris = fan_triangulated(torus);
  SimplifyOptions options;
  options.ratio = 0.5;
  options.threads = 1;
  const SimplifyResult joined = simplify(tris, options);
  ASSERT_TRUE(joined.ok()) << joined.error;
  ASSERT_TRUE(joined.report.contains("quad_recovery"));
  EXPECT_EQ(joined.report["quad_recovery"]["quads_made"].get<Index>(), torus.num_faces());
  EXPECT_EQ(joined.report["quad_recovery"]["faces_after"].get<Index>(), torus.num_faces());
  EXPECT_EQ(joined.report["options"]["recover_quads"].get<std::string>(), "auto");
  // The same reduction as of the quad torus itself: its quads were found again exactly.
  options.recover_quads = SimplifyOptions::QuadRecovery::Off;
  const SimplifyResult quads = simplify(torus, options);
  ASSERT_TRUE(quads.ok()) << quads.error;
  EXPECT_EQ(joined.mesh.corner_vertex, quads.mesh.corner_vertex);
  EXPECT_EQ(joined.mesh.positions, quads.mesh.positions);
  // Off: triangles in, triangles out.
  const SimplifyResult plain = simplify(tris, options);
  ASSERT_TRUE(plain.ok()) << plain.error;
  EXPECT_FALSE(plain.report.contains("quad_recovery"));
  for (Index f = 0; f < plain.mesh.num_faces(); ++f) EXPECT_EQ(plain.mesh.face_size(f), 3);
  // A mesh with quads is left alone by "auto".
  options.recover_quads = SimplifyOptions::QuadRecovery::Auto;
  EXPECT_FALSE(simplify(torus, options).report.contains("quad_recovery"));
  // The names the CLI, manifests and Python take; a value outside the enum is refused.
  EXPECT_EQ(parse_quad_recovery("on"), SimplifyOptions::QuadRecovery::On);
  EXPECT_EQ(parse_quad_recovery("sometimes"), std::nullopt);
  EXPECT_STREQ(to_string(SimplifyOptions::QuadRecovery::Off), "off");
  options.recover_quads = static_cast<SimplifyOptions::QuadRecovery>(7);
  EXPECT_EQ(simplify(tris, options).error, "unknown recover_quads 7 (auto, on, off)");
}

}  // namespace
}  // namespace quadlod
