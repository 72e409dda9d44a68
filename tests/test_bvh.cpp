// Tests of src/geometry/bvh.h: exact point–triangle / point–segment closest points (every Voronoi
// region, degenerate triangles, a dense-grid oracle) and the BVH against brute force.
#include "geometry/bvh.h"
#include "geometry/sampling.h"
#include "quadlod/generators.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace quadlod {
namespace {

// std::mt19937_64 is specified bit-exactly by the standard; we only use its raw output.
double uniform(std::mt19937_64& g, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(g() >> 11) * 0x1.0p-53);
}
Vec3 random_point(std::mt19937_64& g, double lo, double hi) {
  return {uniform(g, lo, hi), uniform(g, lo, hi), uniform(g, lo, hi)};
}

// Proper rotation from a random unit quaternion.
Eigen::Matrix3d random_rotation(std::mt19937_64& g) {
  Eigen::Quaterniond q(uniform(g, -1, 1), uniform(g, -1, 1), uniform(g, -1, 1), uniform(g, -1, 1));
  q.normalize();
  return q.toRotationMatrix();
}

// --- closest point on a triangle ----------------------------------------------------------------

struct RegionCase {
  Vec3 p;
  Vec3 expected;
  TriangleRegion region;
};

// Triangle a=(0,0,0), b=(1,0,0), c=(0,1,0); one query in each of the 7 Voronoi regions, off the
// plane so the normal component is exercised too.
std::vector<RegionCase> region_cases() {
  return {
      {{-1.0, -1.0, 0.5}, {0, 0, 0}, TriangleRegion::VertexA},
      {{2.0, -0.5, 0.3}, {1, 0, 0}, TriangleRegion::VertexB},
      {{-0.5, 2.0, -0.2}, {0, 1, 0}, TriangleRegion::VertexC},
      {{0.3, -1.0, 0.7}, {0.3, 0, 0}, TriangleRegion::EdgeAB},
      {{1.0, 1.0, 0.5}, {0.5, 0.5, 0}, TriangleRegion::EdgeBC},
      {{-1.0, 0.4, 0.2}, {0, 0.4, 0}, TriangleRegion::EdgeCA},
      {{0.2, 0.3, 0.9}, {0.2, 0.3, 0}, TriangleRegion::Face},
  };
}

TEST(BvhClosestPoint, TriangleAllSevenVoronoiRegions) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  for (const RegionCase& rc : region_cases()) {
    const TrianglePoint tp = closest_point_on_triangle(rc.p, a, b, c);
    EXPECT_EQ(tp.region, rc.region) << rc.p.transpose();
    EXPECT_LE((tp.point - rc.expected).norm(), 1e-15) << rc.p.transpose();
  }
}

TEST(BvhClosestPoint, TriangleRegionsUnderRigidMotions) {
  // The same seven cases after random rotations, translations and corner relabelings
  // (b, c, a) — the answer point moves with the triangle.
  std::mt19937_64 g(7);
  const Vec3 a0(0, 0, 0), b0(1, 0, 0), c0(0, 1, 0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d R = random_rotation(g);
    const Vec3 t = random_point(g, -10, 10);
    const double s = uniform(g, 0.01, 100.0);
    auto X = [&](const Vec3& p) { return Vec3(R * (s * p) + t); };
    for (const RegionCase& rc : region_cases()) {
      const TrianglePoint tp = closest_point_on_triangle(X(rc.p), X(a0), X(b0), X(c0));
      EXPECT_EQ(tp.region, rc.region);
      EXPECT_LE((tp.point - X(rc.expected)).norm(), 1e-12 * (1 + s + t.norm()));
      // Relabel corners: (b, c, a) — the region names rotate accordingly.
      const TrianglePoint tq = closest_point_on_triangle(X(rc.p), X(b0), X(c0), X(a0));
      EXPECT_LE((tq.point - X(rc.expected)).norm(), 1e-12 * (1 + s + t.norm()));
    }
  }
}

