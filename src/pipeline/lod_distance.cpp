// quadlod — HausdorffToInput (src/pipeline/lod_distance.h).
#include "pipeline/lod_distance.h"

#include <cmath>
#include <limits>

namespace quadlod::lod_detail {

namespace {

/// evaluate()'s normalisation, operation for operation: p ↦ (p − c) · s.
PolyMesh scaled(const PolyMesh& m, const Vec3& centre, double s) {
  PolyMesh out;
  out.positions.resize(m.positions.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) out.positions[i] = (m.positions[i] - centre) * s;
  out.face_offsets = m.face_offsets;
  out.corner_vertex = m.corner_vertex;
  return out;
}

/// The samples plus the vertices used by a face (increasing id), as evaluate() queries them.
std::vector<Vec3> query_points(const PolyMesh& m, const SurfaceSamples& samples) {
  std::vector<Vec3> points = samples.points;
  std::vector<char> used(m.num_vertices(), 0);
  for (Index v : m.corner_vertex) used[v] = 1;
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (used[v]) points.push_back(m.positions[v]);
  return points;
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
  const PolyMesh in = scaled(input, centre_, scale_);
  const TriangleSoup soup = fan_triangulate(in);
  const SurfaceSamples s = sample_triangles(soup, samples_, seed_, 0);
  if (!(s.total_area > 0.0)) return;
  points_ = query_points(in, s);
  bvh_ = TriangleBvh(soup.triangles);
  ok_ = true;
}

double HausdorffToInput::measure(const PolyMesh& level) const {
  if (!ok_) return std::numeric_limits<double>::quiet_NaN();
  const PolyMesh out = scaled(level, centre_, scale_);
  const TriangleSoup soup = fan_triangulate(out);
  const SurfaceSamples s = sample_triangles(soup, samples_, seed_, 1);
  if (!(s.total_area > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const TriangleBvh bvh(soup.triangles);
  return std::max(largest_distance(points_, bvh), largest_distance(query_points(out, s), bvh_));
}

}  // namespace quadlod::lod_detail
