// Directed Hausdorff distance by branch and bound (issue 24; docs/metrics.md §2): the maximum over
// every point of one triangle set of the distance to another, bracketed between an attained value
// and a proven upper bound, without random samples. The sampled maximum of evaluate() is a lower
// bound only, and on a coarse LOD the worst point usually lies inside a face, so the sampled value
// moves with the seed (Fig. 10 on the ram: ±1.5 % between seeds 1–3, enough to swap two methods).
#pragma once

#include "geometry/bvh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace quadlod::eval_detail {

struct HausdorffBoundParams {
  /// Stop when the upper bound exceeds the largest distance found by at most this (the units of
  /// the triangles: evaluate() passes normalised units, where 1e-5 is 0.02 % of the ram's
  /// Hausdorff and far below its seed-to-seed spread).
  double tolerance = 1e-5;
  /// Cap on distance queries per direction (memory: the open pieces, ~100 bytes each, at most
  /// about a third of the queries); reached, the result is not converged and `upper` is still a
  /// valid bound.
  std::uint64_t max_queries = 2'000'000;
};

struct HausdorffBound {
  double lower = 0.0;            ///< distance attained at a point of `from` (max over points evaluated)
  Vec3 at = Vec3::Zero();        ///< that point
  double upper = 0.0;            ///< proven: no point of `from` is farther from `to`
  std::uint64_t queries = 0;     ///< nearest-point queries made
  bool converged = false;        ///< upper − lower ≤ tolerance
};

/// max over p ∈ ∪from of d(p, ∪to). Every triangle starts with its corner distances d_i; since
/// d(·, to) is 1-Lipschitz, a triangle's points are within max_i d_i + r of `to`, r = the largest
/// distance of a point of the triangle from its nearest corner (≤ longest edge / √3, and ≤ the
/// smallest over corners of the farthest other corner); and since the distance to one triangle
/// is convex, they are within max_i d(c_i, T) of it for the nearest triangle T of any corner.
/// The piece with the largest bound is split into four at its edge midpoints until the largest
/// bound is within `tolerance` of the largest distance found. Deterministic (serial; no seed).
/// `to_triangles` are the triangles `to` was built from (by id).
HausdorffBound directed_hausdorff_bound(const std::vector<std::array<Vec3, 3>>& from, const TriangleBvh& to,
                                        const std::vector<std::array<Vec3, 3>>& to_triangles,
                                        const HausdorffBoundParams& params = {});

}  // namespace quadlod::eval_detail
