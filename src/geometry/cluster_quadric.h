// The quadric of a vertex cluster and where its merged vertex goes (paper §3.3.2, "QEM-based
// Simplification", with the per-edge planes and weights of Knodt 2025).
//
// One definition for two users, so that what the selection pays for is what the collapse does:
//   * post/cluster_collapse places every cluster of the final selection with place_cluster();
//   * select/shape_cost prices a selection by the error of the clusters it creates, evaluated
//     at the same placement (issue "Shape first": the cost of a selection is the geometric error
//     of the mesh it produces).
//
// Per input vertex: area-weighted face planes (Garland–Heckbert; a corner's share of its face's
// area, split by interior angle) and Knodt's edge planes (the plane through an edge containing
// the face normal, weight |edge| · h / 2π · kind, kind = dihedral / π floored at min_edge_weight,
// heavy on boundary, non-manifold and sharp edges), plus the Lindstrom–Turk volume terms.
// A cluster's terms are the sum of its members'. docs/cluster_collapse.md has the derivation.
#pragma once

#include "geometry/quadric.h"
#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <vector>

namespace quadlod {

struct QuadricPlacementParams {
  // All weights are dimensionless multipliers of terms that are scaled to the mesh: face planes
  // carry area, edge planes carry |edge| · h / 2π with h the mean input edge length, which
  // reproduces Knodt's ratio of edge to face weight on a regular quad grid.

  /// Multiplier of the face-plane quadrics (Garland–Heckbert), >= 0.
  double face_plane_weight = 1.0;
  /// Multiplier of all edge-plane quadrics (Knodt 2025), >= 0. 0 turns off every edge plane.
  double edge_plane_weight = 1.0;
  /// Weight of a manifold edge's planes is dihedral angle / π (0 flat … 1 folded flat), but at
  /// least this (Knodt's `min_edge_weight`): keeps flat regions evenly spaced.
  double min_edge_weight = 0.01;
  /// Weight of the planes of an open-boundary edge (Knodt: 4): keeps boundaries from shrinking.
  double boundary_edge_weight = 4.0;
  /// Weight of the planes of a non-manifold edge (Knodt: 4).
  double nonmanifold_edge_weight = 4.0;
  /// Manifold edges with a dihedral angle of at least this many degrees are sharp features and
  /// get at least `feature_edge_weight`, as heavy as a boundary (our addition; Knodt only uses
  /// dihedral / π, i.e. 0.5 for a 90° crease). 60° is the paper's ϵ_θ (§3.2.2).
  double feature_angle_deg = 60.0;
  double feature_edge_weight = 4.0;
  /// Per mesh edge (borrowed, sized as the connectivity's edges; nullptr: none): 1 on the lines of
  /// the texture, UV seams and material borders (issue 32). Their planes weigh at least
  /// `texture_line_edge_weight`, as meshoptimizer weighs attribute seams, so a cluster on such a
  /// line is placed near it by its quadric alone (the collapse no longer pins it onto the
  /// polyline; docs/attributes.md, "Lines that shorten").
  const std::vector<std::uint8_t>* texture_line_edges = nullptr;
  double texture_line_edge_weight = 1.0;
  /// Pull toward the cluster centroid: each member adds regularization · h² · |x − p_member|².
  /// Makes the 3×3 system positive definite in flat and straight regions. >= 0. It decides the
  /// placement only; the error a cluster is charged (ClusterPlacement::error) leaves it out.
  double regularization = 1e-3;
  /// Minimise subject to Lindstrom–Turk volume preservation (the signed volume swept between the
  /// members' face planes and the new vertex is zero), as Knodt's code does. Skipped where the
  /// constraint is degenerate.
  bool preserve_volume = true;
  /// Eigenvalues below this fraction of the largest are treated as zero (pseudo-inverse around
  /// the centroid) when the direct solve is ill-conditioned.
  double eigen_cutoff = 1e-6;
  /// A minimiser outside the cluster's bounding box enlarged by this fraction of max(box
  /// diagonal, h) is not trusted: the best of {centroid, members} by quadric error is used.
  double bbox_margin = 0.5;
};

/// What one input vertex brings to the quadric of any cluster it joins.
struct VertexTerms {
  Quadric q;              ///< face planes + edge planes through this vertex
  Vec3 g = Vec3::Zero();  ///< Σ w·n       volume constraint: g·x = h
  double h = 0.0;         ///< Σ w·(n·p)
  double w = 0.0;         ///< Σ w         (scale for the degeneracy test of g)
};

/// The sums over a cluster's members that placement needs. Additive: the terms of a union of
/// clusters are the sum of their terms.
struct ClusterTerms {
  Quadric q;
  Vec3 g = Vec3::Zero();
  double h = 0.0, w = 0.0;
  Vec3 psum = Vec3::Zero();  ///< Σ member positions
  double p2sum = 0.0;        ///< Σ |member position|²
  double count = 0.0;        ///< members
  BoundingBox box;

