// Symmetric reduction (issue 34, docs/symmetry.md): detection, the mirror maps, and simplify()
// with --symmetry on meshes whose mirror is known by construction.
#include "mesh/connectivity.h"
#include "mesh/symmetry.h"
#include "mesh/validation.h"
#include "quadlod/generators.h"
#include "quadlod/simplify.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace quadlod {
namespace {

// A grid of n × m quads centred on the origin in x and y, bent up by a bump and a ramp: mirror
// symmetric about x = 0 only (the ramp in y and the y² term break the y mirror; z is not flat but
// not symmetric either). An odd n puts a column of quads across the plane (no vertex on it).
PolyMesh bumped_grid(Index n, Index m) {
  PolyMesh mesh = make_grid(n, m, 2.0, 1.5);
  for (Vec3& p : mesh.positions) {
    p.x() -= 1.0;
    p.y() -= 0.75;
    p.z() = 0.3 * std::exp(-3.0 * (p.x() * p.x() + p.y() * p.y())) + 0.15 * p.y() + 0.1 * p.y() * p.y() + 0.05 * p.x() * p.x();
  }
  return mesh;
}

// Coordinates rotated so that the x mirror becomes the mirror of `axis`.
PolyMesh mirror_on_axis(PolyMesh mesh, int axis) {
  for (Vec3& p : mesh.positions) {
    const Vec3 q = p;
    p[axis] = q.x();
    p[(axis + 1) % 3] = q.y();
    p[(axis + 2) % 3] = q.z();
  }
  return mesh;
}

SimplifyOptions reduce(double ratio, SimplifyOptions::Symmetry symmetry) {
  SimplifyOptions o;
  o.ratio = ratio;
  o.symmetry = symmetry;
  o.threads = 1;
  return o;
}

// The bar of the tests: every vertex of `out` has a vertex within 1e-9 of the diagonal at its
// reflection about the input's bbox-centred plane of `axis`, and a vertex that close to the plane
// is exactly on it. Returns how many vertices lie on the plane.
Index expect_mirrored(const PolyMesh& in, const PolyMesh& out, int axis, const std::string& what) {
  const BoundingBox box = bounding_box(in);
  const double diag = box.diagonal(), tol = 1e-9 * diag;
  const double c = 0.5 * (box.min[axis] + box.max[axis]);
  const MirrorPlane plane{axis, std::abs(c) <= 1e-12 * diag ? 0.0 : c};
  Index on_plane = 0, missing = 0;
  for (const Vec3& p : out.positions) {
    const Vec3 q = plane.reflect(p);
    double best = INFINITY;
    for (const Vec3& o : out.positions) best = std::min(best, (o - q).norm());
    if (!(best <= tol)) ++missing;
    if (std::abs(p[axis] - plane.centre) <= tol) {
      EXPECT_EQ(p[axis], plane.centre) << what << ": a vertex near the plane is not on it";
      ++on_plane;
    }
  }
  EXPECT_EQ(missing, 0u) << what << ": vertices without a mirror partner, of " << out.positions.size();
  return on_plane;
}

void expect_valid(const PolyMesh& in, const PolyMesh& out, const std::string& what) {
  const MeshStats a = compute_stats(in, build_connectivity(in)), b = compute_stats(out, build_connectivity(out));
  EXPECT_LE(b.nonmanifold_edges, a.nonmanifold_edges) << what;
  EXPECT_LE(b.degenerate_faces, a.degenerate_faces) << what;
  EXPECT_EQ(b.unused_vertices, 0u) << what;
}

TEST(Symmetry, MatchesPairsOnPlaneVerticesAndDuplicates) {
  // x = -1, 0, 1 (0 on the plane), a duplicate pair at ±2, and one vertex with no partner.
  const std::vector<Vec3> p = {Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(1, 0, 0), Vec3(2, 5, 0),
                               Vec3(2, 5, 0),  Vec3(-2, 5, 0), Vec3(-2, 5, 0), Vec3(3, 7, 1)};
  const VertexMirror m = match_mirror_vertices(p, MirrorPlane{0, 0.0}, 1e-6);
  EXPECT_EQ(m.partner[0], 2u);
  EXPECT_EQ(m.partner[2], 0u);
  EXPECT_EQ(m.partner[1], 1u);
  EXPECT_EQ(m.partner[3], 5u);  // each duplicate pairs with one of the other side's duplicates
  EXPECT_EQ(m.partner[4], 6u);
  EXPECT_EQ(m.partner[7], kInvalidIndex);
  EXPECT_EQ(m.pairs, 6u);
  EXPECT_EQ(m.on_plane, 1u);
  EXPECT_EQ(m.unmatched, 1u);
  EXPECT_DOUBLE_EQ(m.matched_fraction(), 7.0 / 8.0);
}

// Hostile coordinates (eval reads any file): no cast overflow, such points match nothing.
TEST(Symmetry, NonFiniteAndHugeCoordinatesMatchNothing) {
  const double nan = std::nan("");
  const std::vector<Vec3> p = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(nan, 0, 0), Vec3(1e300, 0, 0), Vec3(INFINITY, 1, 0)};
  const VertexMirror m = match_mirror_vertices(p, MirrorPlane{0, 0.0}, 1e-6);
  EXPECT_EQ(m.pairs, 2u);
  EXPECT_EQ(m.unmatched, 3u);
  EXPECT_DOUBLE_EQ(mirrored_vertex_fraction(p, MirrorPlane{0, 0.0}, 1e-6), 2.0 / 5.0);
}

