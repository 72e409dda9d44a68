// Bounding volume hierarchies for exact nearest-point queries against triangles and segments
// (the distance oracles of `quadlod eval`: Chamfer, Hausdorff, PCCD, flow; docs/metrics.md).
//
// One tree kernel (`Bvh`) over axis-aligned boxes, built by binned SAH (longest centroid axis),
// queried iteratively with an explicit stack, nearest child first, pruning every node whose box
// is not strictly nearer than the best hit so far. Two thin wrappers own the primitives:
//   * TriangleBvh: closest point on a set of triangles (the Voronoi-region method of Ericson,
//     "Real-Time Collision Detection" §5.1.5, evaluated in a per-triangle orthonormal frame so
//     that slivers and zero-area triangles stay exact, see TriangleFrame);
//   * SegmentBvh: closest point on a set of segments.
//
// Exactness: the answer is the minimum of the same per-primitive function a brute-force loop
// evaluates (closest_point_on_triangle / closest_point_on_segment below); boxes are exact
// min/max of the primitive's coordinates, so pruning never discards the minimiser except when a
// box distance and a triangle distance round differently by an ulp (distances then agree to
// ~1e-16 of the coordinates; tests/test_bvh.cpp checks <= 1e-14 against brute force).
//
// Thread safety: queries are const and touch no shared mutable state; run them concurrently.
#pragma once

#include "quadlod/mesh.h"

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace quadlod {

// --- exact primitive distances ---------------------------------------------------------------

/// Which Voronoi feature of triangle (a, b, c) holds the closest point.
enum class TriangleRegion : std::uint8_t { VertexA, VertexB, VertexC, EdgeAB, EdgeBC, EdgeCA, Face };

struct TrianglePoint {
  Vec3 point;                   ///< closest point of the triangle
  double distance_sq = 0.0;     ///< squared distance from the query (computed in the frame)
  TriangleRegion region = TriangleRegion::Face;
};

/// A triangle in its own orthonormal frame, ready for repeated queries. The corners are rotated
/// (keeping orientation) so that the longest edge is A'B'; then A' = origin, B' = (len, 0),
/// C' = (cx, h) with h >= 0 in the basis (e1, e2), n = e1 × e2.
///
/// Why a frame: Ericson's region method (RTCD §5.1.5) decides regions from differences of
/// products of dot products, which cancel catastrophically on slivers — a triangle of relative
/// height 1e-9 gets points 0.2 of its length away (tests/test_bvh.cpp, SliversAreExact). In the
/// frame the same Voronoi regions are decided by edge functions of 2D coordinates that carry
/// absolute error ~1e-16·len whatever the shape, so the answer is exact up to that rounding for
/// every triangle, zero-area ones included.
struct TriangleFrame {
  Vec3 origin = Vec3::Zero();
  Vec3 e1 = Vec3::Zero(), e2 = Vec3::Zero(), n = Vec3::Zero();
  double len = 0.0, cx = 0.0, h = 0.0;
  double inv_len2_bc = 0.0, inv_len2_ca = 0.0;  ///< 1/|B'C'|², 1/|C'A'|² (0 for zero length)
  std::uint8_t rotation = 0;    ///< A' is the original corner number `rotation` (0 = a, 1 = b, 2 = c)
};

TriangleFrame make_triangle_frame(const Vec3& a, const Vec3& b, const Vec3& c);

/// Closest point of the closed triangle to p: project into the frame, classify by the signs of
/// the three edge functions (inside → the projection; outside → the nearest point of the edges
/// the point is outside of, a vertex when clamped). Exact up to rounding for every triangle shape;
/// a zero-area triangle is its longest edge (which contains the third corner). Region names refer
/// to the corners as given to make_triangle_frame. Never NaN for finite input.
TrianglePoint closest_point_on_triangle(const TriangleFrame& t, const Vec3& p);

/// Convenience: make_triangle_frame(a, b, c) then the query (bit-identical to a BVH query).
TrianglePoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Closest point of the closed segment [a, b] to p (a when a == b).
Vec3 closest_point_on_segment(const Vec3& p, const Vec3& a, const Vec3& b);

/// Squared distance from p to the box (0 inside).
inline double box_distance_sq(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = p[k] < lo[k] ? lo[k] - p[k] : (p[k] > hi[k] ? p[k] - hi[k] : 0.0);
    d2 += d * d;
  }
  return d2;
}

// --- tree kernel ---------------------------------------------------------------------------------

/// A node covers primitives order[first, first + count) when count > 0 (leaf); otherwise its
/// children are nodes `first` and `first + 1`.
struct BvhNode {
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
  Index first = 0;
  Index count = 0;
};

struct BvhBuildParams {
  Index max_leaf_size = 4;  ///< leaves hold at most this many primitives (>= 1)
  Index sah_bins = 16;      ///< SAH candidate planes per axis = bins - 1
  /// Threads for the per-primitive set-up (boxes, triangle frames); 0 = every core. The tree is
  /// built on one thread and is the same for any count.
  int threads = 1;
};

class Bvh {
 public:
  /// Builds over primitive boxes [lo[i], hi[i]] with split keys `centroid[i]`. Deterministic.
  void build(std::span<const Vec3> lo, std::span<const Vec3> hi, std::span<const Vec3> centroid,
             const BvhBuildParams& params = {});

  bool empty() const { return nodes_.empty(); }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  /// Leaf order: position in the tree → primitive id given to build().
  const std::vector<Index>& order() const { return order_; }
  Index depth() const { return depth_; }

