// Mesh kernel, connectivity, generators and statistics against hand-counted answers.
#include "mesh/connectivity.h"
#include "mesh/validation.h"
#include "quadlod/generators.h"
#include "quadlod/mesh.h"

#include <gtest/gtest.h>

#include <set>

using namespace quadlod;

namespace {

// Checks the structural invariants every Connectivity must satisfy.
void expect_consistent(const PolyMesh& mesh, const Connectivity& conn) {
  ASSERT_EQ(mesh.check_layout(), "");
  ASSERT_EQ(conn.corner_edge.size(), mesh.num_corners());
  for (Index c = 0; c < mesh.num_corners(); ++c) {
    const Index e = conn.corner_edge[c];
    ASSERT_LT(e, conn.num_edges);
    const Index a = mesh.corner_vertex[c], b = conn.tip_vertex(c);
    EXPECT_EQ(conn.edge_vertices[e][0], std::min(a, b));
    EXPECT_EQ(conn.edge_vertices[e][1], std::max(a, b));
    EXPECT_EQ(conn.corner_prev[conn.corner_next[c]], c);
    const auto cs = conn.corners_of_edge(e);
    EXPECT_NE(std::find(cs.begin(), cs.end(), c), cs.end());
  }
  Index total = 0;
  for (Index e = 0; e < conn.num_edges; ++e) total += conn.edge_face_count(e);
  EXPECT_EQ(total, mesh.num_corners());
}

MeshStats stats_of(const PolyMesh& mesh) { return compute_stats(mesh, build_connectivity(mesh)); }

}  // namespace

TEST(MeshKernel, AddFaceKeepsAttributeArraysAligned) {
  PolyMesh m;
  for (int i = 0; i < 4; ++i) m.add_vertex(Vec3(i, i * i, 0));
  m.uv_sets.clear();
  m.face_material.clear();
  m.add_face({0, 1, 2});
  m.uv_sets.resize(1);
  m.uv_sets[0].values.emplace_back(0.5, 0.5);
  m.uv_sets[0].corner.assign(3, 0);
  m.material_names = {"steel"};
  m.face_material = {0};
  m.add_face({0, 2, 3});
  EXPECT_EQ(m.num_faces(), 2u);
  EXPECT_EQ(m.uv_sets[0].corner.size(), 6u);
  EXPECT_EQ(m.uv_sets[0].corner[5], kInvalidIndex);
  EXPECT_EQ(m.face_material[1], kInvalidIndex);
  EXPECT_EQ(m.check_layout(), "");
}

TEST(MeshKernel, CheckLayoutNamesTheBadElement) {
  PolyMesh m;
  m.add_vertex(Vec3(0, 0, 0));
  m.add_vertex(Vec3(1, 0, 0));
  m.add_vertex(Vec3(0, 1, 0));
  m.add_face({0, 1, 2});
  m.corner_vertex[2] = 7;
  EXPECT_NE(m.check_layout().find("corner 2"), std::string::npos);
  m.corner_vertex[2] = 2;
  m.uv_sets.resize(1);
  m.uv_sets[0].corner = {0, 0, 0};
  EXPECT_NE(m.check_layout().find("uv"), std::string::npos);
}

TEST(MeshKernel, FaceGeometry) {
  PolyMesh quad = make_grid(1, 1, 2.0, 3.0);
  EXPECT_NEAR(face_area_vector(quad, 0).z(), 6.0, 1e-12);
  EXPECT_TRUE(face_normal(quad, 0).isApprox(Vec3(0, 0, 1)));
  EXPECT_TRUE(face_centroid(quad, 0).isApprox(Vec3(1.0, 1.5, 0)));
  EXPECT_EQ(tri_equivalent_count(quad), 2u);
  EXPECT_EQ(tri_equivalent(7), 5u);
}