TEST(Symmetry, MirrorEdgesOfAGridAreItsReflections) {
  const PolyMesh g = bumped_grid(6, 4);
  const Connectivity conn = build_connectivity(g);
  const SymmetryDetection d = detect_symmetry(g, 0);
  ASSERT_TRUE(d.symmetric());
  const std::vector<Index> em = mirror_edges(conn, d.mirror);
  Index self = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    ASSERT_NE(em[e], kInvalidIndex);
    EXPECT_EQ(em[em[e]], e);
    const auto [a, b] = conn.edge_vertices[e];
    const auto [ma, mb] = conn.edge_vertices[em[e]];
    const Vec3 mid = 0.5 * (g.positions[a] + g.positions[b]), mmid = 0.5 * (g.positions[ma] + g.positions[mb]);
    EXPECT_NEAR((d.mirror.plane.reflect(mid) - mmid).norm(), 0.0, 1e-12);
    self += em[e] == e;
  }
  EXPECT_EQ(self, 4u);  // the 4 edges of the centre column on the plane x = 0
}

TEST(Symmetry, AutoFindsTheAxisOfMeshesSymmetricInXYAndZ) {
  for (int axis = 0; axis < 3; ++axis) {
    const PolyMesh m = mirror_on_axis(bumped_grid(8, 6), axis);
    const SymmetryDetection d = detect_symmetry(m, -1);
    ASSERT_TRUE(d.symmetric()) << axis;
    EXPECT_EQ(d.mirror.plane.axis, axis);
    EXPECT_EQ(d.mirror.unmatched, 0u);
    EXPECT_EQ(d.mirror.on_plane, 7u) << axis;  // the grid's centre column
    const SimplifyResult r = simplify(m, reduce(0.5, SimplifyOptions::Symmetry::Auto));
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.report["symmetry"]["axis"], axis_name(axis));
    EXPECT_EQ(r.report["symmetry"]["requested"], "auto");
  }
}