  /// Visits leaves nearest-first. `leaf(position, best_d2)` is called for each leaf primitive
  /// position (an index into order()) whose node box is strictly nearer than the current best, and
  /// returns the squared distance of that primitive (or +inf). Returns the minimum found, or
  /// `best_d2` unchanged (initially: an upper bound, +inf for none) when nothing was closer.
  template <class LeafFn>
  double nearest(const Vec3& p, double best_d2, LeafFn&& leaf) const;

 private:
  std::vector<BvhNode> nodes_;
  std::vector<Index> order_;
  Index depth_ = 0;
};

template <class LeafFn>
double Bvh::nearest(const Vec3& p, double best_d2, LeafFn&& leaf) const {
  if (nodes_.empty()) return best_d2;
  struct Entry {
    Index node;
    double d2;
  };
  // Depth is bounded by the build (at most ~2·log2(n) + a few for SAH on real meshes; the build
  // records it), and every push pairs with at most one more level, so depth + 2 entries suffice.
  constexpr int kInline = 128;
  Entry inline_stack[kInline];
  std::vector<Entry> heap_stack;
  Entry* stack = inline_stack;
  if (depth_ + 2 > static_cast<Index>(kInline)) {
    heap_stack.resize(depth_ + 2);
    stack = heap_stack.data();
  }
  int top = 0;
  stack[top++] = {0, box_distance_sq(p, nodes_[0].lo, nodes_[0].hi)};
  while (top > 0) {
    const Entry e = stack[--top];
    // Only strictly closer primitives can replace the best hit, so a box at distance >= best
    // holds nothing useful.
    if (e.d2 >= best_d2) continue;
    const BvhNode& node = nodes_[e.node];
    if (node.count > 0) {
      for (Index i = node.first; i < node.first + node.count; ++i) {
        const double d2 = leaf(i, best_d2);
        if (d2 < best_d2) best_d2 = d2;
      }
      continue;
    }
    const Index l = node.first, r = node.first + 1;
    const double dl = box_distance_sq(p, nodes_[l].lo, nodes_[l].hi);
    const double dr = box_distance_sq(p, nodes_[r].lo, nodes_[r].hi);
    // Push the farther child first so the nearer one is popped next.
    if (dl <= dr) {
      if (dr < best_d2) stack[top++] = {r, dr};
      if (dl < best_d2) stack[top++] = {l, dl};
    } else {
      if (dl < best_d2) stack[top++] = {l, dl};
      if (dr < best_d2) stack[top++] = {r, dr};
    }
  }
  return best_d2;
}

// --- primitive sets --------------------------------------------------------------------------------

/// Result of a nearest-point query. `primitive` is the id given at construction (kInvalidIndex
/// when the set is empty; then distance_sq is +inf).
struct NearestHit {
  double distance_sq = std::numeric_limits<double>::infinity();
  Vec3 point = Vec3::Zero();
  Index primitive = kInvalidIndex;
};

class TriangleBvh {
 public:
  TriangleBvh() = default;
  /// Triangles (a, b, c); zero-area triangles are kept (they are segments or points of the set).
  explicit TriangleBvh(std::span<const std::array<Vec3, 3>> triangles, const BvhBuildParams& params = {});

  /// Exact closest point of the union of all triangles to p. `hint` (a triangle id, optional)
  /// seeds the search with that triangle's distance — typically the answer of a nearby query —
  /// which prunes more; the distance found does not depend on it (ties may pick another id).
  NearestHit nearest(const Vec3& p, Index hint = kInvalidIndex) const;
  /// The same among the triangles whose id passes `accept` (a predicate on the original id);
  /// `hint`, if it passes, seeds the search as for nearest(). Only triangles strictly nearer than
  /// sqrt(max_distance_sq) count (none found: primitive = kInvalidIndex); a finite bound keeps a
  /// search that rejects the nearby triangles from opening the whole tree.
  template <class Accept>
  NearestHit nearest_if(const Vec3& p, Accept&& accept, Index hint = kInvalidIndex,
                        double max_distance_sq = std::numeric_limits<double>::infinity()) const {
    NearestHit hit;
    double best_d2 = max_distance_sq;
    auto consider = [&](Index i) {
      const TrianglePoint tp = closest_point_on_triangle(frames_[i], p);
      if (tp.distance_sq < best_d2) {
        best_d2 = tp.distance_sq;
        hit = {tp.distance_sq, tp.point, ids_[i]};
      }
      return tp.distance_sq;
    };
    if (hint < pos_.size() && accept(hint)) consider(pos_[hint]);
    bvh_.nearest(p, best_d2, [&](Index i, double) {
      return accept(ids_[i]) ? consider(i) : std::numeric_limits<double>::infinity();
    });
    return hit;
  }
  Index size() const { return static_cast<Index>(frames_.size()); }
  const Bvh& tree() const { return bvh_; }

 private:
  Bvh bvh_;
  std::vector<TriangleFrame> frames_;  ///< in tree order
  std::vector<Index> ids_;             ///< tree order → original triangle id
  std::vector<Index> pos_;             ///< original triangle id → tree order
};

class SegmentBvh {
 public:
  SegmentBvh() = default;
  explicit SegmentBvh(std::span<const std::array<Vec3, 2>> segments, const BvhBuildParams& params = {});

  /// Exact closest point of the union of all segments to p; `hint` as for TriangleBvh.
  NearestHit nearest(const Vec3& p, Index hint = kInvalidIndex) const;
  Index size() const { return static_cast<Index>(segs_.size()); }
  const Bvh& tree() const { return bvh_; }

 private:
  Bvh bvh_;
  std::vector<std::array<Vec3, 2>> segs_;  ///< in tree order
  std::vector<Index> ids_;
  std::vector<Index> pos_;
};

}  // namespace quadlod
