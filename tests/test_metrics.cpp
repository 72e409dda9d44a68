// Tests of `quadlod eval` (include/quadlod/metrics.h, docs/metrics.md) and of the deterministic
// samplers (src/geometry/sampling.h): closed forms, oracles and determinism.
#include "quadlod/metrics.h"

#include "geometry/bvh.h"
#include "geometry/sampling.h"
#include "feature_test_util.h"
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <vector>

namespace quadlod {
namespace {

// Small sample counts keep the sanitizer build fast; closed-form tolerances below are derived
// from these counts.
EvalParams small_params(std::uint64_t samples = 4000, std::uint64_t curve_samples = 4000) {
  EvalParams p;
  p.samples = samples;
  p.curve_samples = curve_samples;
  return p;
}

PolyMesh transformed(PolyMesh m, double scale, const Vec3& about, const Vec3& shift = Vec3::Zero()) {
  for (Vec3& p : m.positions) p = about + scale * (p - about) + shift;
  return m;
}

/// Every face fanned from its corner 0 (the same triangles the metrics measure).
PolyMesh fan_triangulated(const PolyMesh& m) {
  PolyMesh out;
  out.positions = m.positions;
  for (Index f = 0; f < m.num_faces(); ++f) {
    const auto v = m.face_vertices(f);
    for (std::size_t i = 1; i + 1 < v.size(); ++i) out.add_face({v[0], v[i], v[i + 1]});
  }
  return out;
}

// --- generators and samplers -------------------------------------------------------------------

TEST(EvalSampling, Splitmix64KnownAnswers) {
  std::uint64_t s = 0;
  EXPECT_EQ(splitmix64(s), 0xE220A8397B1DCDAFULL);
  EXPECT_EQ(splitmix64(s), 0x6E789E6AA1B965F4ULL);
  EXPECT_EQ(splitmix64(s), 0x06C45D188009454FULL);
}

TEST(EvalSampling, Xoshiro256KnownAnswers) {
  // Reference output of xoshiro256** 1.0 for state {1, 2, 3, 4}.
  Xoshiro256 g = Xoshiro256::from_state({1, 2, 3, 4});
  EXPECT_EQ(g.next(), 11520ULL);
  EXPECT_EQ(g.next(), 0ULL);
  EXPECT_EQ(g.next(), 1509978240ULL);
  EXPECT_EQ(g.next(), 1215971899390074240ULL);
  // Seeding through splitmix64 (values from an independent Python implementation).
  Xoshiro256 a(1, 0), b(1, 1), c(42, 0);
  EXPECT_EQ(a.next(), 0xB3F2AF6D0FC710C5ULL);
  EXPECT_EQ(b.next(), 0xBAA24E21D05C2935ULL);
  EXPECT_EQ(c.next(), 0x15780B2E0C2EC716ULL);
  EXPECT_EQ(a.uniform01(), 0.5204366199388569);
  EXPECT_EQ(b.uniform01(), 0.10028392203766334);
}

TEST(EvalSampling, SurfaceSamplesLieOnTheirTrianglesAndFollowArea) {
  PolyMesh m = make_demo_vase(16, 10);
  // A zero-area face (collinear corners) must never receive a sample.
  const Index a = m.add_vertex({5, 5, 5}), b = m.add_vertex({6, 5, 5}), c = m.add_vertex({7, 5, 5});
  m.add_face({a, b, c});
  const TriangleSoup soup = fan_triangulate(m);
  const std::uint64_t n = 50000;
  const SurfaceSamples s = sample_triangles(soup, n, 3, 0);
  ASSERT_EQ(s.points.size(), n);
  std::vector<double> hits(soup.triangles.size(), 0.0);
  for (std::uint64_t k = 0; k < n; ++k) {
    const auto& t = soup.triangles[s.triangle[k]];
    EXPECT_LE((closest_point_on_triangle(s.points[k], t[0], t[1], t[2]).point - s.points[k]).norm(), 1e-14);
    hits[s.triangle[k]] += 1;
  }
  EXPECT_EQ(hits.back(), 0.0);
  // Per-face counts follow the area share: binomial, |count − n·p| <= 5·sqrt(n·p(1−p)) + 1.
  double total = 0;
  for (const auto& t : soup.triangles) total += triangle_area(t);
  EXPECT_DOUBLE_EQ(total, s.total_area);
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    const double p = triangle_area(soup.triangles[t]) / total;
    EXPECT_LE(std::abs(hits[t] - n * p), 5 * std::sqrt(n * p * (1 - p)) + 1) << "triangle " << t;
  }
}

TEST(EvalSampling, SameSeedSameSamplesOtherSeedOrStreamOthers) {
  const TriangleSoup soup = fan_triangulate(make_torus(12, 8));
  const SurfaceSamples a = sample_triangles(soup, 1000, 5, 0);
  const SurfaceSamples b = sample_triangles(soup, 1000, 5, 0);
  const SurfaceSamples c = sample_triangles(soup, 1000, 6, 0);
  const SurfaceSamples d = sample_triangles(soup, 1000, 5, 1);
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.triangle, b.triangle);
  int same_c = 0, same_d = 0;
  for (int k = 0; k < 1000; ++k) {
    same_c += a.points[k] == c.points[k];
    same_d += a.points[k] == d.points[k];
  }
  EXPECT_EQ(same_c, 0);
  EXPECT_EQ(same_d, 0);
}

TEST(EvalSampling, ArcLengthSamplesAreEvenlySpaced) {
  // Segments of lengths 1, 0, 3 along the x axis, concatenated: L = 4, 8 samples at 0.25 + k/2.
  const std::vector<std::array<Vec3, 2>> segs = {
      {Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(1, 0, 0), Vec3(1, 0, 0)}, {Vec3(1, 0, 0), Vec3(4, 0, 0)}};
  const CurveSamples s = sample_segments_by_arc_length(segs, 8);
  EXPECT_EQ(s.total_length, 4.0);
  ASSERT_EQ(s.points.size(), 8u);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(s.points[k].x(), 0.25 + 0.5 * k, 1e-15) << k;
  EXPECT_TRUE(sample_segments_by_arc_length({}, 8).points.empty());
  const std::vector<std::array<Vec3, 2>> zero = {{Vec3(1, 2, 3), Vec3(1, 2, 3)}};
  EXPECT_TRUE(sample_segments_by_arc_length(zero, 8).points.empty());
}

// --- QPR ---------------------------------------------------------------------------------------------

FaceCounts counts(std::uint64_t quads, std::uint64_t tris, std::uint64_t ngons = 0) {
  FaceCounts c;
  c.quads = quads;
  c.tris = tris;
  c.ngons = ngons;
  c.faces = quads + tris + ngons;
  return c;
}

TEST(EvalMetrics, QprRuleTable) {
  std::string rule;
  EXPECT_EQ(quad_preservation_ratio(counts(100, 20), counts(40, 10), &rule), (40.0 * 20) / (10 * 100.0));
  EXPECT_EQ(rule, "ratio");
  EXPECT_EQ(quad_preservation_ratio(counts(100, 20), counts(100, 20), &rule), 1.0);
  EXPECT_EQ(rule, "ratio");
  EXPECT_EQ(quad_preservation_ratio(counts(100, 20), counts(0, 250), &rule), 0.0);
  EXPECT_EQ(rule, "no_output_quads");
  EXPECT_EQ(quad_preservation_ratio(counts(100, 0), counts(0, 200), &rule), 0.0);
  EXPECT_EQ(rule, "no_output_quads");
  EXPECT_EQ(quad_preservation_ratio(counts(0, 50), counts(0, 20), &rule), 1.0);
  EXPECT_EQ(rule, "no_input_quads");
  EXPECT_EQ(quad_preservation_ratio(counts(100, 0), counts(30, 10), &rule), 30.0 / 40.0);
  EXPECT_EQ(rule, "input_tri_free");
  EXPECT_EQ(quad_preservation_ratio(counts(100, 0), counts(30, 0, 5), &rule), 1.0);
  EXPECT_EQ(rule, "input_tri_free");
  EXPECT_EQ(quad_preservation_ratio(counts(100, 20), counts(30, 0), &rule), 2.0 * 30 * 20 / 100);
  EXPECT_EQ(rule, "output_tri_free");
  // N-gons do not enter QPR.
  EXPECT_EQ(quad_preservation_ratio(counts(100, 20, 7), counts(40, 10, 99)),
            quad_preservation_ratio(counts(100, 20), counts(40, 10)));
}

