// Vertex and cluster quadrics shared by the collapse (§3.3.2) and the shape cost of the
// selection. Garland & Heckbert 1997 (face planes), Knodt 2025 (edge planes and their weights),
// Lindstrom & Turk 1998 (volume preservation), Trettner & Kobbelt 2020 (centroid regulariser).
#include "geometry/cluster_quadric.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace quadlod {

namespace {

// q += w · (squared distance to the plane through p with unit normal n), without temporaries.
inline void add_plane(Quadric& q, double w, const Vec3& p, const Vec3& n) {
  const double d = -n.dot(p);
  q.A.noalias() += (w * n) * n.transpose();
  q.b += (w * d) * n;
  q.c += w * d * d;
}

}  // namespace

VertexQuadrics build_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn, const std::vector<Vec3>& face_n,
                                     const std::vector<double>& face_area, double mean_edge,
                                     const QuadricPlacementParams& params) {
  VertexQuadrics out;
  out.mean_edge = mean_edge;
  out.terms.assign(mesh.num_vertices(), VertexTerms{});
  const double pi = std::numbers::pi;
  const double face_w = std::max(0.0, params.face_plane_weight);
  const double edge_w = std::max(0.0, params.edge_plane_weight);
  const double feature_cos = std::cos(std::clamp(params.feature_angle_deg, 0.0, 180.0) * pi / 180.0);
  const Index ne = conn.num_edges;

  // Edge kind weight (Knodt): dihedral angle / π on manifold edges, floored; boundary and
  // non-manifold edges heavy; sharp edges at least feature_edge_weight (ours).
  std::vector<double> kind_w(ne, 0.0);
  for (Index e = 0; e < ne; ++e) {
    const Index count = conn.edge_face_count(e);
    double w;
    if (count == 1) {
      w = params.boundary_edge_weight;
    } else if (count > 2) {
      w = params.nonmanifold_edge_weight;
    } else {
      const auto cs = conn.corners_of_edge(e);
      const Vec3& n0 = face_n[conn.corner_face[cs[0]]];
      const Vec3& n1 = face_n[conn.corner_face[cs[1]]];
      w = params.min_edge_weight;
      if (n0.squaredNorm() > 0.0 && n1.squaredNorm() > 0.0) {
        // Normals of consistently oriented neighbours: 0 on a flat edge, π folded flat.
        const double cosang = std::clamp(n0.dot(n1), -1.0, 1.0);
        w = std::max(w, std::acos(cosang) / pi);
        if (cosang <= feature_cos) w = std::max(w, params.feature_edge_weight);
      }
    }
    if (params.texture_line_edges && params.texture_line_edges->size() == ne && (*params.texture_line_edges)[e])
      w = std::max(w, params.texture_line_edge_weight);
    kind_w[e] = std::max(0.0, std::max(w, params.min_edge_weight));
  }

  const double edge_scale = edge_w * mean_edge / (2.0 * pi);
  std::vector<double> angles;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const double area = face_area[f];
    if (!(area > 0.0)) continue;  // no plane without a normal
    const Vec3& n = face_n[f];
    const Index b = mesh.face_begin(f), k = mesh.face_size(f);
    // Interior angles (unsigned, atan2 form: accurate near 0 and π).
    double angle_sum = 0.0;
    angles.resize(k);
    for (Index i = 0; i < k; ++i) {
      const Vec3& p = mesh.positions[mesh.corner_vertex[b + i]];
      const Vec3 e0 = mesh.positions[mesh.corner_vertex[b + (i + k - 1) % k]] - p;
      const Vec3 e1 = mesh.positions[mesh.corner_vertex[b + (i + 1) % k]] - p;
      angles[i] = std::atan2(e0.cross(e1).norm(), e0.dot(e1));
      angle_sum += angles[i];
    }
    for (Index i = 0; i < k; ++i) {
      const Index c = b + i;
      const Index v = mesh.corner_vertex[c];
      const Vec3& p = mesh.positions[v];
      const double wc = angle_sum > 0.0 ? area * angles[i] / angle_sum : area / k;
      VertexTerms& t = out.terms[v];
      if (face_w > 0.0) add_plane(t.q, face_w * wc, p, n);
      t.g += wc * n;
      t.h += wc * n.dot(p);
      t.w += wc;

      // Knodt's edge plane: through edge(c), containing the face normal.
      if (edge_scale <= 0.0) continue;
      const Index w = conn.tip_vertex(c);
      if (w == v) continue;
      const Vec3 d = mesh.positions[w] - p;
      const double len = d.norm();
      Vec3 m = n.cross(d);
      const double mlen = m.norm();
      if (!(len > 0.0) || !(mlen > 0.0)) continue;
      m /= mlen;
      const double weight = edge_scale * kind_w[conn.corner_edge[c]] * len;
      if (!(weight > 0.0)) continue;
      add_plane(t.q, weight, p, m);
      add_plane(out.terms[w].q, weight, p, m);  // the plane contains the edge: same plane at w
    }
  }
  return out;
}