TEST(Symmetry, SymmetricGridGivesAnExactlyMirroredOutput) {
  const PolyMesh in = bumped_grid(16, 12);
  for (double ratio : {0.4, 0.2}) {
    const std::string what = "grid at " + std::to_string(ratio);
    const SimplifyResult r = simplify(in, reduce(ratio, SimplifyOptions::Symmetry::X));
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.report["symmetry"]["axis"], "x");
    EXPECT_LT(r.achieved, r.input_tri_equivalent);
    EXPECT_NEAR(double(r.achieved), double(r.target), 0.03 * double(r.target) + 2.0) << what;
    EXPECT_GT(expect_mirrored(in, r.mesh, 0, what), 0u) << what;  // the centre column survives on the plane
    expect_valid(in, r.mesh, what);
  }
}

TEST(Symmetry, SymmetricCylinderGivesAnExactlyMirroredOutput) {
  const PolyMesh in = make_cylinder(24, 10, 0.5, 1.5);
  for (double ratio : {0.4, 0.2}) {
    const std::string what = "cylinder at " + std::to_string(ratio);
    const SimplifyResult r = simplify(in, reduce(ratio, SimplifyOptions::Symmetry::Auto));
    ASSERT_TRUE(r.ok()) << r.error;
    const std::string axis = r.report["symmetry"]["axis"];
    ASSERT_NE(axis, "none") << what;
    EXPECT_LT(r.achieved, r.input_tri_equivalent);
    expect_mirrored(in, r.mesh, axis == "x" ? 0 : axis == "y" ? 1 : 2, what);
    expect_valid(in, r.mesh, what);
  }
}

// A column of quads across the plane and no vertex on it (a centre column without a centre loop):
// its cross edges are their own mirrors, and collapsing one puts a cluster on the plane.
TEST(Symmetry, FacesStraddlingThePlaneReduceSymmetrically) {
  const PolyMesh in = bumped_grid(15, 10);
  const SymmetryDetection d = detect_symmetry(in, 0);
  ASSERT_TRUE(d.symmetric());
  EXPECT_EQ(d.mirror.on_plane, 0u);
  for (double ratio : {0.5, 0.25}) {
    const std::string what = "straddling grid at " + std::to_string(ratio);
    const SimplifyResult r = simplify(in, reduce(ratio, SimplifyOptions::Symmetry::X));
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_LT(r.achieved, r.input_tri_equivalent);
    expect_mirrored(in, r.mesh, 0, what);
    expect_valid(in, r.mesh, what);
  }
}

// Not symmetric within the tolerance: a note, and the very output of --symmetry off.
TEST(Symmetry, AnAsymmetricInputGetsTheNoteAndTheOutputOfOff) {
  PolyMesh in = bumped_grid(16, 12);
  std::mt19937 rng(34);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (Vec3& p : in.positions) p.z() += jitter(rng);
  const SimplifyResult off = simplify(in, reduce(0.4, SimplifyOptions::Symmetry::Off));
  ASSERT_TRUE(off.ok());
  EXPECT_FALSE(off.report["symmetry"].contains("note"));
  for (auto s : {SimplifyOptions::Symmetry::Auto, SimplifyOptions::Symmetry::X}) {
    const SimplifyResult r = simplify(in, reduce(0.4, s));
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.report["symmetry"]["axis"], "none");
    const std::string note = r.report["symmetry"].value("note", "");
    EXPECT_NE(note.find("not mirror-symmetric"), std::string::npos) << note;
    EXPECT_NE(note.find("reduced without symmetry"), std::string::npos) << note;
    EXPECT_EQ(note.find('\n'), std::string::npos);
    EXPECT_EQ(r.mesh.positions, off.mesh.positions);
    EXPECT_EQ(r.mesh.corner_vertex, off.mesh.corner_vertex);
    EXPECT_EQ(r.mesh.face_offsets, off.mesh.face_offsets);
  }
}

