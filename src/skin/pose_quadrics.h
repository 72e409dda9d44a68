// Deformation-sensitive vertex quadrics (issue 24; docs/skinning.md "Error under animation"):
// the quadric error a cluster is charged and placed by, measured in every pose of the rig's
// animation instead of the bind pose alone (Mohr & Gleicher 2003, "Deformation sensitive
// decimation"). Where the skin moves rigidly the result equals the bind-pose quadric, so only
// regions the animation bends (blended weights across a joint) become more expensive to reduce.
#pragma once

#include "geometry/cluster_quadric.h"
#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <Eigen/Core>

#include <vector>

namespace quadlod {

/// The vertex terms of build_vertex_quadrics(mesh, conn, placement) with each vertex's quadric
/// replaced by its mean over the bind pose and the given poses:
///     Q_v = (Q_v^bind + Σ_t M_v(t)* Q_v^(t)) / (1 + T),
/// Q_v^(t) the vertex's quadric (face and edge planes) on the mesh posed by pose t, and
/// M_v(t)* its pull-back to bind space through the vertex's own skinning transform
/// M_v(t) = Σ_j w_vj S_j(t), so that Q_v(x) is the mean over poses of the squared plane distances
/// of the posed point M_v(t)·x. A rigid M_v(t) (one bone, or bones moving together) gives back
/// Q_v^bind exactly. The volume terms and mean edge length stay the bind pose's.
/// `poses[t][j]` = S_j(t), the skinning matrix (G_j B_j⁻¹, skin.h) of joint j at pose t.
/// Preconditions: mesh.skin covers the mesh, every joint index < poses[t].size(). No poses (or
/// no skin): the bind-pose terms unchanged.
VertexQuadrics build_pose_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn,
                                          const QuadricPlacementParams& placement,
                                          const std::vector<std::vector<Eigen::Matrix4d>>& poses);

/// Quadric of the posed point: q∘(x ↦ L·x + t) for the affine map m = [L t; 0 1].
Quadric pull_back_quadric(const Quadric& q, const Eigen::Matrix4d& m);

}  // namespace quadlod