TEST(EvalMetrics, QprIsFiniteAndMonotoneInOutputCounts) {
  for (const FaceCounts& in : {counts(0, 0, 3), counts(0, 10), counts(10, 0), counts(10, 10),
                               counts(500, 3), counts(1, 900)}) {
    for (std::uint64_t qo = 0; qo <= 30; ++qo)
      for (std::uint64_t to = 0; to <= 30; ++to) {
        const double v = quad_preservation_ratio(in, counts(qo, to));
        ASSERT_TRUE(std::isfinite(v));
        ASSERT_GE(v, 0.0);
        // More output quads never lowers QPR; more output triangles never raises it.
        ASSERT_LE(v, quad_preservation_ratio(in, counts(qo + 1, to))) << qo << " " << to;
        ASSERT_GE(v, quad_preservation_ratio(in, counts(qo, to + 1))) << qo << " " << to;
      }
    // Against itself: 1.
    EXPECT_EQ(quad_preservation_ratio(in, in), 1.0);
  }
}

// --- whole-evaluation closed forms ----------------------------------------------------------------

void expect_self_evaluation_is_zero(const PolyMesh& m, const char* what) {
  const EvalResult r = evaluate(m, m, small_params());
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_LE(r.chamfer, 1e-12) << what;
  EXPECT_LE(r.chamfer_sq, 1e-24) << what;
  EXPECT_LE(r.hausdorff, 1e-12) << what;
  EXPECT_EQ(r.qpr, 1.0) << what;
  EXPECT_TRUE(r.pccd_defined) << what;
  EXPECT_LE(r.pccd, 1e-12) << what;
  EXPECT_EQ(r.chords_in, r.chords_out);
  EXPECT_EQ(r.quad_fraction_in, r.quad_fraction_out);
  EXPECT_EQ(r.counts_in.tri_equivalent, tri_equivalent_count(m));
}

TEST(EvalMetrics, MeshAgainstItselfIsPerfect) {
  const PolyMesh torus = make_torus(24, 12);
  expect_self_evaluation_is_zero(torus, "torus");
  expect_self_evaluation_is_zero(make_demo_vase(16, 10), "vase");
  expect_self_evaluation_is_zero(make_grid(10, 7), "grid");
  // An all-quad mesh against itself: every output sample's closest input face is its own quad.
  const EvalResult r = evaluate(torus, torus, small_params());
  EXPECT_EQ(r.flow_deviation_deg, 0.0);
  EXPECT_EQ(r.flow_deviation_p90_deg, 0.0);
  EXPECT_EQ(r.flow_coverage, 1.0);
  EXPECT_EQ(r.qpr_rule, "input_tri_free");
  EXPECT_EQ(r.flipped_faces, 0u);
}

TEST(EvalMetrics, ReversedFacesAreCountedAsFlipped) {
  const PolyMesh torus = make_torus(24, 12);
  PolyMesh reversed = torus;
  // Reverse the corner order of every other face.
  std::uint64_t expected = 0;
  for (Index f = 0; f < reversed.num_faces(); f += 2) {
    std::reverse(reversed.corner_vertex.begin() + reversed.face_begin(f),
                 reversed.corner_vertex.begin() + reversed.face_end(f));
    ++expected;
  }
  EXPECT_EQ(evaluate(torus, reversed, small_params()).flipped_faces, expected);
  EXPECT_EQ(evaluate(torus, torus, small_params()).flipped_faces, 0u);
}

// Two interpenetrating quads from makehuman_teeth_base (input faces 2162 and 2720, vertex
// coordinates copied as numbers): the centroid of the first lies 0.0014 (normalised) from the
// second, which faces the other way, and 0.0597 from the first's own fan triangles, which fold
// away from its Newell normal. The input is like that; an output that keeps the face unchanged
// replaced nothing and counts it in flipped_faces_kept, an output that moved it counts it flipped.
TEST(EvalMetrics, InputFacesThatTheRuleFlagsAreCountedApartWhenKept) {
  PolyMesh m;
  m.positions = {{0.1553, 6.2913, 1.0111}, {0.1454, 6.2888, 1.0137}, {0.1542, 6.2776, 1.0364},
                 {0.1569, 6.2871, 1.0324}, {0.1592, 6.2843, 1.0314}, {0.1504, 6.2892, 1.0370},
                 {0.1468, 6.2880, 1.0185}, {0.1567, 6.2857, 1.0153}};
  m.add_face({0, 1, 2, 3});
  m.add_face({4, 5, 6, 7});
  const EvalResult self = evaluate(m, m, small_params());
  EXPECT_EQ(self.flipped_faces, 0u);
  EXPECT_EQ(self.flipped_faces_kept, 1u);

  PolyMesh moved = m;
  moved.positions[0].x() += 1e-5;  // no longer the input face
  const EvalResult r = evaluate(m, moved, small_params());
  EXPECT_EQ(r.flipped_faces, 1u);
  EXPECT_EQ(r.flipped_faces_kept, 0u);

  // A rotated corner order is the same face.
  PolyMesh rotated;
  rotated.positions = m.positions;
  rotated.add_face({2, 3, 0, 1});
  rotated.add_face({4, 5, 6, 7});
  EXPECT_EQ(evaluate(m, rotated, small_params()).flipped_faces_kept, 1u);
}

// ∫₀¹∫₀¹ sqrt(1 + s² + t²) ds dt: inner integral in closed form, outer by composite Simpson.
double unit_square_mean_of_sqrt_1_s2_t2() {
  auto inner = [](double s) {  // ∫₀¹ sqrt(c² + t²) dt, c² = 1 + s²
    const double c2 = 1 + s * s, c = std::sqrt(c2);
    return 0.5 * (std::sqrt(c2 + 1) + c2 * std::asinh(1 / c));
  };
  const int n = 20000;
  double sum = inner(0) + inner(1);
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * inner(double(i) / n);
  return sum / (3.0 * n);
}

// Unit cube [-½,½]³ against the same cube scaled 1.1 about its centre, h = 0.05:
//   in → out: every inner point is exactly h from the outer box (it is inside, and the nearest
//     outer face plane is h away), vertices included: mean = max = h.
//   out → in: an outer point at (0.55, u, v) is sqrt(h² + f(u)² + f(v)²) from the inner box,
//     f(t) = max(|t| − ½, 0). Per 1.1 × 1.1 face: area 1 at distance h, area 0.2 (edge strips)
//     with mean h·K1, area 0.01 (corner squares) with mean h·K2, where
//     K1 = ∫₀¹ sqrt(1 + t²) dt = ½(√2 + asinh 1),  K2 = ∫₀¹∫₀¹ sqrt(1 + s² + t²).
//     E[d] = h(1 + 0.2 K1 + 0.01 K2) / 1.21,   E[d²] = h²(1 + 0.2·4/3 + 0.01·5/3) / 1.21.
//     The maximum is at the outer corners (vertex samples): h√3.
struct CubeClosedForm {
  double h = 0.05;
  double mean_out, mean_sq_out, sd_out, sd_sq_out;
  CubeClosedForm() {
    const double k1 = 0.5 * (std::sqrt(2.0) + std::asinh(1.0));
    const double k2 = unit_square_mean_of_sqrt_1_s2_t2();
    mean_out = h * (1 + 0.2 * k1 + 0.01 * k2) / 1.21;
    mean_sq_out = h * h * (1 + 0.2 * 4.0 / 3 + 0.01 * 5.0 / 3) / 1.21;
    sd_out = std::sqrt(mean_sq_out - mean_out * mean_out);
    sd_sq_out = h * h;  // d² ∈ [h², 3h²]: sd <= half the range
  }
};