// A few unmatched vertices (under 1 - min_matched) leave the plane on; those vertices reduce
// without a mirror, the rest stays mirrored.
TEST(Symmetry, AFewUnmatchedVerticesKeepTheRestMirrored) {
  PolyMesh in = bumped_grid(16, 12);  // 221 vertices; one nudged is 0.45 % unmatched… and its mirror
  in.positions[3 * 17 + 2].z() += 0.01;
  const SimplifyResult r = simplify(in, reduce(0.4, SimplifyOptions::Symmetry::X));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.report["symmetry"]["axis"], "x");
  EXPECT_EQ(r.report["symmetry"]["unmatched_vertices"], 2);
  SimplifyOptions strict = reduce(0.4, SimplifyOptions::Symmetry::X);
  strict.symmetry_min_matched = 1.0;
  EXPECT_EQ(simplify(in, strict).report["symmetry"]["axis"], "none");
}

// Protection and symmetry together (issue 34): protect weights on one side only make auto decline
// (the output of off), an explicit axis still mirrors; mirrored weights keep the plane, and every
// weight-1 vertex stays bit-exact while its mirror is reflected.
TEST(Symmetry, OneSidedProtectionTurnsAutoOffAndProtectedVerticesStayExact) {
  const PolyMesh in = bumped_grid(16, 12);
  std::vector<double> one_side(in.num_vertices(), 0.0), both(in.num_vertices(), 0.0);
  for (Index v = 0; v < in.num_vertices(); ++v) {
    const Vec3& p = in.positions[v];
    if (p.y() > 0.3 && p.x() < -0.5) one_side[v] = 1.0;
    if (p.y() > 0.3 && std::abs(p.x()) > 0.5) both[v] = 1.0;
  }
  SimplifyOptions off = reduce(0.4, SimplifyOptions::Symmetry::Off);
  off.protect_weights = one_side;
  const SimplifyResult plain = simplify(in, off);
  SimplifyOptions aut = reduce(0.4, SimplifyOptions::Symmetry::Auto);
  aut.protect_weights = one_side;
  const SimplifyResult declined = simplify(in, aut);
  ASSERT_TRUE(plain.ok() && declined.ok());
  EXPECT_EQ(declined.report["symmetry"]["axis"], "none");
  EXPECT_NE(declined.report["symmetry"].value("note", "").find("protect weights are not"), std::string::npos);
  EXPECT_EQ(declined.mesh.positions, plain.mesh.positions);
  EXPECT_EQ(declined.mesh.corner_vertex, plain.mesh.corner_vertex);

  for (const auto& [weights, symmetry] : {std::pair{both, SimplifyOptions::Symmetry::Auto},
                                          std::pair{one_side, SimplifyOptions::Symmetry::X}}) {
    SimplifyOptions o = reduce(0.4, symmetry);
    o.protect_weights = weights;
    const SimplifyResult r = simplify(in, o);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.report["symmetry"]["axis"], "x");
    // Every weight-1 input vertex is in the output at exactly its input position.
    for (Index v = 0; v < in.num_vertices(); ++v) {
      if (weights[v] < 1.0) continue;
      const bool found = std::find(r.mesh.positions.begin(), r.mesh.positions.end(), in.positions[v]) != r.mesh.positions.end();
      EXPECT_TRUE(found) << "protected vertex " << v << " moved";
    }
    if (symmetry == SimplifyOptions::Symmetry::Auto) expect_mirrored(in, r.mesh, 0, "mirrored protection");
    expect_valid(in, r.mesh, "protected and mirrored");
  }
}

TEST(Symmetry, NamesRoundTripAndAValueOutsideTheEnumIsRefused) {
  for (const auto& [name, value] : symmetry_names()) {
    EXPECT_EQ(parse_symmetry(name), value);
    EXPECT_EQ(std::string(to_string(value)), name);
  }
  EXPECT_FALSE(parse_symmetry("sideways"));
  SimplifyOptions o = reduce(0.5, static_cast<SimplifyOptions::Symmetry>(9));
  const SimplifyResult r = simplify(make_grid(4, 4), o);
  EXPECT_NE(r.error.find("unknown symmetry 9"), std::string::npos) << r.error;
}

}  // namespace
}  // namespace quadlod