// Oracle: the closest point q of a triangle to p is on the triangle, and no point of a dense
// barycentric grid on the triangle is closer than q (up to rounding).
TEST(BvhClosestPoint, TriangleAgainstDenseGridOracle) {
  std::mt19937_64 g(11);
  constexpr int kGrid = 60;
  for (int trial = 0; trial < 150; ++trial) {
    const Vec3 a = random_point(g, -1, 1), b = random_point(g, -1, 1), c = random_point(g, -1, 1);
    const Vec3 p = random_point(g, -2, 2);
    const TrianglePoint tp = closest_point_on_triangle(p, a, b, c);
    const double d = std::sqrt(tp.distance_sq);
    EXPECT_NEAR(d, (p - tp.point).norm(), 1e-12);
    double grid_min = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= kGrid; ++i)
      for (int j = 0; i + j <= kGrid; ++j) {
        const double u = double(i) / kGrid, v = double(j) / kGrid;
        grid_min = std::min(grid_min, (p - ((1 - u - v) * a + u * b + v * c)).norm());
      }
    EXPECT_LE(d, grid_min + 1e-12);
    // The grid is 1/60 fine: its minimum is within one grid cell diameter of the true minimum.
    const double cell = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()}) / kGrid;
    EXPECT_GE(d, grid_min - cell);
    // q lies on the triangle: its barycentric coordinates (least squares) are in [0, 1].
    Eigen::Matrix<double, 3, 2> M;
    M << b - a, c - a;
    const Eigen::Vector2d uv = M.colPivHouseholderQr().solve(tp.point - a);
    EXPECT_GE(uv[0], -1e-9);
    EXPECT_GE(uv[1], -1e-9);
    EXPECT_LE(uv[0] + uv[1], 1 + 1e-9);
    EXPECT_LE((M * uv + a - tp.point).norm(), 1e-12);
    // First-order optimality in the face region: p − q is normal to the plane.
    if (tp.region == TriangleRegion::Face) {
      EXPECT_LE(std::abs((p - tp.point).dot(b - a)), 1e-12);
      EXPECT_LE(std::abs((p - tp.point).dot(c - a)), 1e-12);
    }
  }
}

double min_over_edges(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return std::min({(p - closest_point_on_segment(p, a, b)).norm(),
                   (p - closest_point_on_segment(p, b, c)).norm(),
                   (p - closest_point_on_segment(p, c, a)).norm()});
}

TEST(BvhClosestPoint, DegenerateTrianglesAreTheirEdges) {
  std::mt19937_64 g(13);
  for (int trial = 0; trial < 500; ++trial) {
    const Vec3 a = random_point(g, -1, 1), b = random_point(g, -1, 1);
    const double t = uniform(g, -0.5, 1.5);
    // Collinear (c on the line ab, inside or outside), two corners equal, all equal.
    const std::array<std::array<Vec3, 3>, 5> tris = {{{a, b, Vec3(a + t * (b - a))},
                                                      {a, Vec3(a + t * (b - a)), b},
                                                      {a, a, b},
                                                      {a, b, b},
                                                      {a, a, a}}};
    const Vec3 p = random_point(g, -2, 2);
    for (const auto& tri : tris) {
      const TrianglePoint tp = closest_point_on_triangle(p, tri[0], tri[1], tri[2]);
      ASSERT_TRUE(tp.point.allFinite());
      EXPECT_NEAR((p - tp.point).norm(), min_over_edges(p, tri[0], tri[1], tri[2]), 1e-12);
      EXPECT_NEAR(std::sqrt(tp.distance_sq), min_over_edges(p, tri[0], tri[1], tri[2]), 1e-12);
    }
  }
  // A point exactly on a zero-area triangle's line: distance 0.
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(1, 0, 0);
  EXPECT_EQ((closest_point_on_triangle(Vec3(0.5, 0, 0), a, b, c).point - Vec3(0.5, 0, 0)).norm(), 0.0);
}