void expect_cube_closed_form(const EvalResult& r, std::uint64_t n) {
  const CubeClosedForm cf;
  const double h = cf.h;
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_NEAR(r.mean_in_to_out, h, 1e-12);
  EXPECT_NEAR(r.hausdorff_in_to_out, h, 1e-12);
  EXPECT_NEAR(r.hausdorff_out_to_in, h * std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(r.hausdorff, h * std::sqrt(3.0), 1e-12);
  // Deterministic bounds: every out→in distance is in [h, h√3].
  EXPECT_GE(r.mean_out_to_in, h - 1e-12);
  EXPECT_LE(r.mean_out_to_in, h * std::sqrt(3.0));
  // Monte Carlo: within 5 standard errors of the closed form (a fixed seed: no flakiness).
  const double se = cf.sd_out / std::sqrt(double(n));
  EXPECT_NEAR(r.mean_out_to_in, cf.mean_out, 5 * se);
  EXPECT_NEAR(r.chamfer, 0.5 * (h + cf.mean_out), 2.5 * se + 1e-12);
  EXPECT_NEAR(r.chamfer_sq, 0.5 * (h * h + cf.mean_sq_out), 2.5 * cf.sd_sq_out / std::sqrt(double(n)));
}

TEST(EvalMetrics, CubeAgainstScaledCubeClosedForm) {
  const PolyMesh cube = make_cube(3, 1.0);
  const PolyMesh big = transformed(cube, 1.1, Vec3::Zero());
  const EvalParams p = small_params(20000, 1000);
  const EvalResult r = evaluate(cube, big, p);
  EXPECT_EQ(r.scale, 1.0);
  expect_cube_closed_form(r, p.samples);
  // Sanity of the closed form itself: 82.6% of the outer area is at exactly h.
  EXPECT_GT(CubeClosedForm().mean_out, 0.05);
  EXPECT_LT(CubeClosedForm().mean_out, 0.05 * 1.1);
}

TEST(EvalMetrics, NormalisationUsesTheInputBoundingBox) {
  // The same pair, 7× larger and far from the origin: identical metric values.
  const Vec3 far(100, -3, 5);
  const PolyMesh cube = transformed(make_cube(3, 1.0), 7.0, Vec3::Zero(), far);
  const PolyMesh big = transformed(cube, 1.1, far);
  const EvalParams p = small_params(10000, 1000);
  const EvalResult r = evaluate(cube, big, p);
  EXPECT_NEAR(r.scale, 1.0 / 7.0, 1e-15);
  expect_cube_closed_form(r, p.samples);
  // Swapping the roles changes the normalisation to the bigger cube: distances shrink by 1.1.
  const EvalResult s = evaluate(big, cube, p);
  EXPECT_NEAR(s.hausdorff, 0.05 * std::sqrt(3.0) / 1.1, 1e-12);
  EXPECT_NEAR(s.hausdorff_out_to_in, 0.05 / 1.1, 1e-12);
}

TEST(EvalMetrics, QuadMeshAgainstItsFanTriangulation) {
  for (const PolyMesh& m : {make_torus(12, 8), make_grid(9, 5), make_cube(3)}) {
    const PolyMesh tri = fan_triangulated(m);
    const EvalResult r = evaluate(m, tri, small_params(2000, 2000));
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.qpr, 0.0);
    EXPECT_EQ(r.qpr_rule, "no_output_quads");
    EXPECT_EQ(r.quad_fraction_out, 0.0);
    EXPECT_LE(r.chamfer, 1e-12);
    EXPECT_LE(r.hausdorff, 1e-12);
    EXPECT_EQ(r.counts_in.tri_equivalent, r.counts_out.tri_equivalent);
    // No chords on the output side: PCCD falls back to the documented penalty.
    EXPECT_FALSE(r.pccd_defined);
    EXPECT_EQ(r.chords_out, 0u);
    EXPECT_EQ(r.pccd, 1.0);
    // No output quads: flow undefined, coverage 0, JSON null.
    EXPECT_TRUE(std::isnan(r.flow_deviation_deg));
    EXPECT_EQ(r.flow_coverage, 0.0);
    const nlohmann::json j = to_json(r);
    EXPECT_TRUE(j["flow_deviation_deg"].is_null());
    EXPECT_TRUE(j["pccd_in_to_out"].is_null());
    EXPECT_EQ(j["pccd_defined"], false);
    // The other way round: input without chords or quads.
    const EvalResult back = evaluate(tri, m, small_params(2000, 2000));
    EXPECT_EQ(back.qpr, 1.0);
    EXPECT_EQ(back.qpr_rule, "no_input_quads");
    EXPECT_EQ(back.pccd, 1.0);
    EXPECT_FALSE(back.pccd_defined);
    EXPECT_EQ(back.flow_coverage, 0.0);
    // Both sides triangles: nothing to compare, PCCD 0, not defined.
    const EvalResult tt = evaluate(tri, tri, small_params(2000, 2000));
    EXPECT_EQ(tt.pccd, 0.0);
    EXPECT_FALSE(tt.pccd_defined);
  }
}

TEST(EvalMetrics, PccdOfGridShiftedInZIsTheShift) {
  const double delta = 0.0123;
  const PolyMesh grid = make_grid(8, 8);
  const PolyMesh up = transformed(grid, 1.0, Vec3::Zero(), Vec3(0, 0, delta));
  const EvalResult r = evaluate(grid, up, small_params());
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.scale, 1.0);
  EXPECT_TRUE(r.pccd_defined);
  EXPECT_EQ(r.chords_in, 16u);
  EXPECT_NEAR(r.curve_length_in, 16.0, 1e-12);
  EXPECT_NEAR(r.pccd_in_to_out, delta, 1e-12);
  EXPECT_NEAR(r.pccd_out_to_in, delta, 1e-12);
  EXPECT_NEAR(r.pccd, delta, 1e-12);
  // Parallel planes: every surface distance is exactly delta too.
  EXPECT_NEAR(r.chamfer, delta, 1e-12);
  EXPECT_NEAR(r.chamfer_sq, delta * delta, 1e-15);
  EXPECT_NEAR(r.hausdorff, delta, 1e-12);
  EXPECT_EQ(r.flow_deviation_deg, 0.0);
  EXPECT_EQ(r.flow_coverage, 1.0);
}

TEST(EvalMetrics, PccdOfGridAgainstTwiceFinerGrid) {
  // Coarse n×n chords at odd multiples of 1/(2n); fine ones at odd multiples of 1/(4n).
  //   coarse → fine: min(1/(4n), triangle wave in [0, 1/(4n)]) → mean 1/(8n);
  //   fine → coarse: min(1/(4n), triangle wave in [0, 1/(2n)]) → mean 3/(16n).
  // Quadrature bound: the midpoint rule with spacing h = L/N integrates a continuous piecewise-
  // linear function with K kinks of slope jump <= 2 to within K·2h²/8, so the mean is within
  // K·L/(4N²). Coarse side: L = 2n, K = 8n² + 2n; fine side: L = 4n, K = 16n² + 4n (the +
  // are the junctions between concatenated curves, where the value is 1/(4n) on both sides)
  // → both within 20n³/N².
  const Index n = 5;
  const std::uint64_t N = 20000;
  const double bound = 20.0 * n * n * n / (double(N) * double(N));
  const EvalResult r = evaluate(make_grid(n, n), make_grid(2 * n, 2 * n), small_params(2000, N));
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_NEAR(r.pccd_in_to_out, 1.0 / (8 * n), bound);
  EXPECT_NEAR(r.pccd_out_to_in, 3.0 / (16 * n), bound);
  EXPECT_NEAR(r.pccd, 5.0 / (32 * n), bound);
  EXPECT_LE(r.chamfer, 1e-12);  // same plane, same square
}

PolyMesh rotated_about_z(const PolyMesh& m, double degrees, const Vec3& centre) {
  PolyMesh out = m;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(degrees * std::numbers::pi / 180, Vec3::UnitZ()).toRotationMatrix();
  for (Vec3& p : out.positions) p = centre + R * (p - centre);
  return out;
}

