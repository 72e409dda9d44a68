// Plane quadrics (Garland & Heckbert 1997; Trettner & Kobbelt 2020, "Fast and robust QEF
// minimization using probabilistic quadrics") in (A, b, c) form:
//
//     Q(x) = xᵀ A x + 2 bᵀ x + c,      A symmetric 3×3.
//
// The quadric of the plane through p with unit normal n is the squared distance to that plane:
// A = n nᵀ, b = −(n·p) n, c = (n·p)². Quadrics add; a weighted quadric is w·Q.
//
// Used by the medial-curve clustering (§3.2.3, Eq. 5: `edge_quadric`) and the triangle-region
// clustering (§3.2.4: plane quadrics of faces). Both only need the error and a robust minimiser
// on a segment, so no 3×3 solve is exposed here: the segment search cannot run off to infinity
// where the quadric is rank deficient (flat regions, straight curves).
#pragma once

#include "quadlod/mesh.h"

#include <Eigen/Core>

#include <algorithm>

namespace quadlod {

struct Quadric {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Vec3 b = Vec3::Zero();
  double c = 0.0;

  /// Squared distance to the plane through `point` with normal `normal` (unit length expected;
  /// a zero normal gives the zero quadric).
  static Quadric plane(const Vec3& point, const Vec3& normal) {
    Quadric q;
    const double d = -normal.dot(point);
    q.A = normal * normal.transpose();
    q.b = d * normal;
    q.c = d * d;
    return q;
  }

  double operator()(const Vec3& x) const { return x.dot(A * x) + 2.0 * b.dot(x) + c; }

  Quadric& operator+=(const Quadric& o) {
    A += o.A;
    b += o.b;
    c += o.c;
    return *this;
  }
  friend Quadric operator+(Quadric a, const Quadric& o) { return a += o; }
  friend Quadric operator*(double w, Quadric q) {
    q.A *= w;
    q.b *= w;
    q.c *= w;
    return q;
  }

  /// The point of segment [p, r] with the least error, and that error (clamped at 0: rounding
  /// can make an exact zero slightly negative). The error along the segment is the parabola
  /// f(t) = Q(p) + 2t (A p + b)·d + t² dᵀA d with d = r − p, minimised in closed form on [0, 1].
  struct Minimum {
    Vec3 point;
    double error;
    double t;
  };
  Minimum minimize_on_segment(const Vec3& p, const Vec3& r) const {
    const Vec3 d = r - p;
    const double curvature = d.dot(A * d);
    const double slope = (A * p + b).dot(d);
    double t = 0.5;
    if (curvature > 1e-300) {
      t = std::clamp(-slope / curvature, 0.0, 1.0);
    } else {
      // Linear (or constant) along the segment: the lower end.
      t = slope > 0.0 ? 0.0 : slope < 0.0 ? 1.0 : 0.5;
    }
    const Vec3 x = p + t * d;
    return {x, std::max(0.0, (*this)(x)), t};
  }
};

/// Eq. 5 (after Knodt 2025): the per-edge quadric of a medial edge ⟨v0, v1⟩ with face normal n_f,
///     Q(e) = w_n · Q(v0, n_f) + w_f · Q(v0, (v0 − v1)/|v0 − v1| × n_f),   w_n = |v0 − v1|.
/// The first plane is the tangent plane (surface deviation), the second the plane through the
/// edge that contains n_f (in-plane distortion orthogonal to the flow). A zero-length edge or a
/// zero normal contributes only what is defined (possibly nothing).
inline Quadric edge_quadric(const Vec3& v0, const Vec3& v1, const Vec3& n_f, double w_f) {
  const Vec3 d = v0 - v1;
  const double w_n = d.norm();
  Quadric q = w_n * Quadric::plane(v0, n_f);
  if (w_n > 0.0) {
    const Vec3 side = (d / w_n).cross(n_f);
    const double len = side.norm();
    if (len > 0.0) q += w_f * Quadric::plane(v0, side / len);
  }
  return q;
}

}  // namespace quadlod