TEST(BvhClosestPoint, SliversAreExact) {
  // Cap-shaped slivers (c near the middle of ab, lifted by `height`) and needles: the true distance
  // d* satisfies edges − height <= d* <= edges; a point on the sliver is at distance 0. (Ericson's
  // dot-product region tests fail the last check by up to 0.2 for relative heights 1e-10…1e-7.)
  std::mt19937_64 g(37);
  for (double rel : {0.0, 1e-14, 1e-11, 1e-10, 1e-9, 1e-7, 1e-4}) {
    for (int trial = 0; trial < 300; ++trial) {
      const Vec3 a = random_point(g, -1, 1), b = random_point(g, -1, 1);
      const Vec3 dir = (b - a).normalized();
      Vec3 side = dir.cross(random_point(g, -1, 1)).normalized();
      const double len = (b - a).norm();
      const double height = rel * len;
      const Vec3 cap = a + uniform(g, -0.2, 1.2) * (b - a) + height * side;
      const Vec3 needle = b + 1e-3 * (b - a) + height * side;
      for (const Vec3& c : {cap, needle}) {
        const Vec3 p = random_point(g, -2, 2);
        const TrianglePoint tp = closest_point_on_triangle(p, a, b, c);
        const double d = std::sqrt(tp.distance_sq);
        EXPECT_NEAR(d, (p - tp.point).norm(), 1e-12);
        const double e = min_over_edges(p, a, b, c);
        EXPECT_LE(d, e + 1e-13) << rel;
        EXPECT_GE(d, e - height - 1e-12) << rel;
        // A point on the sliver itself.
        const double u = uniform(g, 0, 1), v = uniform(g, 0, 1 - u);
        const Vec3 on = (1 - u - v) * a + u * b + v * c;
        const TrianglePoint to = closest_point_on_triangle(on, a, b, c);
        EXPECT_LE(std::sqrt(to.distance_sq), 1e-13) << rel;
        EXPECT_LE((on - to.point).norm(), 1e-13) << rel;
      }
    }
  }
}

TEST(BvhClosestPoint, Segment) {
  const Vec3 a(0, 0, 0), b(2, 0, 0);
  EXPECT_EQ(closest_point_on_segment(Vec3(-1, 1, 0), a, b), a);
  EXPECT_EQ(closest_point_on_segment(Vec3(3, 1, 0), a, b), b);
  EXPECT_EQ(closest_point_on_segment(Vec3(0.5, 1, 7), a, b), Vec3(0.5, 0, 0));
  EXPECT_EQ(closest_point_on_segment(Vec3(0.5, 1, 7), a, a), a);
}

// --- BVH against brute force ----------------------------------------------------------------------

std::vector<std::array<Vec3, 3>> random_soup(std::mt19937_64& g, int n, double size) {
  std::vector<std::array<Vec3, 3>> tris;
  for (int i = 0; i < n; ++i) {
    const Vec3 o = random_point(g, -1, 1);
    tris.push_back({o, Vec3(o + random_point(g, -size, size)), Vec3(o + random_point(g, -size, size))});
  }
  return tris;
}

// The oracle: every triangle, in input order (frames built once: the same values as
// closest_point_on_triangle(p, a, b, c), see bvh.h).
NearestHit brute_force(const std::vector<TriangleFrame>& frames, const Vec3& p) {
  NearestHit h;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const TrianglePoint tp = closest_point_on_triangle(frames[i], p);
    if (tp.distance_sq < h.distance_sq) h = {tp.distance_sq, tp.point, static_cast<Index>(i)};
  }
  return h;
}