TEST(EvalMetrics, FlowDeviationOfRotatedGridIsTheAngle) {
  const PolyMesh grid = make_grid(10, 10);
  const Vec3 centre(0.5, 0.5, 0);
  // Lines are unoriented and the two directions may swap: deviation(α) = min(α, 90° − α) for
  // α in [0°, 90°].
  for (const auto& [angle, expected] : {std::pair{30.0, 30.0}, {60.0, 30.0}, {45.0, 45.0},
                                        {10.0, 10.0}, {90.0, 0.0}, {-20.0, 20.0}}) {
    const EvalResult r = evaluate(grid, rotated_about_z(grid, angle, centre), small_params(2000, 500));
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_NEAR(r.flow_deviation_deg, expected, 1e-9) << angle;
    EXPECT_NEAR(r.flow_deviation_p90_deg, expected, 1e-9) << angle;
    EXPECT_EQ(r.flow_coverage, 1.0) << angle;
  }
}

TEST(EvalMetrics, FlowCoverageIsTheQuadAreaShare) {
  // Left half of a 20×20 grid split into triangles: half the output area is on quads.
  const PolyMesh grid = make_grid(20, 20);
  PolyMesh half;
  half.positions = grid.positions;
  for (Index f = 0; f < grid.num_faces(); ++f) {
    const auto v = grid.face_vertices(f);
    if (face_centroid(grid, f).x() < 0.5) {
      half.add_face({v[0], v[1], v[2]});
      half.add_face({v[0], v[2], v[3]});
    } else {
      half.add_face({v[0], v[1], v[2], v[3]});
    }
  }
  const EvalParams p = small_params();
  const EvalResult r = evaluate(grid, half, p);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_NEAR(r.flow_coverage, 0.5, 5 * 0.5 / std::sqrt(double(p.samples)));
  EXPECT_EQ(r.flow_deviation_deg, 0.0);
  EXPECT_EQ(r.qpr, 200.0 / 600.0);
  EXPECT_EQ(r.qpr_rule, "input_tri_free");
  EXPECT_EQ(r.counts_out.tri_equivalent, 800u);
  EXPECT_LE(r.chamfer, 1e-12);
}

TEST(EvalMetrics, DeterministicForASeedAndIndependentOfThreads) {
  PolyMesh bumpy = make_torus(30, 16);
  for (std::size_t i = 0; i < bumpy.positions.size(); ++i)
    bumpy.positions[i] *= 1.0 + 0.02 * std::sin(7.0 * i);
  const PolyMesh torus = make_torus(30, 16);
  auto strip_times = [](nlohmann::json j) {
    for (const char* k : {"seconds", "seconds_distance", "seconds_pccd", "seconds_features", "threads"}) j.erase(k);
    return j;
  };
  EvalParams p = small_params(3000, 2000);
  p.threads = 1;
  const nlohmann::json one = strip_times(to_json(evaluate(torus, bumpy, p)));
  p.threads = 2;
  const nlohmann::json two = strip_times(to_json(evaluate(torus, bumpy, p)));
  p.threads = 3;
  const nlohmann::json three = strip_times(to_json(evaluate(torus, bumpy, p)));
  EXPECT_EQ(one, two);  // exact double equality of every field
  EXPECT_EQ(one, three);
  EXPECT_EQ(one.dump(17), two.dump(17));
  p.seed = 2;
  const EvalResult other = evaluate(torus, bumpy, p);
  EXPECT_NE(other.chamfer, one["chamfer"].get<double>());
  EXPECT_NE(other.mean_in_to_out, one["mean_in_to_out"].get<double>());
  // Curve samples are not random: PCCD does not depend on the seed.
  EXPECT_EQ(other.pccd, one["pccd"].get<double>());
}

TEST(EvalMetrics, ErrorsAreValues) {
  const PolyMesh grid = make_grid(3, 3);
  PolyMesh empty;
  EXPECT_FALSE(evaluate(grid, empty).ok());
  EXPECT_FALSE(evaluate(empty, grid).ok());
  PolyMesh point;  // zero-size bbox
  for (int i = 0; i < 3; ++i) point.add_vertex(Vec3(1, 1, 1));
  point.add_face({0, 1, 2});
  const EvalResult r = evaluate(point, grid, small_params(100, 100));
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.error.find("bounding box"), std::string::npos) << r.error;
  EXPECT_TRUE(std::isnan(r.chamfer));
  EXPECT_TRUE(to_json(r)["chamfer"].is_null());
  PolyMesh nan = grid;
  nan.positions[2].x() = std::nan("");
  EXPECT_NE(evaluate(grid, nan, small_params(100, 100)).error.find("non-finite"), std::string::npos);
  // Zero-area output (a collinear triangle).
  PolyMesh line;
  line.add_vertex({0, 0, 0});
  line.add_vertex({1, 0, 0});
  line.add_vertex({2, 0, 0});
  line.add_face({0, 1, 2});
  EXPECT_NE(evaluate(grid, line, small_params(100, 100)).error.find("zero surface area"),
            std::string::npos);
  PolyMesh bad = grid;
  bad.corner_vertex[0] = 999;
  EXPECT_NE(evaluate(grid, bad).error.find("output"), std::string::npos);
}

TEST(EvalMetrics, JsonHasEveryMetric) {
  const nlohmann::json j = to_json(evaluate(make_demo_vase(12, 6), make_demo_vase(12, 6), small_params(1000, 1000)));
  for (const char* k : {"chamfer", "chamfer_sq", "hausdorff", "hausdorff_in_to_out", "hausdorff_out_to_in",
                        "qpr", "qpr_rule", "quad_fraction_in", "quad_fraction_out", "pccd", "pccd_defined",
                        "flow_deviation_deg", "flow_deviation_p90_deg", "flow_coverage",
                        "tri_equivalent_in", "tri_equivalent_out", "quads_in", "tris_out", "ngons_out",
                        "uv_stretch_median_in", "uv_stretch_median_out", "uv_stretch_p90_in", "uv_stretch_p90_out",
                        "uv_stretch_skipped_out",
                        "scale", "seed", "samples_in", "seconds"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["ngons_in"], 1);
  EXPECT_EQ(j["tris_in"], 12);
  EXPECT_EQ(j["quads_in"], 72);
  EXPECT_EQ(j["tri_equivalent_in"], 12 + 2 * 72 + 10);
}

// --- features, UVs, materials (docs/metrics.md §6c) ---------------------------------------------------

using feature_test::grid_with_seam_column;
using feature_test::paint_columns;

/// A mesh with its UVs shifted by `delta` on the faces of columns >= split of a make_grid(n, ·).
PolyMesh with_uv_offset(PolyMesh g, Index n, Index split, const Vec2& delta) {
  UvSet& uv = g.uv_sets[0];
  std::vector<char> moved(uv.values.size(), 0);
  for (Index f = 0; f < g.num_faces(); ++f)
    if (f % n >= split)
      for (Index c = g.face_begin(f); c < g.face_end(f); ++c) moved[uv.corner[c]] = 1;
  for (std::size_t k = 0; k < uv.values.size(); ++k)
    if (moved[k]) uv.values[k] += delta;
  return g;
}

TEST(EvalFeatures, MeshAgainstItselfTearsNothing) {
  PolyMesh g = grid_with_seam_column(6, 4, 3, 0.5);
  paint_columns(g, 6, {"red", "green", "blue"}, {0, 0, 1, 1, 2, 2});
  PolyMesh cube = make_cube(2);
  for (const PolyMesh* m : {&g, &cube}) {
    const EvalResult r = evaluate(*m, *m, small_params());
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.seams_torn, 0u);
    EXPECT_EQ(r.uv_islands_in, r.uv_islands_out);
    EXPECT_EQ(r.uv_samples, r.samples_out);
    EXPECT_LE(r.uv_error_max, 1e-14);
    EXPECT_LE(r.feature_deviation_max, 1e-15);
    EXPECT_EQ(r.feature_edges_in, r.feature_edges_out);
  }
  const EvalResult r = evaluate(g, g, small_params());
  EXPECT_EQ(r.uv_islands_in, 2u);
  EXPECT_EQ(r.seam_edges_in, 4u);
  EXPECT_EQ(r.boundary_edges_in, 20u);
  EXPECT_EQ(r.material_border_edges_out, 8u);
  EXPECT_EQ(r.material_border_error, 0.0);
  EXPECT_EQ(r.material_mismatch_fraction, 0.0);
  // make_cube shares one UV lattice between all sides: corners of different sides that meet carry
  // different values except where the lattice happens to agree, so islands are whole sides.
  EXPECT_EQ(evaluate(cube, cube, small_params()).uv_islands_in, 6u);
}

