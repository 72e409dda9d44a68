// BVH build (binned SAH) and exact point–primitive distances.
//
// Papers / references:
//   * C. Ericson, "Real-Time Collision Detection" (2005), §5.1.5 ClosestPtPointTriangle: the
//     Voronoi regions (3 vertices, 3 edges, face) decided below; the decision is made in a
//     per-triangle orthonormal frame instead of by Ericson's dot-product differences, which are
//     unusable on slivers (see TriangleFrame in bvh.h). §5.1.2 for the segment.
//   * I. Wald, "On fast construction of SAH-based bounding volume hierarchies" (2007): binned SAH.
#include "geometry/bvh.h"

#include "util/parallel.h"

#include <algorithm>
#include <cmath>

namespace quadlod {

namespace {
// Below this many primitives the set-up runs on one thread (a thread costs more than it saves).
constexpr std::size_t kMinParallelPrimitives = 20000;
}  // namespace

// --- primitive distances -----------------------------------------------------------------------

Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (!(len2 > 0.0)) return a;
  double t = (p - a).dot(ab) / len2;
  t = std::clamp(t, 0.0, 1.0);
  if (t == 0.0) return a;
  if (t == 1.0) return b;
  return a + t * ab;
}

namespace {

// Region of the rotated triangle (A' B' C') → region of the triangle as given (a b c).
// Vertex k' is original vertex (k' + rotation) mod 3; edge k' (from vertex k') likewise.
TriangleRegion original_vertex(int local, int rotation) {
  constexpr TriangleRegion v[3] = {TriangleRegion::VertexA, TriangleRegion::VertexB, TriangleRegion::VertexC};
  return v[(local + rotation) % 3];
}
TriangleRegion original_edge(int local, int rotation) {
  constexpr TriangleRegion e[3] = {TriangleRegion::EdgeAB, TriangleRegion::EdgeBC, TriangleRegion::EdgeCA};
  return e[(local + rotation) % 3];
}

}  // namespace

TriangleFrame make_triangle_frame(const Vec3& a, const Vec3& b, const Vec3& c) {
  TriangleFrame f;
  const Vec3* v[3] = {&a, &b, &c};
  const double l2[3] = {(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()};
  int r = 0;
  if (l2[1] > l2[r]) r = 1;
  if (l2[2] > l2[r]) r = 2;
  f.rotation = static_cast<std::uint8_t>(r);
  const Vec3& A = *v[r];
  const Vec3& B = *v[(r + 1) % 3];
  const Vec3& C = *v[(r + 2) % 3];
  f.origin = A;
  const Vec3 ab = B - A;
  f.len = ab.norm();
  if (!(f.len > 0.0)) return f;  // all three corners coincide: the triangle is the point A'
  f.e1 = ab / f.len;
  const Vec3 ac = C - A;
  f.cx = ac.dot(f.e1);
  Vec3 w = ac - f.cx * f.e1;
  w -= w.dot(f.e1) * f.e1;  // re-orthogonalise: w is tiny (and its direction noisy) on slivers
  const double wn = w.norm();
  if (wn > 0.0) {
    f.e2 = w / wn;
    f.h = std::max(0.0, ac.dot(f.e2));
    f.n = f.e1.cross(f.e2);
  }
  if (!(f.h > 0.0)) {  // collinear: the triangle is its longest edge A'B' (which contains C')
    f.h = 0.0;
    f.e2 = f.n = Vec3::Zero();
    return f;
  }
  const double lbc2 = (f.cx - f.len) * (f.cx - f.len) + f.h * f.h;
  const double lca2 = f.cx * f.cx + f.h * f.h;
  f.inv_len2_bc = lbc2 > 0.0 ? 1.0 / lbc2 : 0.0;
  f.inv_len2_ca = lca2 > 0.0 ? 1.0 / lca2 : 0.0;
  return f;
}

TrianglePoint closest_point_on_triangle(const TriangleFrame& t, const Vec3& p) {
  const int rot = t.rotation;
  const Vec3 d = p - t.origin;
  if (!(t.len > 0.0)) return {t.origin, d.squaredNorm(), original_vertex(0, rot)};
  const double x = d.dot(t.e1);
  if (t.h == 0.0) {
    // Segment A'B', measured directly in 3D.
    const double u = std::clamp(x / t.len, 0.0, 1.0);
    const Vec3 q = u == 0.0 ? t.origin : Vec3(t.origin + (u * t.len) * t.e1);
    const TriangleRegion region = u == 0.0   ? original_vertex(0, rot)
                                  : u == 1.0 ? original_vertex(1, rot)
                                             : original_edge(0, rot);
    return {q, (p - q).squaredNorm(), region};
  }
  const double y = d.dot(t.e2);
  const double z = d.dot(t.n);
  // Edge functions of the CCW 2D triangle A'(0,0) B'(len,0) C'(cx,h); >= 0 on the inner side.
  // Their terms are products of 2D coordinates, with no cancellation between large quantities.
  const double s_ab = y;
  const double s_bc = (t.cx - t.len) * y - t.h * (x - t.len);
  const double s_ca = t.h * (x - t.cx) - t.cx * (y - t.h);
  if (s_ab >= 0.0 && s_bc >= 0.0 && s_ca >= 0.0)
    return {t.origin + x * t.e1 + y * t.e2, z * z, TriangleRegion::Face};

  // Outside: the closest point lies on an edge whose outer side holds p.
  double best = std::numeric_limits<double>::infinity(), qx = 0.0, qy = 0.0;
  TriangleRegion region = TriangleRegion::Face;
  auto consider = [&](double u, double ax, double ay, double bx, double by, int local_edge) {
    u = std::clamp(u, 0.0, 1.0);
    const double px = u == 1.0 ? bx : ax + u * (bx - ax);
    const double py = u == 1.0 ? by : ay + u * (by - ay);
    const double d2 = (x - px) * (x - px) + (y - py) * (y - py);
    if (d2 < best) {
      best = d2;
      qx = px;
      qy = py;
      region = u == 0.0   ? original_vertex(local_edge, rot)
               : u == 1.0 ? original_vertex((local_edge + 1) % 3, rot)
                          : original_edge(local_edge, rot);
    }
  };
  if (s_ab < 0.0) consider(x / t.len, 0.0, 0.0, t.len, 0.0, 0);
  if (s_bc < 0.0)
    consider(((x - t.len) * (t.cx - t.len) + y * t.h) * t.inv_len2_bc, t.len, 0.0, t.cx, t.h, 1);
  if (s_ca < 0.0) consider(((x - t.cx) * -t.cx + (y - t.h) * -t.h) * t.inv_len2_ca, t.cx, t.h, 0.0, 0.0, 2);
  return {t.origin + qx * t.e1 + qy * t.e2, best + z * z, region};
}

TrianglePoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return closest_point_on_triangle(make_triangle_frame(a, b, c), p);
}

