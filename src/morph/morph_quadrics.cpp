// Shape-sensitive vertex quadrics: see morph_quadrics.h. The same construction as the pose
// quadrics of Mohr & Gleicher 2003 ("Deformation sensitive decimation"), with a blend shape's
// per-vertex translation in place of a pose's per-vertex skinning transform.
#include "morph/morph_quadrics.h"

#include "quadlod/morph.h"
#include "skin/pose_quadrics.h"

namespace quadlod {

void add_morph_quadrics(VertexQuadrics& quadrics, const PolyMesh& mesh, const Connectivity& conn,
                        const QuadricPlacementParams& placement, double shape_weight) {
  if (mesh.morph_targets.empty() || !(shape_weight > 0.0)) return;
  const Index n = mesh.num_vertices();
  std::vector<Quadric> sum(n);
  for (Index v = 0; v < n; ++v) sum[v] = quadrics.terms[v].q;
  for (Index k = 0; k < mesh.morph_targets.size(); ++k) {
    const PolyMesh shaped = apply_morph_target(mesh, k);
    // The base's h (mean edge length), as for poses: a shape that stretches some edges must not
    // rescale the edge planes of every vertex.
    const VertexQuadrics at = build_vertex_quadrics(shaped, conn, quadrics.mean_edge, placement);
    const std::vector<Vec3>& d = mesh.morph_targets[k].displacement;
    for (Index v = 0; v < n; ++v) {
      Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
      m.topRightCorner<3, 1>() = d[v];
      const Quadric q = pull_back_quadric(at.terms[v].q, m);
      sum[v].A += shape_weight * q.A;
      sum[v].b += shape_weight * q.b;
      sum[v].c += shape_weight * q.c;
    }
  }
  const double scale = 1.0 / (1.0 + shape_weight * double(mesh.morph_targets.size()));
  for (Index v = 0; v < n; ++v) {
    Quadric& q = quadrics.terms[v].q;
    q.A = sum[v].A * scale;
    q.b = sum[v].b * scale;
    q.c = sum[v].c * scale;
  }
}

}  // namespace quadlod