TEST(EvalFeatures, SlitInAGridTearsItsEdges) {
  // Grid 4×4 over [0,1]²; the vertex at (½, ½) is duplicated for the two faces above the row
  // y = ½ between x = ¼ and ¾: the two edges of that row open into a slit of 4 boundary edges.
  const Index n = 4;
  const PolyMesh g = make_grid(n, n);
  PolyMesh slit = g;
  const Index centre = 2 * (n + 1) + 2;
  const Index copy = slit.add_vertex(slit.positions[centre]);
  for (Index f : {Index{2 * n + 1}, Index{2 * n + 2}})  // faces (1, 2) and (2, 2)
    for (Index c = slit.face_begin(f); c < slit.face_end(f); ++c)
      if (slit.corner_vertex[c] == centre) slit.corner_vertex[c] = copy;
  const EvalResult r = evaluate(g, slit, small_params());
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.boundary_edges_out, 16u + 4u);
  EXPECT_EQ(r.seams_torn, 4u);
  EXPECT_EQ(r.uv_islands_out, 1u);
  EXPECT_LE(r.uv_error_max, 1e-14);
  // The slit's sample points nearest the centre, x = ½ ± 1/16, are 7/16 from the boundary.
  EXPECT_NEAR(r.feature_deviation_max, 7.0 / 16.0, 1e-15);
  EXPECT_EQ(evaluate(slit, g, small_params()).seams_torn, 0u);  // closing a slit tears nothing
}

TEST(EvalFeatures, NewSeamThroughAnIslandIsTornAndMergedSeamIsNot) {
  const Index n = 4;
  const PolyMesh plain = make_grid(n, n);
  const PolyMesh seamed = grid_with_seam_column(n, n, 2, 0.5);
  const EvalResult torn = evaluate(plain, seamed, small_params());
  EXPECT_EQ(torn.seams_torn, n);
  EXPECT_EQ(torn.seam_edges_out, n);
  EXPECT_EQ(torn.uv_islands_in, 1u);
  EXPECT_EQ(torn.uv_islands_out, 2u);
  // Both output islands map to the one input island; the right half's UVs are off by ½ in u,
  // over the input island's diagonal √2.
  EXPECT_NEAR(torn.uv_error_max, 0.5 / std::sqrt(2.0), 1e-12);
  const EvalResult merged = evaluate(seamed, plain, small_params());
  EXPECT_EQ(merged.seams_torn, 0u);
  EXPECT_EQ(merged.uv_islands_out, 1u);
  // A seam moved by one column (from x = ½ to x = ¾) is torn; a seam moved by less than
  // feature_tolerance of its edge length is not.
  EXPECT_EQ(evaluate(seamed, grid_with_seam_column(n, n, 3, 0.5), small_params()).seams_torn, n);
  PolyMesh nudged = seamed;
  for (Index j = 0; j <= n; ++j) nudged.positions[j * (n + 1) + 2].x() += 0.1 * 0.25;
  EXPECT_EQ(evaluate(seamed, nudged, small_params()).seams_torn, 0u);
  nudged = seamed;
  for (Index j = 0; j <= n; ++j) nudged.positions[j * (n + 1) + 2].x() += 0.3 * 0.25;
  EXPECT_EQ(evaluate(seamed, nudged, small_params()).seams_torn, n);
}

TEST(EvalFeatures, UvOffsetIsTheOffsetOverTheIslandDiagonal) {
  const Index n = 4;
  const PolyMesh in = grid_with_seam_column(n, n, 2, 0.5);  // islands of UV size ½ × 1
  const Vec2 delta(0.03, 0.04);
  const double expected = 0.05 / std::sqrt(0.25 + 1.0);
  // Both islands moved: every sample is off by exactly |delta| / diagonal.
  const EvalResult both = evaluate(in, with_uv_offset(in, n, 0, delta), small_params());
  EXPECT_NEAR(both.uv_error_mean, expected, 1e-12);
  EXPECT_NEAR(both.uv_error_max, expected, 1e-12);
  // One island moved: half the area (binomial share of the samples) is off by that much.
  const EvalParams p = small_params();
  const EvalResult one = evaluate(in, with_uv_offset(in, n, 2, delta), p);
  EXPECT_NEAR(one.uv_error_max, expected, 1e-12);
  EXPECT_NEAR(one.uv_error_mean, 0.5 * expected, 5 * 0.5 / std::sqrt(double(p.samples)) * expected);
  EXPECT_EQ(one.seams_torn, 0u);
  // No UVs on either side: not measured.
  PolyMesh bare = in;
  bare.uv_sets.clear();
  const EvalResult none = evaluate(in, bare, small_params());
  EXPECT_TRUE(std::isnan(none.uv_error_mean));
  EXPECT_TRUE(to_json(none)["uv_error_max"].is_null());
  EXPECT_EQ(none.uv_islands_out, 0u);
  EXPECT_EQ(none.uv_samples, 0u);
}

/// feature_test::grid_with_face_uvs with shift[i] for the faces of column i: columns with equal
/// shifts form one UV island, the lines between different ones are seams.
PolyMesh grid_with_column_islands(Index n, Index m, const std::vector<double>& shift) {
  return feature_test::grid_with_face_uvs(n, m, [&](Index f) { return shift[f % n]; });
}

/// The faces of `m` for which keep(face) holds, with all of m's vertices and pools.
template <class Keep>
PolyMesh keep_faces(const PolyMesh& m, Keep&& keep) {
  PolyMesh r;
  r.positions = m.positions;
  r.uv_sets.assign(1, UvSet{});
  r.uv_sets[0].values = m.uv_sets[0].values;
  for (Index f = 0; f < m.num_faces(); ++f) {
    if (!keep(f)) continue;
    const Index g = r.add_face(m.face_vertices(f));  // adds the corners' UV slots (unset)
    for (Index i = 0; i < m.face_size(f); ++i) r.uv_sets[0].corner[r.face_begin(g) + i] = m.uv_sets[0].corner[m.face_begin(f) + i];
  }
  return r;
}

/// Gives the corners of column i's faces at x = i/n (their left side) the UV values of the faces
/// of column i − 1 there: the seam between the two columns is stitched shut.
PolyMesh stitch_left_of_column(PolyMesh g, Index n, Index i, double left_shift) {
  UvSet& uv = g.uv_sets[0];
  for (Index f = i; f < g.num_faces(); f += n)
    for (Index c = g.face_begin(f); c < g.face_end(f); ++c) {
      const Vec3& p = g.positions[g.corner_vertex[c]];
      if (std::abs(p.x() - double(i) / double(n)) < 1e-12) uv.values[uv.corner[c]] = Vec2(p.x() + left_shift, p.y());
    }
  return g;
}

/// The island counts of an evaluation: in, out, vanished, merged, split.
void expect_islands(const EvalResult& r, std::uint64_t in, std::uint64_t out, std::uint64_t vanished,
                    std::uint64_t merged, std::uint64_t split) {
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.uv_islands_in, in);
  EXPECT_EQ(r.uv_islands_out, out);
  EXPECT_EQ(r.uv_islands_vanished, vanished);
  EXPECT_EQ(r.uv_islands_merged, merged);
  EXPECT_EQ(r.uv_islands_split, split);
}

