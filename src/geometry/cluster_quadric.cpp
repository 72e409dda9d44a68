// Vertex and cluster quadrics shared by the collapse (§3.3.2) and the shape cost of the
// selection. Garland & Heckbert 1997 (face planes), Knodt 2025 (edge planes and their weights),
// Lindstrom & Turk 1998 (volume preservation), Trettner & Kobbelt 2020 (centroid regulariser).
#include "geometry/cluster_quadric.h"

#include "util/parallel.h"

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

// Below this many items a stage runs on one thread (a thread costs more than it saves).
constexpr std::size_t kMinParallelItems = 20000;

}  // namespace

VertexQuadrics build_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn, const std::vector<Vec3>& face_n,
                                     const std::vector<double>& face_area, double mean_edge,
                                     const QuadricPlacementParams& params, int threads) {
  VertexQuadrics out;
  out.mean_edge = mean_edge;
  const Index nv = mesh.num_vertices(), nf = mesh.num_faces(), ne = conn.num_edges;
  out.terms.assign(nv, VertexTerms{});
  const double pi = std::numbers::pi;
  const double face_w = std::max(0.0, params.face_plane_weight);
  const double edge_w = std::max(0.0, params.edge_plane_weight);
  const double feature_cos = std::cos(std::clamp(params.feature_angle_deg, 0.0, 180.0) * pi / 180.0);

  // Edge kind weight (Knodt): dihedral angle / π on manifold edges, floored; boundary and
  // non-manifold edges heavy; sharp edges at least feature_edge_weight (ours).
  std::vector<double> kind_w(ne, 0.0);
  parallel_chunks(std::size_t(ne), threads, kMinParallelItems, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (Index e = Index(begin); e < Index(end); ++e) {
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
      kind_w[e] = std::max(0.0, std::max(w, params.min_edge_weight));
    }
  });

  // Interior angles of every corner (unsigned, atan2 form: accurate near 0 and π) and their sum
  // per face, summed in corner order.
  std::vector<double> angle(mesh.num_corners(), 0.0), angle_sum(nf, 0.0);
  parallel_chunks(std::size_t(nf), threads, kMinParallelItems, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (Index f = Index(begin); f < Index(end); ++f) {
      if (!(face_area[f] > 0.0)) continue;  // no plane without a normal
      const Index b = mesh.face_begin(f), k = mesh.face_size(f);
      double sum = 0.0;
      for (Index i = 0; i < k; ++i) {
        const Vec3& p = mesh.positions[mesh.corner_vertex[b + i]];
        const Vec3 e0 = mesh.positions[mesh.corner_vertex[b + (i + k - 1) % k]] - p;
        const Vec3 e1 = mesh.positions[mesh.corner_vertex[b + (i + 1) % k]] - p;
        angle[b + i] = std::atan2(e0.cross(e1).norm(), e0.dot(e1));
        sum += angle[b + i];
      }
      angle_sum[f] = sum;
    }
  });

  // Knodt's edge plane of corner c: through edge(c) = (v, tip), containing the face normal; it is
  // added at both endpoints. False when it has no weight.
  const double edge_scale = edge_w * mean_edge / (2.0 * pi);
  auto edge_plane = [&](Index c, double& weight, Vec3& m) {
    if (edge_scale <= 0.0) return false;
    const Index f = conn.corner_face[c], v = mesh.corner_vertex[c], w = conn.tip_vertex(c);
    if (!(face_area[f] > 0.0) || w == v) return false;
    const Vec3 d = mesh.positions[w] - mesh.positions[v];
    const double len = d.norm();
    m = face_n[f].cross(d);
    const double mlen = m.norm();
    if (!(len > 0.0) || !(mlen > 0.0)) return false;
    m /= mlen;
    weight = edge_scale * kind_w[conn.corner_edge[c]] * len;
    return weight > 0.0;
  };

  // Each vertex gathers what the faces give it — its corners' face planes (a corner's share of
  // its face's area, split by interior angle) and the edge planes of the edges through it — in
  // the order of the corners that give them: the order a loop over the faces would add them in,
  // so the sums do not depend on the thread count.
  parallel_chunks(std::size_t(nv), threads, kMinParallelItems, [&](std::size_t begin, std::size_t end, std::size_t) {
    std::vector<std::pair<Index, bool>> given;  // (corner, its own corner: else the edge ending here)
    for (Index v = Index(begin); v < Index(end); ++v) {
      given.clear();
      for (Index c : conn.corners_at_vertex(v)) {
        given.push_back({c, true});
        given.push_back({conn.corner_prev[c], false});
      }
      std::sort(given.begin(), given.end());
      VertexTerms& t = out.terms[v];
      const Vec3& p = mesh.positions[v];
      for (const auto& [c, own] : given) {
        const Index f = conn.corner_face[c];
        double weight = 0.0;
        Vec3 m;
        if (!own) {
          if (edge_plane(c, weight, m)) add_plane(t.q, weight, mesh.positions[mesh.corner_vertex[c]], m);
          continue;
        }
        const double area = face_area[f];
        if (!(area > 0.0)) continue;
        const Vec3& n = face_n[f];
        const Index k = mesh.face_size(f);
        const double wc = angle_sum[f] > 0.0 ? area * angle[c] / angle_sum[f] : area / k;
        if (face_w > 0.0) add_plane(t.q, face_w * wc, p, n);
        t.g += wc * n;
        t.h += wc * n.dot(p);
        t.w += wc;
        if (edge_plane(c, weight, m)) add_plane(t.q, weight, p, m);
      }
    }
  });
  return out;
}

VertexQuadrics build_vertex_quadrics(const PolyMesh& mesh, const Connectivity& conn,
                                     const QuadricPlacementParams& params, int threads) {
  const Index nf = mesh.num_faces();
  std::vector<Vec3> face_n(nf);
  std::vector<double> face_area(nf);
  parallel_chunks(std::size_t(nf), threads, kMinParallelItems, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (Index f = Index(begin); f < Index(end); ++f) {
      const Vec3 av = face_area_vector(mesh, f);
      face_area[f] = av.norm();
      face_n[f] = face_area[f] > 0.0 ? Vec3(av / face_area[f]) : Vec3::Zero();
    }
  });
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
  return build_vertex_quadrics(mesh, conn, face_n, face_area, mean_edge, params, threads);
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
