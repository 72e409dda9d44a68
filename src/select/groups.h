// The decision space of the edge selection (paper §3.2; internal to src/select/ and the model
// builder of src/select/formulation.cpp): decision groups (Eq. 4), the geometric constraints of
// Eqs. 6–8 and the face terms of Eq. 1 in group space, the incremental SelectionState every
// search works on, and Eq. 1 / Eq. 9 evaluated on group bits.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "select/selection.h"
#include "topology/analysis.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace quadlod::select_detail {

// ------------------------------------------------------------------------------------------
// Decision groups: the units the greedy and the fast model decide on. With consistency (Eq. 4)
// a group is the union of the opposing edges of segments that share an edge (only non-manifold
// edges are shared); without it, and for edges of no quad, every edge is its own group.
struct Groups {
  Index count = 0;
  std::vector<Index> edge_group;
  std::vector<Index> offsets, edges;   // CSR group → edges
  std::vector<std::uint8_t> fixed;     // 1: must be kept
  std::vector<double> importance;      // Σ Q̂(e) over the group's edges
};

Groups make_groups(const Connectivity& conn, const AnalysisResult& analysis,
                   const std::vector<double>& importance, const SelectionParams& params);

// Distinct groups of a list of edges, sorted.
std::vector<Index> distinct_groups(const Groups& g, const std::vector<Index>& edges);

// Geometric constraints (Eqs. 6–8) in terms of groups, shared by the greedy and the fast model.
struct GroupConstraints {
  std::vector<std::vector<Index>> geo;  // per Eq. 6 cluster: its groups (clusters with a fixed group dropped)
  std::vector<std::vector<Index>> tri;  // per Eq. 7 cluster: its groups
  std::vector<std::pair<Index, Index>> tri_neighbours;
  std::vector<std::vector<Index>> group_geo, group_tri;  // inverse lists
  // λ_tri term: opposite edges of a quad in different groups (one pair per quad side pair);
  // group_split lists, per group, the partner group of each such pair it is in.
  std::vector<std::pair<Index, Index>> split_pairs;
  std::vector<std::vector<Index>> group_split;
};

// Opposite edges (corners c and c + 2) of every quad, as edge pairs.
template <class F>
void for_each_opposite_pair(const PolyMesh& mesh, const Connectivity& conn, F&& f) {
  for (Index face = 0; face < mesh.num_faces(); ++face) {
    if (mesh.face_size(face) != 4) continue;
    const Index b = mesh.face_begin(face);
    for (Index k = 0; k < 2; ++k) f(conn.corner_edge[b + k], conn.corner_edge[b + k + 2]);
  }
}

GroupConstraints make_group_constraints(const PolyMesh& mesh, const Connectivity& conn, const Groups& g,
                                        const AnalysisResult& analysis, const SelectionParams& params);

// ------------------------------------------------------------------------------------------
// Face terms in group space.
struct FaceGroups {
  std::vector<Index> offsets, group, mult;  // CSR face → (group, multiplicity)
  std::vector<Index> degree;
};

FaceGroups make_face_groups(const PolyMesh& mesh, const Connectivity& conn, const Groups& g);

// t_f = max(0, S_f − 2) for the current group values.
inline Index face_count(const FaceGroups& fg, Index f, const std::vector<std::uint8_t>& y) {
  Index kept = 0;
  for (Index i = fg.offsets[f]; i < fg.offsets[f + 1]; ++i) kept += y[fg.group[i]] * fg.mult[i];
  return kept > 2 ? kept - 2 : 0;
}

// ------------------------------------------------------------------------------------------
// The incremental state the greedy and the flip search work on: group bits, N', kept groups per
// Eq. 6 cluster, collapsed groups per Eq. 7 cluster, and the group → faces index for the count.
class SelectionState {
 public:
  SelectionState(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg, std::vector<std::uint8_t> bits);