// Island correspondence (uv_islands_vanished / _merged / _split) on known cases: a 6×2 grid
// whose column pairs are three islands A | B | C (UV shifts 0, 3, 6).
// Sander et al.'s L2 stretch, normalised (issue 32's "report the UV stretch"): make_grid's UVs are
// the unit lattice, so a square grid of any size is a map without stretch (1), and a 1 × 2 grid
// has S_s = (1, 0, 0), S_t = (0, 2, 0): √((1 + 4) / 2) · √(UV area 1 / area 2) = √1.25.
TEST(EvalFeatures, UvStretchKnownAnswers) {
  const PolyMesh square = make_grid(4, 4, 3.0, 3.0), tall = make_grid(4, 4, 1.0, 2.0);
  const EvalResult r = evaluate(square, tall, small_params());
  EXPECT_NEAR(r.uv_stretch_median_in, 1.0, 1e-12);
  EXPECT_NEAR(r.uv_stretch_p90_in, 1.0, 1e-12);
  EXPECT_NEAR(r.uv_stretch_median_out, std::sqrt(1.25), 1e-12);
  EXPECT_NEAR(r.uv_stretch_p90_out, std::sqrt(1.25), 1e-12);
  EXPECT_EQ(r.uv_stretch_skipped_out, 0u);
  // A face whose UVs collapse to a point has no UV area: left out and counted (2 fan triangles).
  PolyMesh pinched = square;
  for (Index c = pinched.face_begin(0); c < pinched.face_end(0); ++c)
    pinched.uv_sets[0].corner[c] = pinched.uv_sets[0].corner[pinched.face_begin(0)];
  const EvalResult q = evaluate(square, pinched, small_params());
  EXPECT_NEAR(q.uv_stretch_median_out, 1.0, 1e-12);
  EXPECT_NEAR(q.uv_stretch_p90_out, 1.0, 1e-12);
  EXPECT_EQ(q.uv_stretch_skipped_out, 2u);
  PolyMesh bare = square;
  bare.uv_sets.clear();
  EXPECT_TRUE(std::isnan(evaluate(square, bare, small_params()).uv_stretch_median_out));
}

TEST(EvalFeatures, IslandsVanishMergeAndSplitKnownAnswers) {
  const Index n = 6, m = 2;
  const PolyMesh in = grid_with_column_islands(n, m, {0, 0, 3, 3, 6, 6});
  expect_islands(evaluate(in, in, small_params()), 3, 3, 0, 0, 0);

  // C's faces removed: C vanished, nothing merged; out = in − vanished.
  expect_islands(evaluate(in, keep_faces(in, [&](Index f) { return f % n < 4; }), small_params()), 3, 2, 1, 0, 0);

  // The seam B | C stitched shut (column 4's left corners take B's UVs): B and C are one output
  // island whose faces lie in, and carry the UVs of, both: one merge, and out = in − vanished − 1
  // shows it. seams_torn cannot: a merge adds no seam.
  const EvalResult joined = evaluate(in, stitch_left_of_column(in, n, 4, 3.0), small_params());
  expect_islands(joined, 3, 2, 0, 1, 0);
  EXPECT_EQ(joined.seams_torn, 0u);

  // B cut in two by a new seam (column 3's UVs moved by 0.1, still nearest B's chart): split,
  // not merged.
  expect_islands(evaluate(in, grid_with_column_islands(n, m, {0, 0, 3, 3.1, 6, 6}), small_params()), 3, 4, 0, 0, 1);
}

// Faces whose UVs span two islands (what an unconstrained collapse makes): input 4×1 grid with
// islands A | B (UV shifts 0 | 3, seam x = ½); output a 3×1 grid whose middle face straddles the
// seam with A's UVs at its left corners and B's at its right ones, so the output is one island.
// Its faces vote A (left face, the middle face's fan triangle at x̄ = 4/9, UV-nearest A) and B:
// one merged island, nothing vanished or split.
TEST(EvalFeatures, FaceAcrossASeamIsAMerge) {
  const PolyMesh in = grid_with_column_islands(4, 1, {0, 0, 3, 3});
  PolyMesh out = grid_with_column_islands(3, 1, {0, 0, 3});
  for (Index c = out.face_begin(1); c < out.face_end(1); ++c) {
    const Vec3& p = out.positions[out.corner_vertex[c]];
    if (p.x() > 0.5) out.uv_sets[0].values[out.uv_sets[0].corner[c]].x() += 3.0;
  }
  const EvalResult r = evaluate(in, out, small_params());
  expect_islands(r, 2, 1, 0, 1, 0);
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j["uv_islands_merged"], 1);
  EXPECT_EQ(j["uv_islands_vanished"], 0);
  EXPECT_EQ(j["uv_islands_split"], 0);
}

/// Flat make_grid(2, 2) sheets at the heights z, stacked: one island each, all with the same UVs
/// (nested eyeball shells, layered hair cards).
PolyMesh stacked_sheets(const std::vector<double>& z) {
  PolyMesh r;
  r.uv_sets.assign(1, UvSet{});
  for (double h : z) {
    const PolyMesh g = make_grid(2, 2);
    const Index v0 = r.num_vertices(), u0 = static_cast<Index>(r.uv_sets[0].values.size());
    for (const Vec3& p : g.positions) r.positions.push_back(p + Vec3(0, 0, h));
    for (const Vec2& uv : g.uv_sets[0].values) r.uv_sets[0].values.push_back(uv);
    for (Index f = 0; f < g.num_faces(); ++f) {
      std::vector<Index> vs;
      for (Index v : g.face_vertices(f)) vs.push_back(v + v0);
      const Index nf = r.add_face(vs);
      for (Index i = 0; i < g.face_size(f); ++i) r.uv_sets[0].corner[r.face_begin(nf) + i] = g.uv_sets[0].corner[g.face_begin(f) + i] + u0;
    }
  }
  return r;
}

// Twin islands: sheets A (z = 0) and B (z = 0.01) with the same UVs. An output with sheets at
// z = 0.001 and 0.004 has both nearest A; the second one's votes also name B (within 2d, same
// UV: a tie), and A comes first for both. A is not split: the second sheet takes B, which fits it
// as well and is nobody's chart. An output with only the sheet at 0.004 keeps one island: B
// vanished, although that sheet's votes name it.
TEST(EvalFeatures, TwinIslandsAreNeitherSplitNorKeptByANameAlone) {
  const PolyMesh in = stacked_sheets({0.0, 0.01});
  expect_islands(evaluate(in, stacked_sheets({0.001, 0.004}), small_params()), 2, 2, 0, 0, 0);
  expect_islands(evaluate(in, stacked_sheets({0.004}), small_params()), 2, 1, 1, 0, 0);
}

/// Appends a strip of quads over [xs[0], xs.back()] × [0, 1] (z = 0) with its own UV values
/// (u = us[i] at x = xs[i], v = y): one island.
void add_strip(PolyMesh& m, const std::vector<double>& xs, const std::vector<double>& us) {
  if (m.uv_sets.empty()) m.uv_sets.assign(1, UvSet{});
  const Index v0 = m.num_vertices(), u0 = static_cast<Index>(m.uv_sets[0].values.size());
  for (std::size_t i = 0; i < xs.size(); ++i)
    for (double y : {0.0, 1.0}) {
      m.positions.push_back(Vec3(xs[i], y, 0.0));
      m.uv_sets[0].values.push_back(Vec2(us[i], y));
    }
  for (Index i = 0; i + 1 < xs.size(); ++i) {
    const std::vector<Index> f = {2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1};
    const Index g = m.add_face({f[0] + v0, f[1] + v0, f[2] + v0, f[3] + v0});
    for (Index k = 0; k < 4; ++k) m.uv_sets[0].corner[m.face_begin(g) + k] = f[k] + u0;
  }
}

// A coarse face over a chart stretched unevenly: input island A = 4 columns over x in [0, 1] whose
// u runs 0, 0.05, 0.1, 0.15, 1 (the last column stretched), and B, one quad over x in [1, 2] with
// u = x − 1/3. The output keeps B and replaces A by one quad with A's corner UVs. At the centroid
// (2/3, 1/3) of its first fan triangle the interpolated u is 2/3, A's is 0.13: off by more than a
// quarter of A's diagonal, and B (u = 2/3 at its closest point) wins the vote. By centroids alone
// the quad's island fits only B, which then has two pieces (a false split) and A none. Its
// corners lie on A with A's UVs: the quad fits A, nothing is merged, split or vanished.
TEST(EvalFeatures, CoarseFaceFitsItsChartAtTheCorners) {
  PolyMesh in;
  add_strip(in, {0, 0.25, 0.5, 0.75, 1}, {0, 0.05, 0.1, 0.15, 1});
  add_strip(in, {1, 2}, {2.0 / 3, 5.0 / 3});
  PolyMesh out;
  add_strip(out, {0, 1}, {0, 1});
  add_strip(out, {1, 2}, {2.0 / 3, 5.0 / 3});
  expect_islands(evaluate(in, out, small_params()), 2, 2, 0, 0, 0);
}