TEST(Connectivity, GridCounts) {
  const Index n = 5, m = 3;
  PolyMesh grid = make_grid(n, m);
  Connectivity conn = build_connectivity(grid);
  expect_consistent(grid, conn);
  EXPECT_EQ(conn.num_edges, n * (m + 1) + m * (n + 1));
  Index boundary = 0;
  for (Index e = 0; e < conn.num_edges; ++e) boundary += conn.is_boundary_edge(e);
  EXPECT_EQ(boundary, 2 * (n + m));
  const auto loops = boundary_loops(conn);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].corners.size(), 2 * (n + m));
  // The loop is closed: each corner's tip is the next corner's vertex.
  for (std::size_t i = 0; i < loops[0].corners.size(); ++i) {
    const Index c = loops[0].corners[i];
    const Index d = loops[0].corners[(i + 1) % loops[0].corners.size()];
    EXPECT_EQ(conn.tip_vertex(c), grid.corner_vertex[d]);
  }
  EXPECT_EQ(face_components(conn).count, 1u);
}

TEST(Connectivity, OppositeEdgesAndAcross) {
  PolyMesh grid = make_grid(2, 1);  // two quads side by side
  Connectivity conn = build_connectivity(grid);
  // Face 0 = (0,1,4,3): corner 1 has edge 1→4, shared with face 1's corner 7 (edge 4→1).
  EXPECT_EQ(conn.across(1), 7u);
  EXPECT_EQ(conn.across(7), 1u);
  EXPECT_EQ(conn.across(0), kInvalidIndex);  // boundary
  EXPECT_EQ(conn.opposite_corner_in_quad(1), 3u);
  EXPECT_EQ(conn.opposite_corner_in_quad(3), 1u);
  EXPECT_EQ(conn.corner_edge[conn.opposite_corner_in_quad(0)], conn.corner_edge[2]);
}

TEST(Connectivity, ClosedMeshesHaveNoBoundary) {
  const std::pair<PolyMesh, long> cases[] = {
      {make_torus(8, 5), 0}, {make_cube(1), 2}, {make_cube(3), 2}, {make_demo_vase(12, 6), 2}};
  for (const auto& [mesh, euler] : cases) {
    Connectivity conn = build_connectivity(mesh);
    expect_consistent(mesh, conn);
    const MeshStats s = compute_stats(mesh, conn);
    EXPECT_EQ(s.boundary_edges, 0u);
    EXPECT_EQ(s.boundary_loops, 0u);
    EXPECT_EQ(s.nonmanifold_edges, 0u);
    EXPECT_EQ(s.nonmanifold_vertices, 0u);
    EXPECT_EQ(s.components, 1u);
    EXPECT_EQ(long(s.vertices) - long(s.edges) + long(s.faces), euler);
  }
}

TEST(Generators, KnownCounts) {
  EXPECT_EQ(make_torus(8, 5).num_faces(), 40u);
  EXPECT_EQ(make_cube(1).num_vertices(), 8u);
  EXPECT_EQ(make_cube(3).num_faces(), 54u);
  EXPECT_EQ(make_cube(3).num_vertices(), 56u);  // 6k² + 2 for k = 3
  const PolyMesh cyl = make_cylinder(6, 4);
  EXPECT_EQ(cyl.num_vertices(), 30u);
  EXPECT_EQ(stats_of(cyl).boundary_loops, 2u);
  const MeshStats vase = stats_of(make_demo_vase(10, 4));
  EXPECT_EQ(vase.quads, 40u);
  EXPECT_EQ(vase.triangles, 10u);
  EXPECT_EQ(vase.ngons, 1u);
  EXPECT_EQ(vase.tri_equivalent, 80u + 10u + 8u);
  EXPECT_TRUE(vase.has_uvs);
}

