// Directed Hausdorff by branch and bound: see hausdorff_bound.h. The same idea as Metro's
// subdivision sampling (Cignoni et al. 1998) with the Lipschitz bound of Tang et al. 2009 making it
// a bracket instead of an estimate.
#include "eval/hausdorff_bound.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace quadlod::eval_detail {

namespace {

struct Piece {
  std::array<Vec3, 3> corner;
  std::array<double, 3> dist;
  std::array<Index, 3> nearest;  ///< nearest triangle of `to` of each corner
  double upper = 0.0;
};

/// Largest distance of a point of the triangle from its nearest corner, bounded from above.
double corner_radius(const std::array<Vec3, 3>& c) {
  const double ab = (c[1] - c[0]).norm(), bc = (c[2] - c[1]).norm(), ca = (c[0] - c[2]).norm();
  // Acute: the circumradius ≤ longest / √3 (largest angle ≥ 60°); right or obtuse: ≤ longest / 2.
  const double by_edge = std::max({ab, bc, ca}) / std::sqrt(3.0);
  // From corner i every point is within the farther of its two edges (the distance from a
  // point of a triangle is largest at a corner).
  const double by_corner = std::min({std::max(ab, ca), std::max(ab, bc), std::max(bc, ca)});
  return std::min(by_edge, by_corner);
}

/// The smaller of two bounds: the Lipschitz one, and for each corner's nearest triangle T the
/// farthest corner from T — the distance to one triangle is convex, so on the piece it is
/// largest at a corner, and the distance to the whole set is at most it. The second closes at
/// once a piece that lies over one triangle of `to` (a plateau of distance along a flat face,
/// where the Lipschitz bound alone would subdivide down to the tolerance).
double piece_upper(const Piece& p, const std::vector<TriangleFrame>& to) {
  double upper = std::max({p.dist[0], p.dist[1], p.dist[2]}) + corner_radius(p.corner);
  for (int k = 0; k < 3; ++k) {
    const Index t = p.nearest[k];
    if (t >= to.size() || (k > 0 && t == p.nearest[0]) || (k > 1 && t == p.nearest[1])) continue;
    double far = p.dist[k];
    for (int i = 0; i < 3 && far < upper; ++i)
      if (i != k) far = std::max(far, std::sqrt(closest_point_on_triangle(to[t], p.corner[i]).distance_sq));
    upper = std::min(upper, far);
  }
  return upper;
}

struct ByUpper {
  bool operator()(const Piece& a, const Piece& b) const { return a.upper < b.upper; }
};

}  // namespace

HausdorffBound directed_hausdorff_bound(const std::vector<std::array<Vec3, 3>>& from, const TriangleBvh& to,
                                        const std::vector<std::array<Vec3, 3>>& to_triangles,
                                        const HausdorffBoundParams& params) {
  HausdorffBound r;
  if (from.empty()) {
    r.converged = true;
    return r;
  }
  std::vector<TriangleFrame> frames(to_triangles.size());
  for (std::size_t t = 0; t < to_triangles.size(); ++t)
    frames[t] = make_triangle_frame(to_triangles[t][0], to_triangles[t][1], to_triangles[t][2]);
  auto query = [&](const Vec3& p, Index& hint) {
    const NearestHit h = to.nearest(p, hint);
    hint = h.primitive;
    ++r.queries;
    const double d = std::sqrt(h.distance_sq);
    if (d > r.lower) {
      r.lower = d;
      r.at = p;
    }
    return d;
  };
  std::vector<Piece> start;
  start.reserve(from.size());
  Index hint = kInvalidIndex;
  for (const auto& t : from) {
    Piece p;
    p.corner = t;
    for (int k = 0; k < 3; ++k) {
      p.dist[k] = query(t[k], hint);
      p.nearest[k] = hint;
    }
    p.upper = piece_upper(p, frames);
    start.push_back(p);
  }
  std::priority_queue<Piece, std::vector<Piece>, ByUpper> open;
  double pruned = 0.0;  // largest bound of a piece dropped as within tolerance of the lower bound
  auto keep = [&](const Piece& p) {
    if (p.upper > r.lower + params.tolerance) open.push(p);
    else pruned = std::max(pruned, p.upper);
  };
  for (const Piece& p : start) keep(p);
  start.clear();
  start.shrink_to_fit();
  while (!open.empty() && open.top().upper > r.lower + params.tolerance && r.queries < params.max_queries) {
    const Piece p = open.top();
    open.pop();
    // Midpoints m01, m12, m20 and the four children (corner triangles and the middle one).
    const std::array<Vec3, 3> m = {0.5 * (p.corner[0] + p.corner[1]), 0.5 * (p.corner[1] + p.corner[2]),
                                   0.5 * (p.corner[2] + p.corner[0])};
    std::array<double, 3> dm;
    std::array<Index, 3> nm;
    Index h = p.nearest[0];
    for (int k = 0; k < 3; ++k) {
      dm[k] = query(m[k], h);
      nm[k] = h;
    }
    const Piece children[4] = {
        {{p.corner[0], m[0], m[2]}, {p.dist[0], dm[0], dm[2]}, {p.nearest[0], nm[0], nm[2]}, 0.0},
        {{m[0], p.corner[1], m[1]}, {dm[0], p.dist[1], dm[1]}, {nm[0], p.nearest[1], nm[1]}, 0.0},
        {{m[2], m[1], p.corner[2]}, {dm[2], dm[1], p.dist[2]}, {nm[2], nm[1], p.nearest[2]}, 0.0},
        {{m[0], m[1], m[2]}, {dm[0], dm[1], dm[2]}, {nm[0], nm[1], nm[2]}, 0.0},
    };
    for (Piece c : children) {
      c.upper = piece_upper(c, frames);
      keep(c);
    }
  }
  r.upper = std::max(r.lower, pruned);
  if (!open.empty()) r.upper = std::max(r.upper, open.top().upper);
  r.converged = r.upper - r.lower <= params.tolerance;
  return r;
}

}  // namespace quadlod::eval_detail