TEST(EvalFeatures, MaterialsAreComparedByName) {
  const Index n = 4;
  PolyMesh in = make_grid(n, n);
  paint_columns(in, n, {"red", "blue"}, {0, 0, 1, 1});
  // Another name table, the same painting: nothing differs.
  PolyMesh renamed = make_grid(n, n);
  paint_columns(renamed, n, {"blue", "red"}, {1, 1, 0, 0});
  EvalResult r = evaluate(in, renamed, small_params());
  EXPECT_EQ(r.material_mismatch_fraction, 0.0);
  EXPECT_EQ(r.material_border_error, 0.0);
  // Swapped: every sample mismatches, the border is where it was (same unordered pair).
  PolyMesh swapped = make_grid(n, n);
  paint_columns(swapped, n, {"red", "blue"}, {1, 1, 0, 0});
  r = evaluate(in, swapped, small_params());
  EXPECT_EQ(r.material_mismatch_fraction, 1.0);
  EXPECT_EQ(r.material_border_error, 0.0);
  EXPECT_EQ(r.material_border_edges_out, n);
  // Column 1 repainted blue: the border moves from x = ½ to x = ¼, a quarter of the area changes.
  PolyMesh moved = make_grid(n, n);
  paint_columns(moved, n, {"red", "blue"}, {0, 1, 1, 1});
  const EvalParams p = small_params();
  r = evaluate(in, moved, p);
  EXPECT_NEAR(r.material_border_error, 0.25, 1e-15);
  EXPECT_NEAR(r.material_border_error_mean, 0.25, 1e-15);
  EXPECT_NEAR(r.material_mismatch_fraction, 0.25, 5 * std::sqrt(0.25 * 0.75 / double(p.samples)));
  // Feature deviation of the moved border (length 1) against boundary ∪ input border: ¼ except
  // for the end edges' quarter points, which are 1/16, 1/8, 3/16 from y = 0 (or y = 1).
  // Length-weighted mean over the boundary (length 4, on the input) and the border:
  // ¼ · (2 · ⅛ + 2 · ¼) / 5 = 0.0375.
  EXPECT_NEAR(r.feature_deviation_max, 0.25, 1e-15);
  EXPECT_NEAR(r.feature_deviation_mean, 0.0375, 1e-15);
  // A border between materials that never met in the input: the missing-feature penalty, 1.
  PolyMesh green = make_grid(n, n);
  paint_columns(green, n, {"red", "blue", "green"}, {0, 0, 1, 2});
  r = evaluate(in, green, small_params());
  EXPECT_EQ(r.material_border_error, 1.0);
  // Without materials on either side: not measured.
  r = evaluate(make_grid(n, n), make_grid(n, n), small_params());
  EXPECT_TRUE(std::isnan(r.material_mismatch_fraction));
  EXPECT_TRUE(std::isnan(r.material_border_error));
}

/// UV at a point of a triangle by solving the 2×2 normal equations (independent of uv_at).
Vec2 oracle_uv(const std::array<Vec3, 3>& t, const std::array<Vec2, 3>& uv, const Vec3& p) {
  Eigen::Matrix<double, 3, 2> a;
  a.col(0) = t[1] - t[0];
  a.col(1) = t[2] - t[0];
  const Eigen::Vector2d w = a.colPivHouseholderQr().solve(p - t[0]);
  return uv[0] + w[0] * (uv[1] - uv[0]) + w[1] * (uv[2] - uv[0]);
}

struct OracleUvError {
  double mean = 0, max = 0;       ///< docs/metrics.md §6c, by brute force over all triangles
  double naive_max = 0;           ///< the same without the self-seam candidates
  std::size_t samples = 0;
};

/// uv_error of docs/metrics.md §6c with every nearest-point search done by brute force: the same
/// normalisation and samples as evaluate(), votes with the coincident-island tie-break, the
/// restricted nearest point and the self-seam candidates within reach.
OracleUvError brute_force_uv_error(const PolyMesh& input, const PolyMesh& output, const EvalParams& params) {
  const BoundingBox box = bounding_box(input);
  const double s = 1.0 / box.longest_side();
  const Vec3 c = 0.5 * (box.min + box.max);
  auto scaled = [&](PolyMesh m) {
    for (Vec3& p : m.positions) p = (p - c) * s;
    return m;
  };
  const PolyMesh in = scaled(input), out = scaled(output);
  const TriangleSoup soup_in = fan_triangulate(in), soup_out = fan_triangulate(out);
  const SurfaceSamples samples = sample_triangles(soup_out, params.samples, params.seed, 1);
  const Connectivity conn_in = build_connectivity(in);
  const UvIslands is_in = find_uv_islands(in, conn_in, 0);
  const UvIslands is_out = find_uv_islands(out, build_connectivity(out), 0);
  const FeatureEdges fe_in = find_feature_edges(in, conn_in);
  std::vector<char> self_seam(in.num_faces(), 0);
  for (Index e = 0; e < conn_in.num_edges; ++e) {
    const auto cs = conn_in.corners_of_edge(e);
    if ((fe_in.edge_uv_seam_sets[e] & 1u) &&
        is_in.face_island[conn_in.corner_face[cs[0]]] == is_in.face_island[conn_in.corner_face[cs[1]]])
      self_seam[conn_in.corner_face[cs[0]]] = self_seam[conn_in.corner_face[cs[1]]] = 1;
  }
  auto tri_uv = [](const PolyMesh& m, const TriangleSoup& soup, std::size_t t) {
    const Index f = soup.face[t];
    Index k = 0;  // position of t in its face's fan
    while (t > k && soup.face[t - k - 1] == f) ++k;
    const UvSet& set = m.uv_sets[0];
    const Index b = m.face_begin(f);
    return std::array<Vec2, 3>{set.values[set.corner[b]], set.values[set.corner[b + k + 1]],
                               set.values[set.corner[b + k + 2]]};
  };
  auto island_of = [&](std::size_t t) {
    return triangle_area(soup_in.triangles[t]) > 0 ? is_in.face_island[soup_in.face[t]] : kInvalidIndex;
  };
  auto closest = [&](const Vec3& p, std::size_t t) {
    const auto& tr = soup_in.triangles[t];
    return closest_point_on_triangle(p, tr[0], tr[1], tr[2]);
  };
  auto uv_in = [&](std::size_t t, const Vec3& q) { return oracle_uv(soup_in.triangles[t], tri_uv(in, soup_in, t), q); };

  const std::size_t n = samples.points.size();
  std::vector<Vec2> uv_out(n);
  std::map<std::pair<Index, Index>, int> votes;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& p = samples.points[k];
    const std::size_t to = samples.triangle[k];
    uv_out[k] = oracle_uv(soup_out.triangles[to], tri_uv(out, soup_out, to), p);
    std::size_t t0 = 0;
    std::vector<double> island_d2(is_in.num_islands, std::numeric_limits<double>::infinity());
    std::vector<std::size_t> island_t(is_in.num_islands);
    for (std::size_t t = 0; t < soup_in.triangles.size(); ++t) {
      const double d2 = closest(p, t).distance_sq;
      if (d2 < closest(p, t0).distance_sq) t0 = t;
      const Index j = island_of(t);
      if (j != kInvalidIndex && d2 < island_d2[j]) {
        island_d2[j] = d2;
        island_t[j] = t;
      }
    }
    const Index j0 = island_of(t0);
    if (j0 == kInvalidIndex) continue;
    const double bound = 2.0 * std::sqrt(closest(p, t0).distance_sq) + 1e-9;
    std::vector<std::pair<double, Index>> near;  // other islands within the bound, nearest first
    for (Index j = 0; j < is_in.num_islands; ++j)
      if (j != j0 && island_d2[j] < bound * bound) near.emplace_back(island_d2[j], j);
    std::sort(near.begin(), near.end());
    near.resize(std::min<std::size_t>(near.size(), 3));
    Index best = j0;
    double best_uv = (uv_in(t0, closest(p, t0).point) - uv_out[k]).squaredNorm();
    for (const auto& [d2, j] : near) {
      const double d_uv = (uv_in(island_t[j], closest(p, island_t[j]).point) - uv_out[k]).squaredNorm();
      if (d_uv < best_uv || (d_uv == best_uv && j < best)) {
        best_uv = d_uv;
        best = j;
      }
    }
    ++votes[{is_out.face_island[soup_out.face[to]], best}];
  }
  std::map<Index, std::pair<int, Index>> target;  // output island → (votes, input island)
  for (const auto& [key, count] : votes)
    if (count > target[key.first].first) target[key.first] = {count, key.second};

  OracleUvError r;
  double sum = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& p = samples.points[k];
    const Index f_out = soup_out.face[samples.triangle[k]];
    const Index j = target[is_out.face_island[f_out]].second;
    std::size_t tj = 0;
    double dj = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < soup_in.triangles.size(); ++t)
      if (island_of(t) == j && closest(p, t).distance_sq < dj) {
        dj = closest(p, t).distance_sq;
        tj = t;
      }
    double e = (uv_out[k] - uv_in(tj, closest(p, tj).point)).norm();
    r.naive_max = std::max(r.naive_max, e / (is_in.uv_max[j] - is_in.uv_min[j]).norm());
    double longest = 0;
    for (Index cc = out.face_begin(f_out); cc < out.face_end(f_out); ++cc)
      longest = std::max(longest, (out.positions[out.corner_vertex[out.next_corner(f_out, cc)]] -
                                   out.positions[out.corner_vertex[cc]]).norm());
    const double reach = std::sqrt(dj) + longest;
    for (std::size_t t = 0; t < soup_in.triangles.size(); ++t)
      if (island_of(t) == j && self_seam[soup_in.face[t]] && closest(p, t).distance_sq <= reach * reach)
        e = std::min(e, (uv_out[k] - uv_in(t, closest(p, t).point)).norm());
    e /= (is_in.uv_max[j] - is_in.uv_min[j]).norm();
    sum += e;
    r.max = std::max(r.max, e);
    ++r.samples;
  }
  r.mean = sum / double(r.samples);
  return r;
}

