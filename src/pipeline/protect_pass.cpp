// Issue 34: the protect weights inside one pass (src/pipeline/protect_pass.h).
#include "pipeline/protect_pass.h"

#include <algorithm>

namespace quadlod::protect_detail {

std::vector<std::uint8_t> protected_flags(const std::vector<double>& weights) {
  std::vector<std::uint8_t> flags(weights.size(), 0);
  for (std::size_t v = 0; v < weights.size(); ++v) flags[v] = weights[v] >= 1.0 ? 1 : 0;
  return flags;
}

void add_protect_quadrics(VertexQuadrics& quadrics, const PolyMesh& mesh, const std::vector<double>& weights,
                          double strength) {
  if (weights.size() != quadrics.terms.size() || !(strength > 0.0)) return;
  const double h2 = quadrics.mean_edge * quadrics.mean_edge;
  for (std::size_t v = 0; v < weights.size(); ++v) {
    if (!(weights[v] > 0.0)) continue;
    // The point quadric s |x − p|²: A = s I, b = −s p, c = s |p|².
    const double s = strength * weights[v] * h2;
    const Vec3& p = mesh.positions[v];
    Quadric point;
    point.A = s * Eigen::Matrix3d::Identity();
    point.b = -s * p;
    point.c = s * p.squaredNorm();
    quadrics.terms[v].q += point;
  }
}

Index pin_protected_edges(const Connectivity& conn, const std::vector<std::uint8_t>& flags,
                          std::vector<std::uint8_t>& pinned) {
  if (pinned.empty()) pinned.assign(conn.num_edges, 0);
  Index added = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    if (flags[a] && flags[b] && !pinned[e]) {
      pinned[e] = 1;
      ++added;
    }
  }
  return added;
}

std::vector<double> protect_edge_importance(const Connectivity& conn, const std::vector<double>& weights,
                                            double importance) {
  std::vector<double> extra(conn.num_edges, 0.0);
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    extra[e] = importance * std::max(weights[a], weights[b]);
  }
  return extra;
}

std::vector<double> carry_protect_weights(const std::vector<double>& weights, const std::vector<Index>& vertex_map,
                                          Index output_vertices) {
  std::vector<double> out(output_vertices, 0.0);
  for (std::size_t v = 0; v < vertex_map.size() && v < weights.size(); ++v)
    if (const Index o = vertex_map[v]; o != kInvalidIndex && o < output_vertices) out[o] = std::max(out[o], weights[v]);
  return out;
}

}  // namespace quadlod::protect_detail
