// Deformation-sensitive vertex quadrics: see pose_quadrics.h.
#include "skin/pose_quadrics.h"

#include "quadlod/skin.h"

namespace quadlod {

Quadric pull_back_quadric(const Quadric& q, const Eigen::Matrix4d& m) {
  // E(Lx + t) = xᵀ(LᵀAL)x + 2(Lᵀ(At + b))ᵀx + (tᵀAt + 2bᵀt + c).
  const Eigen::Matrix3d L = m.topLeftCorner<3, 3>();
  const Vec3 t = m.topRightCorner<3, 1>();
  Quadric out;
  out.A = L.transpose() * q.A * L;
  out.A = 0.5 * (out.A + out.A.transpose());  // keep it exactly symmetric
  out.b = L.transpose() * (q.A * t + q.b);
  out.c = t.dot(q.A * t) + 2.0 * q.b.dot(t) + q.c;
  return out;
}

VertexQuadrics build_pose_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn,
                                          const QuadricPlacementParams& placement,
                                          const std::vector<std::vector<Eigen::Matrix4d>>& poses) {
  VertexQuadrics bind = build_vertex_quadrics(mesh, conn, placement);
  if (poses.empty() || mesh.skin.empty()) return bind;
  const Index n = mesh.num_vertices();
  std::vector<Quadric> sum(n);
  for (Index v = 0; v < n; ++v) sum[v] = bind.terms[v].q;
  for (const std::vector<Eigen::Matrix4d>& pose : poses) {
    const PolyMesh posed = pose_mesh(mesh, pose);
    // The bind pose's h (mean edge length): a pose that stretches or shrinks some edges must not
    // rescale the edge planes of every vertex (rigid parts keep their quadric exactly).
    const VertexQuadrics at = build_vertex_quadrics(posed, conn, bind.mean_edge, placement);
    for (Index v = 0; v < n; ++v) {
      Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
      double w = 0.0;
      for (Index i = mesh.skin.offsets[v]; i < mesh.skin.offsets[v + 1]; ++i) {
        m += mesh.skin.weight[i] * pose[mesh.skin.joint[i]];
        w += mesh.skin.weight[i];
      }
      if (!(w > 0.0)) m = Eigen::Matrix4d::Identity();  // no influence: pose_mesh leaves it in place
      sum[v] += pull_back_quadric(at.terms[v].q, m);
    }
  }
  const double scale = 1.0 / double(1 + poses.size());
  for (Index v = 0; v < n; ++v) {
    Quadric& q = bind.terms[v].q;
    q.A = sum[v].A * scale;
    q.b = sum[v].b * scale;
    q.c = sum[v].c * scale;
  }
  return bind;
}

}  // namespace quadlod