void expect_matches_brute_force(const std::vector<std::array<Vec3, 3>>& tris, std::mt19937_64& g,
                                int queries, const char* what) {
  const TriangleBvh bvh(tris);
  ASSERT_EQ(bvh.size(), tris.size());
  std::vector<TriangleFrame> frames;
  for (const auto& t : tris) frames.push_back(make_triangle_frame(t[0], t[1], t[2]));
  int exact = 0;
  double max_diff = 0.0;
  for (int k = 0; k < queries; ++k) {
    // Mix far points, near points and points on the surface.
    Vec3 p;
    switch (k % 3) {
      case 0: p = random_point(g, -3, 3); break;
      case 1: p = random_point(g, -1.1, 1.1); break;
      default: {
        const auto& t = tris[g() % tris.size()];
        const double u = uniform(g, 0, 1), v = uniform(g, 0, 1 - u);
        p = (1 - u - v) * t[0] + u * t[1] + v * t[2];
      }
    }
    const NearestHit want = brute_force(frames, p);
    const NearestHit got = bvh.nearest(p);
    ASSERT_NE(got.primitive, kInvalidIndex);
    // A warm-start hint (any triangle) changes no distance.
    const NearestHit hinted = bvh.nearest(p, static_cast<Index>(g() % tris.size()));
    ASSERT_LE(std::abs(std::sqrt(hinted.distance_sq) - std::sqrt(want.distance_sq)), 1e-14) << what;
    ASSERT_LE(std::abs(std::sqrt(got.distance_sq) - std::sqrt(want.distance_sq)), 1e-12)
        << what << " query " << k;
    // The reported primitive really is at the reported distance, through the reported point.
    const auto& t = tris[got.primitive];
    const TrianglePoint tp = closest_point_on_triangle(p, t[0], t[1], t[2]);
    EXPECT_EQ(tp.point, got.point);
    EXPECT_EQ(tp.distance_sq, got.distance_sq);
    exact += got.distance_sq == want.distance_sq;
    max_diff = std::max(max_diff, std::abs(std::sqrt(got.distance_sq) - std::sqrt(want.distance_sq)));
  }
  // Pruning compares box distances with frame-computed triangle distances, which may differ in
  // the last bits, so a handful of queries may pick a rounding-tied neighbour.
  EXPECT_GE(exact, queries - queries / 100) << what;
  EXPECT_LE(max_diff, 1e-14) << what;
}

TEST(BvhNearest, TriangleBvhMatchesBruteForceOnRandomSoups) {
  std::mt19937_64 g(17);
  // 5 850 queries in all; sized so the sanitizer build stays fast.
  for (int n : {1, 2, 3, 7, 50, 300, 1000}) {
    for (double size : {0.01, 0.2, 1.5}) {
      const auto tris = random_soup(g, n, size);
      expect_matches_brute_force(tris, g, n >= 1000 ? 150 : n >= 300 ? 200 : 300, "soup");
    }
  }
}

TEST(BvhNearest, TriangleBvhMatchesBruteForceOnMeshes) {
  std::mt19937_64 g(19);
  for (const PolyMesh& m : {make_torus(20, 10), make_demo_vase(16, 8), make_cube(4), make_grid(12, 12)}) {
    // Add noise so nothing is axis aligned or exactly planar.
    PolyMesh noisy = m;
    for (Vec3& p : noisy.positions) p += random_point(g, -0.01, 0.01);
    const auto soup = fan_triangulate(noisy);
    expect_matches_brute_force(soup.triangles, g, 400, "mesh");
  }
}

TEST(BvhNearest, DegenerateAndDuplicateTriangles) {
  std::mt19937_64 g(23);
  std::vector<std::array<Vec3, 3>> tris;
  // 300 copies of one triangle (all centroids coincide), zero-area triangles, and points.
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  for (int i = 0; i < 150; ++i) tris.push_back({a, b, c});
  for (int i = 0; i < 60; ++i) {
    const Vec3 p = random_point(g, -1, 1), q = random_point(g, -1, 1);
    tris.push_back({p, q, Vec3(0.5 * (p + q))});
    tris.push_back({p, p, p});
  }
  const TriangleBvh bvh(tris);
  EXPECT_LE(bvh.tree().depth(), 40u);
  expect_matches_brute_force(tris, g, 500, "degenerate");
}