  void add_vertex(const VertexTerms& t, const Vec3& p) {
    q += t.q;
    g += t.g;
    h += t.h;
    w += t.w;
    psum += p;
    p2sum += p.squaredNorm();
    count += 1.0;
    box.extend(p);
  }
  ClusterTerms& operator+=(const ClusterTerms& o) {
    q += o.q;
    g += o.g;
    h += o.h;
    w += o.w;
    psum += o.psum;
    p2sum += o.p2sum;
    count += o.count;
    box.extend(o.box.min);
    box.extend(o.box.max);
    return *this;
  }
};

/// The vertex terms of every input vertex, and the mean input edge length h they are scaled by.
struct VertexQuadrics {
  std::vector<VertexTerms> terms;
  double mean_edge = 1.0;
};

/// Builds the terms of every vertex of `mesh`. `face_normal` / `face_area` are the unit normal
/// (zero when the face has no area) and area of every face; `mean_edge` is h.
VertexQuadrics build_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn, const std::vector<Vec3>& face_normal,
                                     const std::vector<double>& face_area, double mean_edge,
                                     const QuadricPlacementParams& params);
/// The same, computing normals and areas itself, with a given h (a deformed copy of a mesh
/// — a pose, a blend shape — keeps the undeformed mesh's h, so that stretching some edges does
/// not rescale the edge planes of every vertex).
VertexQuadrics build_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn, double mean_edge,
                                     const QuadricPlacementParams& params);
/// The same, computing normals, areas and h itself.
VertexQuadrics build_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn,
                                     const QuadricPlacementParams& params);

struct ClusterPlacement {
  Vec3 position = Vec3::Zero();
  /// The cluster quadric (face and edge planes, no regulariser) at `position`, >= 0: the sum
  /// over the members' planes of weight × squared distance (units: length⁴).
  double error = 0.0;
  bool pseudo_inverse = false;      ///< ill-conditioned: eigen pseudo-inverse used
  bool volume_constrained = false;  ///< the Lindstrom–Turk constraint was applied
  bool fallback = false;            ///< minimiser untrusted: best of centroid and members
};

/// Minimiser of the cluster quadric plus the centroid regulariser, solved around the centroid
/// x̄ so that directions the quadric leaves free stay at x̄:  x = x̄ + A⁻¹ (−A x̄ − b); under
/// volume preservation (g·x = h) the Lagrange solution x + A⁻¹g (h − g·x) / (g·A⁻¹g). An
/// untrusted result (non-finite, or outside the cluster's box grown by bbox_margin) is replaced
/// by the best of the centroid and the members by quadric error: `for_each_member(f)` must call
/// f(position) for every member (it is only called then). `mean_edge` is h.
template <class ForEachMember>
ClusterPlacement place_cluster(const ClusterTerms& t, double mean_edge, const QuadricPlacementParams& params,
                               ForEachMember&& for_each_member);

/// place_cluster() without the fallback to members (the centroid is the only fallback); for
/// callers that do not hold the member list at hand.
ClusterPlacement place_cluster(const ClusterTerms& t, double mean_edge, const QuadricPlacementParams& params);

/// The cluster quadric plus the centroid regulariser (regularization · h² · Σ_m |x − p_m|²): what
/// placement minimises.
Quadric regularized_quadric(const ClusterTerms& t, double mean_edge, const QuadricPlacementParams& params);

namespace cluster_quadric_detail {
/// The solve of place_cluster(); `ok` false when the minimiser is untrusted (the caller then
/// picks the fallback). `q` receives the regularised quadric, `plain` is without regulariser.
ClusterPlacement solve(const ClusterTerms& t, double mean_edge, const QuadricPlacementParams& params, Quadric& q,
                       bool& ok);
}  // namespace cluster_quadric_detail

template <class ForEachMember>
ClusterPlacement place_cluster(const ClusterTerms& t, double mean_edge, const QuadricPlacementParams& params,
                               ForEachMember&& for_each_member) {
  Quadric q;
  bool ok = false;
  ClusterPlacement out = cluster_quadric_detail::solve(t, mean_edge, params, q, ok);
  if (ok) return out;
  // Best of the centroid and the members by the regularised quadric, as the collapse always did.
  Vec3 best = t.psum / t.count;
  double best_err = q(best);
  for_each_member([&](const Vec3& p) {
    const double err = q(p);
    if (err < best_err) {
      best_err = err;
      best = p;
    }
  });
  out.position = best;
  out.error = std::max(0.0, t.q(best));
  out.fallback = true;
  return out;
}

}  // namespace quadlod
