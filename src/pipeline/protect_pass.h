// Issue 34 (docs/protect.md): what one pass of simplify() does with the protect weights of its
// input's vertices. Internal to src/pipeline/; the public side is include/quadlod/protect.h.
#pragma once

#include "geometry/cluster_quadric.h"
#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <cstdint>
#include <vector>

namespace quadlod::protect_detail {

/// The measured defaults of SimplifyOptions::protect_strength and protect_importance
/// (docs/protect.md, "Partial weights").
inline constexpr double kDefaultStrength = 16.0;
inline constexpr double kDefaultImportance = 50.0;

/// 1 for the vertices of weight 1 (protected), else 0.
std::vector<std::uint8_t> protected_flags(const std::vector<double>& weights);

/// Adds strength · w · h² · |x − p_v|² to the quadric of every vertex v of weight w > 0 (h =
/// quadrics.mean_edge): the selection's price and the collapse's placement, which share these
/// quadrics, then charge a collapse for moving the vertex.
void add_protect_quadrics(VertexQuadrics& quadrics, const PolyMesh& mesh, const std::vector<double>& weights,
                          double strength);

/// Marks in `pinned` (sized to the edges, or empty: then sized here) every edge between two
/// protected vertices; returns how many it added.
Index pin_protected_edges(const Connectivity& conn, const std::vector<std::uint8_t>& flags,
                          std::vector<std::uint8_t>& pinned);

/// importance · max(w_a, w_b) per edge (SelectionParams::extra_importance).
std::vector<double> protect_edge_importance(const Connectivity& conn, const std::vector<double>& weights,
                                            double importance);

/// The weights of a pass's output vertices: each the largest weight of the input vertices
/// `vertex_map` sends to it (input vertex → output vertex or kInvalidIndex).
std::vector<double> carry_protect_weights(const std::vector<double>& weights, const std::vector<Index>& vertex_map,
                                          Index output_vertices);

}  // namespace quadlod::protect_detail