// --- tree build ------------------------------------------------------------------------------------

namespace {

double half_area(const Vec3& lo, const Vec3& hi) {
  const Vec3 e = (hi - lo).cwiseMax(Vec3::Zero());
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

struct Bin {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  Index count = 0;
  void add(const Vec3& l, const Vec3& h) {
    lo = lo.cwiseMin(l);
    hi = hi.cwiseMax(h);
  }
};

}  // namespace

void Bvh::build(std::span<const Vec3> lo, std::span<const Vec3> hi, std::span<const Vec3> centroid,
                const BvhBuildParams& params) {
  nodes_.clear();
  order_.clear();
  depth_ = 0;
  const Index n = static_cast<Index>(lo.size());
  if (n == 0) return;
  const Index max_leaf = std::max<Index>(1, params.max_leaf_size);
  const Index num_bins = std::clamp<Index>(params.sah_bins, 2, 256);

  order_.resize(n);
  for (Index i = 0; i < n; ++i) order_[i] = i;
  nodes_.reserve(2 * static_cast<std::size_t>(n));
  nodes_.push_back({});

  struct Work {
    Index node, begin, end, depth;
  };
  std::vector<Work> work{{0, 0, n, 1}};
  std::vector<Bin> bins(num_bins);
  std::vector<double> right_cost(num_bins, 0.0);

  while (!work.empty()) {
    const Work w = work.back();
    work.pop_back();
    depth_ = std::max(depth_, w.depth);

    Vec3 blo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 bhi = -blo;
    Vec3 clo = blo, chi = bhi;
    for (Index i = w.begin; i < w.end; ++i) {
      const Index id = order_[i];
      blo = blo.cwiseMin(lo[id]);
      bhi = bhi.cwiseMax(hi[id]);
      clo = clo.cwiseMin(centroid[id]);
      chi = chi.cwiseMax(centroid[id]);
    }
    nodes_[w.node].lo = blo;
    nodes_[w.node].hi = bhi;
    const Index count = w.end - w.begin;
    if (count <= max_leaf) {
      nodes_[w.node].first = w.begin;
      nodes_[w.node].count = count;
      continue;
    }

    // Binned SAH along the longest axis of the centroid bounds (Wald 2007);
    // cost = A_left·N_left + A_right·N_right.
    int best_axis = -1;
    Index best_split = 0;  // bins [0, best_split] go left
    double best_cost = std::numeric_limits<double>::infinity();
    int longest = 0;
    for (int axis = 1; axis < 3; ++axis)
      if (chi[axis] - clo[axis] > chi[longest] - clo[longest]) longest = axis;
    for (int axis = longest; axis == longest; ++axis) {
      const double extent = chi[axis] - clo[axis];
      if (!(extent > 0.0)) continue;
      const double k = static_cast<double>(num_bins) / extent;
      for (Bin& b : bins) b = Bin{};
      for (Index i = w.begin; i < w.end; ++i) {
        const Index id = order_[i];
        const double t = (centroid[id][axis] - clo[axis]) * k;
        const Index b = std::min<Index>(num_bins - 1, static_cast<Index>(std::max(0.0, t)));
        bins[b].add(lo[id], hi[id]);
        ++bins[b].count;
      }
      Bin acc;
      for (Index b = num_bins - 1; b > 0; --b) {
        acc.add(bins[b].lo, bins[b].hi);
        acc.count += bins[b].count;
        right_cost[b] = acc.count ? half_area(acc.lo, acc.hi) * acc.count : 0.0;
      }
      Bin left;
      for (Index b = 0; b + 1 < num_bins; ++b) {
        left.add(bins[b].lo, bins[b].hi);
        left.count += bins[b].count;
        if (left.count == 0 || left.count == count) continue;
        const double cost = half_area(left.lo, left.hi) * left.count + right_cost[b + 1];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_split = b;
        }
      }
    }

    Index mid;
    if (best_axis >= 0) {
      const double extent = chi[best_axis] - clo[best_axis];
      const double k = static_cast<double>(num_bins) / extent;
      auto* first = order_.data() + w.begin;
      auto* last = order_.data() + w.end;
      auto* m = std::partition(first, last, [&](Index id) {
        const double t = (centroid[id][best_axis] - clo[best_axis]) * k;
        const Index b = std::min<Index>(num_bins - 1, static_cast<Index>(std::max(0.0, t)));
        return b <= best_split;
      });
      mid = static_cast<Index>(m - order_.data());
    } else {
      // All centroids coincide: split the range in half (keeps the depth logarithmic).
      mid = w.begin + count / 2;
    }
    const Index left = static_cast<Index>(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[w.node].first = left;
    nodes_[w.node].count = 0;
    work.push_back({left + 1, mid, w.end, w.depth + 1});
    work.push_back({left, w.begin, mid, w.depth + 1});
  }
}

// --- primitive sets ----------------------------------------------------------------------------------

TriangleBvh::TriangleBvh(std::span<const std::array<Vec3, 3>> triangles, const BvhBuildParams& params) {
  const std::size_t n = triangles.size();
  std::vector<Vec3> lo(n), hi(n), ce(n);
  parallel_chunks(n, params.threads, kMinParallelPrimitives, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto& t = triangles[i];
      lo[i] = t[0].cwiseMin(t[1]).cwiseMin(t[2]);
      hi[i] = t[0].cwiseMax(t[1]).cwiseMax(t[2]);
      ce[i] = 0.5 * (lo[i] + hi[i]);
    }
  });
  bvh_.build(lo, hi, ce, params);
  ids_ = bvh_.order();
  frames_.resize(n);
  pos_.resize(n);
  parallel_chunks(n, params.threads, kMinParallelPrimitives, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto& t = triangles[ids_[i]];
      frames_[i] = make_triangle_frame(t[0], t[1], t[2]);
      pos_[ids_[i]] = static_cast<Index>(i);
    }
  });
}