namespace {
void face_normals_and_areas(const PolyMesh& mesh, std::vector<Vec3>& face_n, std::vector<double>& face_area) {
  const Index nf = mesh.num_faces();
  face_n.resize(nf);
  face_area.resize(nf);
  for (Index f = 0; f < nf; ++f) {
    const Vec3 av = face_area_vector(mesh, f);
    face_area[f] = av.norm();
    face_n[f] = face_area[f] > 0.0 ? Vec3(av / face_area[f]) : Vec3::Zero();
  }
}
}  // namespace

VertexQuadrics build_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn, double mean_edge,
                                     const QuadricPlacementParams& params) {
  std::vector<Vec3> face_n;
  std::vector<double> face_area;
  face_normals_and_areas(mesh, face_n, face_area);
  return build_vertex_quadrics(mesh, conn, face_n, face_area, mean_edge, params);
}

VertexQuadrics build_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn,
                                     const QuadricPlacementParams& params) {
  std::vector<Vec3> face_n;
  std::vector<double> face_area;
  face_normals_and_areas(mesh, face_n, face_area);
  double sum = 0.0;
  Index counted = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    const double len = (mesh.positions[a] - mesh.positions[b]).norm();
    if (len > 0.0) {
      sum += len;
      ++counted;
    }
  }
  double mean_edge = counted > 0 ? sum / counted : bounding_box(mesh).diagonal();
  if (!(mean_edge > 0.0) || !std::isfinite(mean_edge)) mean_edge = 1.0;
  return build_vertex_quadrics(mesh, conn, face_n, face_area, mean_edge, params);
}

Quadric regularized_quadric(const ClusterTerms& t, double h, const QuadricPlacementParams& params) {
  Quadric q = t.q;
  const double wr = std::max(0.0, params.regularization) * h * h;
  if (wr > 0.0) {  // Σ_m wr |x − p_m|²
    q.A.diagonal().array() += wr * t.count;
    q.b -= wr * t.psum;
    q.c += wr * t.p2sum;
  }
  return q;
}

namespace cluster_quadric_detail {

ClusterPlacement solve(const ClusterTerms& t, double h, const QuadricPlacementParams& params, Quadric& q, bool& ok) {
  ClusterPlacement out;
  q = regularized_quadric(t, h, params);
  const Vec3 centroid = t.psum / t.count;

  const double cutoff = std::max(0.0, params.eigen_cutoff);
  // Direct inverse when A is well conditioned: det A > cutoff · ‖A‖_F³ implies (A symmetric
  // positive semi-definite, ‖A‖_F ≥ λ_max, λ_mid ≤ λ_max) λ_min / λ_max > cutoff. The closed-form
  // 3×3 inverse is several times cheaper than a factorisation with a condition estimate, and the
  // selection prices every move with this placement.
  const double fro = q.A.norm();
  const double det = q.A.determinant();
  const bool direct = fro > 0.0 && std::isfinite(det) && det > cutoff * fro * fro * fro;
  Eigen::Matrix3d inverse;
  if (direct) inverse = q.A.inverse();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  double lambda_cut = 0.0;
  if (!direct) {
    out.pseudo_inverse = true;
    eig.compute(q.A);
    lambda_cut = cutoff * std::max(eig.eigenvalues().cwiseAbs().maxCoeff(), 0.0);
  }
  auto apply_inverse = [&](const Vec3& v) -> Vec3 {
    if (direct) return inverse * v;
    Vec3 x = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      const double l = eig.eigenvalues()[i];
      if (l > lambda_cut && l > 0.0) {
        const Vec3 u = eig.eigenvectors().col(i);
        x += u * (u.dot(v) / l);
      }
    }
    return x;
  };

  Vec3 x = centroid + apply_inverse(-(q.A * centroid + q.b));
  if (params.preserve_volume && t.g.norm() > 1e-9 * t.w) {
    const Vec3 ag = apply_inverse(t.g);
    const double den = t.g.dot(ag);
    if (den > 0.0 && std::isfinite(den)) {
      const Vec3 xv = x + ag * ((t.h - t.g.dot(x)) / den);
      if (xv.allFinite()) {
        x = xv;
        out.volume_constrained = true;
      }
    }
  }

  const double margin = std::max(0.0, params.bbox_margin) * std::max(t.box.diagonal(), h);
  ok = x.allFinite() && (x.array() >= t.box.min.array() - margin).all() &&
       (x.array() <= t.box.max.array() + margin).all();
  out.position = x;
  out.error = ok ? std::max(0.0, t.q(x)) : 0.0;
  return out;
}

}  // namespace cluster_quadric_detail

ClusterPlacement place_cluster(const ClusterTerms& t, double mean_edge, const QuadricPlacementParams& params) {
  return place_cluster(t, mean_edge, params, [](auto&&) {});
}

}  // namespace quadlod