TEST(EvalFeatures, UvErrorMatchesBruteForceOracle) {
  // Input: a bent 6×6 grid with a seam at x = ½. Output: a bent 4×4 grid (other bend), its own
  // UVs (u = x², v = y) and a seam at x = ½, so output samples near the seam have their
  // unrestricted closest input point on the other island.
  const Index n_in = 6, n_out = 4;
  PolyMesh input = grid_with_seam_column(n_in, n_in, 3, 0.5);
  for (Vec3& p : input.positions) p.z() = 0.2 * std::sin(3.0 * p.x()) * std::cos(2.0 * p.y());
  PolyMesh output = grid_with_seam_column(n_out, n_out, 2, 0.25);
  for (Vec3& p : output.positions) p.z() = 0.25 * std::sin(2.9 * p.x()) * std::cos(2.2 * p.y()) + 0.01;
  for (Vec2& uv : output.uv_sets[0].values) uv.x() = uv.x() * uv.x();
  const EvalParams params = small_params(1500, 500);
  const EvalResult r = evaluate(input, output, params);
  ASSERT_TRUE(r.ok()) << r.error;
  const OracleUvError o = brute_force_uv_error(input, output, params);
  EXPECT_EQ(r.uv_samples, o.samples);
  EXPECT_NEAR(r.uv_error_mean, o.mean, 1e-12);
  EXPECT_NEAR(r.uv_error_max, o.max, 1e-12);
  EXPECT_GT(o.max, 0.05);  // the test measures something
}

TEST(EvalFeatures, SelfSeamSidesAreToldApartByUv) {
  // A cylinder unwrapped with one seam is one island whose two sides meet at the seam (u = 0 and
  // u = 1). The output is the same cylinder turned by half a face (and 2 % wider), so its seam
  // lies half a face past the input's: samples in that strip have their closest input point on
  // the u ≈ 0 side while their own face's chart is the u ≈ 1 side. Their error must be the
  // turn's UV offset, (1/32)/√2 ≈ 0.022, not the island's width (≈ 0.7).
  const Index n = 16, m = 3;
  const PolyMesh input = make_cylinder(n, m, 0.5, 1.0);
  PolyMesh output = make_cylinder(n, m, 0.51, 1.0);
  const double turn = std::numbers::pi / n;
  for (Vec3& p : output.positions)
    p = Vec3(std::cos(turn) * p.x() - std::sin(turn) * p.y(), std::sin(turn) * p.x() + std::cos(turn) * p.y(), p.z());
  const EvalParams params = small_params(1500, 500);
  const EvalResult r = evaluate(input, output, params);
  ASSERT_TRUE(r.ok()) << r.error;
  const OracleUvError o = brute_force_uv_error(input, output, params);
  EXPECT_NEAR(r.uv_error_mean, o.mean, 1e-12);
  EXPECT_NEAR(r.uv_error_max, o.max, 1e-12);
  EXPECT_GT(o.naive_max, 0.5);  // the island restriction alone picks the wrong side
  const double offset = 1.0 / (2.0 * n) / std::sqrt(2.0);
  EXPECT_LT(r.uv_error_max, 1.5 * offset);
  EXPECT_NEAR(r.uv_error_mean, offset, 0.2 * offset);
}

// --- corpus ---------------------------------------------------------------------------------------------

TEST(EvalCorpus, SuzanneAgainstItselfAndItsTriangulation) {
  const auto path = std::filesystem::path(QUADLOD_CORPUS_DIR) / "blender_suzanne.obj";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "corpus not found at " << path;
  const ReadResult rr = read_obj(path);
  ASSERT_TRUE(rr.ok()) << rr.error;
  const EvalResult self = evaluate(rr.mesh, rr.mesh, small_params());
  ASSERT_TRUE(self.ok()) << self.error;
  EXPECT_LE(self.chamfer, 1e-12);
  EXPECT_LE(self.hausdorff, 1e-12);
  EXPECT_LE(self.pccd, 1e-12);
  EXPECT_EQ(self.qpr, 1.0);
  EXPECT_EQ(self.qpr_rule, "ratio");
  EXPECT_EQ(self.counts_in.quads, 468u);
  EXPECT_EQ(self.counts_in.tris, 32u);
  EXPECT_EQ(self.flow_deviation_deg, 0.0);
  EXPECT_EQ(self.uv_islands_in, 5u);
  EXPECT_EQ(self.uv_islands_out, 5u);
  EXPECT_EQ(self.seams_torn, 0u);
  EXPECT_EQ(self.seam_edges_in, 50u);
  EXPECT_EQ(self.boundary_edges_in, 42u);
  EXPECT_LE(self.uv_error_max, 1e-12);
  EXPECT_LE(self.feature_deviation_max, 1e-12);
  const EvalResult tri = evaluate(rr.mesh, fan_triangulated(rr.mesh), small_params());
  EXPECT_EQ(tri.qpr, 0.0);
  EXPECT_LE(tri.hausdorff, 1e-12);
}

// Timing over the whole corpus, each mesh against itself with default parameters. Not part of
// the regular suite: run with
//   quadlod_tests --gtest_also_run_disabled_tests --gtest_filter='EvalCorpus.DISABLED_*'
TEST(EvalCorpus, DISABLED_TimeEveryCorpusMeshAgainstItself) {
  const std::filesystem::path dir(QUADLOD_CORPUS_DIR);
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".obj") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  double total = 0, total_read = 0;
  for (const auto& f : files) {
    const ReadResult rr = read_obj(f);
    ASSERT_TRUE(rr.ok()) << rr.error;
    const EvalResult r = evaluate(rr.mesh, rr.mesh);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_LE(r.chamfer, 1e-9) << f;
    EXPECT_LE(r.pccd, 1e-9) << f;
    std::printf("%-40s %7u faces  read %.2f s  eval %.2f s (dist %.2f, pccd %.2f)  chamfer %.2e  "
                "hausdorff %.2e  pccd %.2e  flow %.3g deg  cover %.3f\n",
                f.filename().c_str(), rr.mesh.num_faces(), rr.seconds, r.seconds,
                r.seconds_distance, r.seconds_pccd, r.chamfer, r.hausdorff, r.pccd,
                r.flow_deviation_deg, r.flow_coverage);
    total += r.seconds;
    total_read += rr.seconds;
  }
  std::printf("total: %zu meshes, read %.2f s, eval %.2f s\n", files.size(), total_read, total);
}

}  // namespace
}  // namespace quadlod