TEST(Generators, FacesPointOutward) {
  // For a closed mesh the signed volume (divergence theorem) is positive iff faces point out.
  for (const PolyMesh& mesh : {make_torus(12, 8), make_cube(2), make_demo_vase(16, 8)}) {
    double volume = 0;
    for (Index f = 0; f < mesh.num_faces(); ++f)
      volume += face_area_vector(mesh, f).dot(face_centroid(mesh, f)) / 3.0;
    EXPECT_GT(volume, 0.0);
  }
  EXPECT_NEAR([] {
    const PolyMesh c = make_cube(2, 2.0);
    double v = 0;
    for (Index f = 0; f < c.num_faces(); ++f) v += face_area_vector(c, f).dot(face_centroid(c, f)) / 3.0;
    return v;
  }(), 8.0, 1e-12);
}

TEST(Validation, NonManifoldEdgeAndBowTie) {
  // Three triangles around edge (0,1): a non-manifold edge.
  PolyMesh fin;
  fin.add_vertex(Vec3(0, 0, 0));
  fin.add_vertex(Vec3(1, 0, 0));
  fin.add_vertex(Vec3(0, 1, 0));
  fin.add_vertex(Vec3(0, -1, 0));
  fin.add_vertex(Vec3(0, 0, 1));
  fin.add_face({0, 1, 2});
  fin.add_face({1, 0, 3});
  fin.add_face({0, 1, 4});
  const MeshStats s = stats_of(fin);
  EXPECT_EQ(s.nonmanifold_edges, 1u);
  EXPECT_EQ(s.nonmanifold_vertices, 2u);
  EXPECT_EQ(s.components, 1u);

  // Two triangles touching at one vertex: a bow-tie, two components.
  PolyMesh bow;
  for (Vec3 p : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(-1, 0, 0), Vec3(-1, -1, 0)})
    bow.add_vertex(p);
  bow.add_face({0, 1, 2});
  bow.add_face({0, 3, 4});
  const MeshStats b = stats_of(bow);
  EXPECT_EQ(b.nonmanifold_edges, 0u);
  EXPECT_EQ(b.nonmanifold_vertices, 1u);
  EXPECT_EQ(b.components, 2u);
  EXPECT_EQ(b.boundary_loops, 2u);  // one simple loop per triangle, not a figure eight
}

TEST(Validation, DegenerateAndDuplicateFaces) {
  PolyMesh m = make_grid(2, 1);
  m.add_face({0, 1, 4, 3});  // same as face 0
  m.add_face({3, 4, 1, 0});  // flipped copy of face 0
  const Index a = m.add_vertex(Vec3(5, 0, 0));
  const Index b = m.add_vertex(Vec3(6, 0, 0));
  const Index c = m.add_vertex(Vec3(7, 0, 0));
  m.add_face({a, b, c});     // collinear: zero area
  m.add_face({0, 1, 1, 4});  // repeated index
  // Two distinct vertices on one point: a quad shaped like a triangle, with area.
  const Index d = m.add_vertex(Vec3(10, 0, 0)), e = m.add_vertex(Vec3(10, 0, 0));
  const Index f = m.add_vertex(Vec3(11, 1, 0)), g = m.add_vertex(Vec3(10, 1, 0));
  m.add_face({d, e, f, g});
  const MeshStats s = stats_of(m);
  EXPECT_EQ(s.duplicate_faces, 2u);
  EXPECT_EQ(s.zero_area_faces, 1u);  // the collinear triangle; the repeated-index quad has area
  EXPECT_EQ(s.repeated_index_faces, 1u);
  EXPECT_EQ(s.degenerate_faces, 2u);
  // Face 0's four edges now carry three or more faces each; (1,1) and (0,4) of the repeated-index
  // quad are boundary edges.
  EXPECT_EQ(s.nonmanifold_edges, 4u);
  // Zero length: (d, e), and (1, 1) of the repeated-index quad.
  EXPECT_EQ(s.zero_length_edges, 2u);
}

TEST(Validation, PipelineInputChecks) {
  PolyMesh m = make_grid(1, 1);
  EXPECT_EQ(check_pipeline_input(m), "");
  m.positions[2].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(check_pipeline_input(m).find("vertex 3"), std::string::npos);
  PolyMesh empty;
  EXPECT_NE(check_pipeline_input(empty).find("no faces"), std::string::npos);
}
