// quadlod — HausdorffToInput (src/pipeline/lod_distance.h).
#include "pipeline/lod_distance.h"

#include "eval/metrics_common.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

namespace quadlod::lod_detail {

namespace {


/// Interleaves the low 21 bits of x with two zero bits between each (Morton code, one axis).
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

/// The samples plus the vertices used by a face, as evaluate() queries them, in Morton order:
/// consecutive queries are close, so each one's answer is a good hint for the next (the
/// distances, and so the maximum, do not depend on the order).
std::vector<Vec3> query_points(const PolyMesh& m, const SurfaceSamples& samples) {
  std::vector<Vec3> points = samples.points;
  std::vector<char> used(m.num_vertices(), 0);
  for (Index v : m.corner_vertex) used[v] = 1;
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (used[v]) points.push_back(m.positions[v]);
  BoundingBox box;
  for (const Vec3& p : points) box.extend(p);
  const Vec3 extent = box.extent();
  std::vector<std::pair<std::uint64_t, Index>> keyed(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double t = extent[k] > 0 ? (points[i][k] - box.min[k]) / extent[k] : 0.0;
      code |= spread_bits(static_cast<std::uint64_t>(std::clamp(t, 0.0, 1.0) * 2097151.0)) << k;
    }
    keyed[i] = {code, static_cast<Index>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<Vec3> ordered(points.size());
  for (std::size_t i = 0; i < keyed.size(); ++i) ordered[i] = points[keyed[i].second];
  return ordered;
}

double largest_distance(const std::vector<Vec3>& points, const TriangleBvh& target) {
  double worst = 0.0;
  Index hint = kInvalidIndex;
  for (const Vec3& p : points) {
    const NearestHit h = target.nearest(p, hint);
    hint = h.primitive;
    worst = std::max(worst, h.distance_sq);
  }
  return std::sqrt(worst);
}

}  // namespace

HausdorffToInput::HausdorffToInput(const PolyMesh& input, std::uint64_t samples, std::uint64_t seed)
    : samples_(samples), seed_(seed) {
  const BoundingBox box = bounding_box(input);
  const double side = box.longest_side();
  if (!(side > 0.0)) return;
  scale_ = 1.0 / side;
  centre_ = 0.5 * (box.min + box.max);
  const PolyMesh in = eval_detail::scaled_copy(input, centre_, scale_);
  const TriangleSoup soup = fan_triangulate(in);
  const SurfaceSamples s = sample_triangles(soup, samples_, seed_, 0);
  if (!(s.total_area > 0.0)) return;
  points_ = query_points(in, s);
  bvh_ = TriangleBvh(soup.triangles);
  ok_ = true;
}

double HausdorffToInput::measure(const PolyMesh& level) const {
  if (!ok_) return std::numeric_limits<double>::quiet_NaN();
  const PolyMesh out = eval_detail::scaled_copy(level, centre_, scale_);
  const TriangleSoup soup = fan_triangulate(out);
  const SurfaceSamples s = sample_triangles(soup, samples_, seed_, 1);
  if (!(s.total_area > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  // The two directions are independent: the level's queries run on a second thread while its
  // BVH answers the input's.
  double from_level = 0.0;
  std::thread level_side([&] { from_level = largest_distance(query_points(out, s), bvh_); });
  const TriangleBvh bvh(soup.triangles);
  const double from_input = largest_distance(points_, bvh);
  level_side.join();
  return std::max(from_input, from_level);
}

}  // namespace quadlod::lod_detail
