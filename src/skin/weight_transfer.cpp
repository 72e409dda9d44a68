// Skin weights by projection onto a skinned surface (issue 24; include/quadlod/skin.h,
// docs/skinning.md "Why projection").
//
//   target vertex p ──closest point──► q on source triangle (a, b, c), q = αa + βb + γc
//   w(p) = canonical(α w(a) + β w(b) + γ w(c))        (≤ the source's influence count, sum 1)
//
// The closest triangle is looked for first among those facing p's way (source face normal within
// max_normal_angle_deg of p's area-weighted normal): two surfaces close to each other (a leg
// against the belly, upper and lower lip) usually face apart, and a vertex must follow the bones
// of its own surface.
#include "quadlod/skin.h"

#include "geometry/bvh.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace quadlod {

namespace {

// Barycentric coordinates of q (on or near triangle a, b, c), clamped into the triangle; for a
// degenerate triangle, all weight on the nearest corner.
Vec3 barycentric(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e0 = b - a, e1 = c - a, d = q - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double d20 = d.dot(e0), d21 = d.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 1e-300) || den < 1e-14 * d00 * d11) {
    const double da = (q - a).squaredNorm(), db = (q - b).squaredNorm(), dc = (q - c).squaredNorm();
    if (da <= db && da <= dc) return Vec3(1, 0, 0);
    return db <= dc ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
  }
  double v = (d11 * d20 - d01 * d21) / den;
  double w = (d00 * d21 - d01 * d20) / den;
  v = std::max(0.0, v);
  w = std::max(0.0, w);
  double u = std::max(0.0, 1.0 - v - w);
  const double s = u + v + w;
  return Vec3(u, v, w) / s;
}

}  // namespace

SkinTransferResult transfer_skin_weights(const PolyMesh& source, const PolyMesh& target,
                                         const SkinTransferParams& params) {
  SkinTransferResult result;
  // Fan triangles of the source, each remembering its corners and its polygon's normal.
  std::vector<std::array<Vec3, 3>> triangles;
  std::vector<std::array<Index, 3>> corners;
  std::vector<Vec3> normals;
  for (Index f = 0; f < source.num_faces(); ++f) {
    const auto vs = source.face_vertices(f);
    const Vec3 n = face_normal(source, f);
    for (std::size_t i = 1; i + 1 < vs.size(); ++i) {
      triangles.push_back({source.positions[vs[0]], source.positions[vs[i]], source.positions[vs[i + 1]]});
      corners.push_back({vs[0], vs[i], vs[i + 1]});
      normals.push_back(n);
    }
  }
  const TriangleBvh bvh(triangles);
  const Index max_influences = params.max_influences > 0 ? params.max_influences : source.skin.max_influences();

  // Area-weighted vertex normals of the target.
  std::vector<Vec3> vertex_normal(target.num_vertices(), Vec3::Zero());
  for (Index f = 0; f < target.num_faces(); ++f) {
    const Vec3 area = face_area_vector(target, f);
    for (Index v : target.face_vertices(f)) vertex_normal[v] += area;
  }
  const double cos_limit = std::cos(params.max_normal_angle_deg * std::numbers::pi / 180.0);
  const double side_limit = params.max_side_distance * bounding_box(source).diagonal();

  std::vector<std::vector<Influence>> per_vertex(target.num_vertices());
  double sum_distance = 0.0;
  Index hint = kInvalidIndex;
  for (Index v = 0; v < target.num_vertices(); ++v) {
    const Vec3& p = target.positions[v];
    const double len = vertex_normal[v].norm();
    NearestHit hit;
    if (len > 0.0) {
      const Vec3 n = vertex_normal[v] / len;
      hit = bvh.nearest_if(p, [&](Index t) { return normals[t].dot(n) > cos_limit; }, hint, side_limit * side_limit);
    }
    if (hit.primitive == kInvalidIndex) {
      hit = bvh.nearest(p, hint);
      ++result.nearest_only;
    } else {
      ++result.same_side;
    }
    if (hit.primitive == kInvalidIndex) continue;  // empty source: no weights
    hint = hit.primitive;
    const auto& c = corners[hit.primitive];
    const auto& t = triangles[hit.primitive];
    const Vec3 bary = barycentric(hit.point, t[0], t[1], t[2]);
    std::vector<Influence> blend;
    for (int k = 0; k < 3; ++k)
      if (bary[k] > 0.0)
        for (const Influence& i : influences_of(source.skin, c[k])) blend.push_back({i.joint, bary[k] * i.weight});
    per_vertex[v] = std::move(blend);
    const double d = std::sqrt(hit.distance_sq);
    result.max_distance = std::max(result.max_distance, d);
    sum_distance += d;
  }
  result.mean_distance = target.num_vertices() ? sum_distance / target.num_vertices() : 0.0;
  result.skin = make_skin_weights(per_vertex, max_influences, params.min_weight);
  return result;
}

}  // namespace quadlod