TEST(BvhNearest, EmptyBvh) {
  const TriangleBvh bvh(std::span<const std::array<Vec3, 3>>{});
  const NearestHit h = bvh.nearest(Vec3(1, 2, 3));
  EXPECT_EQ(h.primitive, kInvalidIndex);
  EXPECT_TRUE(std::isinf(h.distance_sq));
  const SegmentBvh sb(std::span<const std::array<Vec3, 2>>{});
  EXPECT_EQ(sb.nearest(Vec3(0, 0, 0)).primitive, kInvalidIndex);
}

TEST(BvhNearest, SegmentBvhMatchesBruteForce) {
  std::mt19937_64 g(29);
  for (int n : {1, 5, 100, 1000}) {
    std::vector<std::array<Vec3, 2>> segs;
    for (int i = 0; i < n; ++i) {
      const Vec3 o = random_point(g, -1, 1);
      segs.push_back({o, Vec3(o + random_point(g, -0.1, 0.1))});
      if (i % 17 == 0) segs.push_back({o, o});  // zero length
    }
    const SegmentBvh bvh(segs);
    for (int k = 0; k < 500; ++k) {
      const Vec3 p = random_point(g, -1.5, 1.5);
      double best = std::numeric_limits<double>::infinity();
      for (const auto& s : segs) best = std::min(best, (p - closest_point_on_segment(p, s[0], s[1])).squaredNorm());
      const NearestHit h = bvh.nearest(p);
      ASSERT_EQ(h.distance_sq, best);
      ASSERT_EQ(bvh.nearest(p, static_cast<Index>(g() % segs.size())).distance_sq, best);
      const auto& s = segs[h.primitive];
      EXPECT_EQ((p - closest_point_on_segment(p, s[0], s[1])).squaredNorm(), best);
    }
  }
}

TEST(BvhBuild, TreeInvariants) {
  std::mt19937_64 g(31);
  const auto tris = random_soup(g, 2000, 0.1);
  std::vector<Vec3> lo, hi, ce;
  for (const auto& t : tris) {
    lo.push_back(t[0].cwiseMin(t[1]).cwiseMin(t[2]));
    hi.push_back(t[0].cwiseMax(t[1]).cwiseMax(t[2]));
    ce.push_back(0.5 * (lo.back() + hi.back()));
  }
  for (Index leaf : {1u, 4u, 8u}) {
    Bvh bvh;
    bvh.build(lo, hi, ce, {leaf, 16});
    // Every primitive appears exactly once.
    std::vector<int> seen(tris.size(), 0);
    for (Index id : bvh.order()) ++seen[id];
    for (int s : seen) ASSERT_EQ(s, 1);
    // Leaves hold <= leaf primitives inside their box; children lie inside their parent.
    std::size_t covered = 0;
    for (const BvhNode& n : bvh.nodes()) {
      if (n.count > 0) {
        EXPECT_LE(n.count, leaf);
        covered += n.count;
        for (Index i = n.first; i < n.first + n.count; ++i) {
          const Index id = bvh.order()[i];
          EXPECT_TRUE((lo[id].array() >= n.lo.array()).all() && (hi[id].array() <= n.hi.array()).all());
        }
      } else {
        for (Index c : {n.first, n.first + 1}) {
          const BvhNode& ch = bvh.nodes()[c];
          EXPECT_TRUE((ch.lo.array() >= n.lo.array()).all() && (ch.hi.array() <= n.hi.array()).all());
        }
      }
    }
    EXPECT_EQ(covered, tris.size());
    EXPECT_LE(bvh.depth(), 64u);
  }
}

}  // namespace
}  // namespace quadlod
