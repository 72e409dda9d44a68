// Shape-sensitive vertex quadrics (issue 34; docs/blend_shapes.md "The error term"): the quadric
// error a cluster is charged and placed by counts the geometry of every blend shape besides the
// base, as build_pose_vertex_quadrics (skin/pose_quadrics.h) counts the poses of a rig. A region a
// shape only translates keeps its base quadric exactly; a region a shape bends or stretches (a
// smile, a blink) becomes more expensive to reduce, so it keeps the resolution the shape needs.
#pragma once

#include "geometry/cluster_quadric.h"
#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

namespace quadlod {

/// Replaces each vertex's quadric Q_v (already built for the base mesh, or for the base and the
/// rig's poses) by
///     Q_v ← (Q_v + w · Σ_k T_v,k* Q_v^(k)) / (1 + w · K),
/// Q_v^(k) the vertex's quadric (face and edge planes) on the mesh in shape k at full weight,
/// T_v,k* its pull-back through the vertex's own displacement x ↦ x + d_k(v), so that Q_v(x) is
/// the weighted mean of the squared plane distances of x in the base and of x + d_k(v) in every
/// shape. w = `shape_weight` (SimplifyOptions::morph_error_weight): how much one shape's
/// geometry weighs against the base's. The volume terms and h stay the base's. No shapes or
/// w <= 0: unchanged. Precondition: `quadrics` were built for `mesh` with `conn`.
void add_morph_quadrics(VertexQuadrics& quadrics, const PolyMesh& mesh, const Connectivity& conn,
                        const QuadricPlacementParams& placement, double shape_weight);

}  // namespace quadlod