NearestHit TriangleBvh::nearest(const Vec3& p, Index hint) const {
  return nearest_if(p, [](Index) { return true; }, hint);
}

SegmentBvh::SegmentBvh(std::span<const std::array<Vec3, 2>> segments, const BvhBuildParams& params) {
  const std::size_t n = segments.size();
  std::vector<Vec3> lo(n), hi(n), ce(n);
  for (std::size_t i = 0; i < n; ++i) {
    lo[i] = segments[i][0].cwiseMin(segments[i][1]);
    hi[i] = segments[i][0].cwiseMax(segments[i][1]);
    ce[i] = 0.5 * (lo[i] + hi[i]);
  }
  bvh_.build(lo, hi, ce, params);
  ids_ = bvh_.order();
  segs_.resize(n);
  pos_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    segs_[i] = segments[ids_[i]];
    pos_[ids_[i]] = static_cast<Index>(i);
  }
}

NearestHit SegmentBvh::nearest(const Vec3& p, Index hint) const {
  NearestHit hit;
  Index best = kInvalidIndex;
  Vec3 best_point = Vec3::Zero();
  double best_d2 = std::numeric_limits<double>::infinity();
  if (hint < pos_.size()) {
    const auto& s = segs_[pos_[hint]];
    best_point = closest_point_on_segment(p, s[0], s[1]);
    best_d2 = (p - best_point).squaredNorm();
    best = pos_[hint];
  }
  bvh_.nearest(p, best_d2, [&](Index i, double) {
    const Vec3 q = closest_point_on_segment(p, segs_[i][0], segs_[i][1]);
    const double d2 = (p - q).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
      best_point = q;
    }
    return d2;
  });
  if (best != kInvalidIndex) {
    hit.distance_sq = best_d2;
    hit.point = best_point;
    hit.primitive = ids_[best];
  }
  return hit;
}

}  // namespace quadlod