  /// Change of N' (Eq. 1) if grp flips: per face of grp, t_f = max(0, S_f − 2) with grp's
  /// multiplicity m added to or removed from S_f.
  std::int64_t delta_count(Index grp) const {
    std::int64_t d = 0;
    const std::int64_t sign = y[grp] ? -1 : 1;
    for (Index k = face_offsets_[grp]; k < face_offsets_[grp + 1]; ++k) {
      const std::int64_t kept = face_kept_[faces_[k]], after = kept + sign * face_mult_[k];
      d += (after > 2 ? after - 2 : 0) - (kept > 2 ? kept - 2 : 0);
    }
    return d;
  }
  /// Change of Eq. 9 without the count term if grp flips: λ_edge Q, λ_geo when grp is the last
  /// kept group of a cluster (or the first kept again), λ_tri per quad side pair split or mended.
  double delta_rest(Index grp, const SelectionParams& params) const {
    const bool collapse = y[grp];
    double d = (collapse ? 1.0 : -1.0) * params.lambda_edge * g_.importance[grp];
    for (Index k = geo_offsets_[grp]; k < geo_offsets_[grp + 1]; ++k) {
      const Index cl = geo_[k];
      if (collapse && geo_kept_[cl] == 1) d += params.lambda_geo;
      if (!collapse && geo_kept_[cl] == 0) d -= params.lambda_geo;
    }
    for (Index k = split_offsets_[grp]; k < split_offsets_[grp + 1]; ++k)
      d += (y[split_[k]] == y[grp]) ? params.lambda_tri : -params.lambda_tri;
    return d;
  }
  /// Eq. 8 for collapsing grp: a cluster that loses an edge needs every neighbour untouched, and
  /// grp must not belong to such a neighbour (keeping a group never breaks Eq. 8).
  bool may_collapse(Index grp) const {
    if (never_collapse_[grp]) return false;
    for (Index k = blocking_offsets_[grp]; k < blocking_offsets_[grp + 1]; ++k)
      if (tri_collapsed_[blocking_[k]] > 0) return false;
    return true;
  }
  /// Flips grp; `dc` = delta_count(grp).
  void flip(Index grp, std::int64_t dc) {
    const bool collapse = y[grp];
    y[grp] ^= 1;
    count += dc;
    const Index sign = collapse ? Index(-1) : 1;
    for (Index k = face_offsets_[grp]; k < face_offsets_[grp + 1]; ++k) face_kept_[faces_[k]] += sign * face_mult_[k];
    for (Index k = geo_offsets_[grp]; k < geo_offsets_[grp + 1]; ++k) geo_kept_[geo_[k]] += sign;
    for (Index k = tri_offsets_[grp]; k < tri_offsets_[grp + 1]; ++k) tri_collapsed_[tri_[k]] -= sign;
  }

  std::vector<std::uint8_t> y;
  std::int64_t count = 0;

 private:
  const Groups& g_;
  std::vector<Index> face_offsets_, faces_, face_mult_, face_kept_;
  std::vector<Index> geo_offsets_, geo_, split_offsets_, split_, tri_offsets_, tri_;
  std::vector<Index> blocking_offsets_, blocking_;
  std::vector<std::uint8_t> never_collapse_;
  std::vector<Index> geo_kept_, tri_collapsed_;
};

// ------------------------------------------------------------------------------------------
// Eq. 1 and Eq. 9 on group bits.

Index count_collapsed_clusters(const GroupConstraints& gc, const std::vector<std::uint8_t>& y);

// The slope of the count term |N' − N| (Eq. 9) that prices start from, for d = N' − N: 0 in the
// middle of Eq. 2's band, ±1 in its outer halves, where one direction is closed.
double count_slope(std::int64_t d, std::int64_t band);

// N' (Eq. 1) of y.
std::uint64_t selection_count(const FaceGroups& fg, const std::vector<std::uint8_t>& y);

// Eq. 9 in group space — what the banded fast model evaluates to for the completion of y:
// |N' − N| + λ_geo · (clusters with every group collapsed) − λ_edge · Σ Q̂ y.
double group_objective(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                       const std::vector<std::uint8_t>& y, std::uint64_t target,
                       const SelectionParams& params);

// Groups that share a face, as CSR.
void group_adjacency(const Groups& g, const FaceGroups& fg, std::vector<Index>& offsets,
                     std::vector<Index>& adjacent);

// The components of the free groups that share no term of Eq. 9 and no constraint (the
// recombination in recombine.cpp explains why only the count row couples them).
struct FreeComponents {
  Index count = 0;
  std::vector<Index> of_group;         // kInvalidIndex for fixed groups
  std::vector<Index> offsets, groups;  // CSR component → groups
};

FreeComponents free_components(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg);

// ------------------------------------------------------------------------------------------
// The decision space of one selection given as edge bits, for the test entry points of
// selection.h (namespace detail).
struct Prepared {
  std::vector<double> importance;
  Groups groups;
  GroupConstraints gc;
  FaceGroups fg;
  std::vector<std::uint8_t> y;
  std::vector<Index> adj_offsets, adjacent;  // group_adjacency, after with_adjacency()

  void with_adjacency() { group_adjacency(groups, fg, adj_offsets, adjacent); }
  // Per-group bits back to per-edge bits.
  std::vector<std::uint8_t> edge_bits(const Connectivity& conn, const std::vector<std::uint8_t>& bits) const {
    std::vector<std::uint8_t> kept(conn.num_edges);
    for (Index e = 0; e < conn.num_edges; ++e) kept[e] = bits[groups.edge_group[e]];
    return kept;
  }
};
Prepared prepare(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                 const SelectionParams& params, const std::vector<std::uint8_t>& edge_kept);

}  // namespace quadlod::select_detail
