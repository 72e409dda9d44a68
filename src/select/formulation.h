// The MIP models of the edge selection (paper §3.2, Eqs. 1–9; internal to the selection stage,
// whose interface is src/select/selection.h): ModelBuilder builds the exact or the fast
// formulation over the decision groups of src/select/groups.h, for the whole mesh or one
// neighbourhood; solve_model() runs a backend on a built model and neighbourhood_search() is the
// large-neighbourhood search (SelectionParams::Strategy). docs/formulation.md has the derivations.
#pragma once

#include "ilp/model.h"
#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "select/groups.h"
#include "select/selection.h"
#include "topology/analysis.h"

#include <cstdint>
#include <vector>

namespace quadlod::select_detail {

using ilp::Col;
using ilp::Term;

// ------------------------------------------------------------------------------------------
// Where each group appears, so that a neighbourhood model touches only what its free groups touch
// instead of scanning every face and cluster (ModelBuilder::set_scope with an index).
struct ScopeIndex {
  std::vector<Index> face_offsets, faces;    // group → faces with an edge in it
  std::vector<Index> split_offsets, splits;  // group → ids into GroupConstraints::split_pairs
  std::vector<Index> tri_offsets, tri_pairs; // Eq. 7 cluster → ids into tri_neighbours (either end)
};

ScopeIndex make_scope_index(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg);

// ------------------------------------------------------------------------------------------
// The model. Columns are created in a fixed order so that the greedy start can be completed
// into a full solution vector by evaluating the same definitions.
class ModelBuilder {
 public:
  ModelBuilder(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
               const Groups& groups, const GroupConstraints& gc, const FaceGroups& fg,
               const std::vector<double>& importance, const SelectionParams& params)
      : mesh_(mesh), conn_(conn), analysis_(analysis), g_(groups), gc_(gc), fg_(fg),
        importance_(importance), params_(params) {}

  /// Restricts the model to a neighbourhood (fast formulation only): groups with free[g] = 0
  /// are fixed to base[g]; faces and clusters that touch no free group become constants.
  void set_scope(const std::vector<std::uint8_t>& free, const std::vector<std::uint8_t>& base) {
    free_ = &free;
    base_ = &base;
  }
  /// The same through `index`: only the faces, clusters and pairs of the free groups (the sorted
  /// `free_list`, i.e. free[g] = 1) are visited, and fixed groups get a column only where such a
  /// row needs one. `base_count` = N' of `base`. Gives the model of the scan above up to the
  /// fixed columns no row uses (tests/test_formulation.cpp checks this).
  void set_scope(const std::vector<std::uint8_t>& free, const std::vector<std::uint8_t>& base,
                 const ScopeIndex& index, const std::vector<Index>& free_list, std::uint64_t base_count) {
    set_scope(free, base);
    index_ = &index;
    free_list_ = &free_list;
    base_count_ = base_count;
  }

  // `band`: Eq. 2 (|N' − N| ≤ ϵ_N N); otherwise |N' − N| ≤ open_slack.
  void build(std::uint64_t target, bool band, double open_slack = ilp::kInf);

  /// The full column vector for a group assignment.
  std::vector<double> complete(const std::vector<std::uint8_t>& y, std::uint64_t target) const;

  /// Group values of a fast-formulation solution (rounded).
  std::vector<std::uint8_t> group_bits(const std::vector<double>& x) const;
  /// Writes the free groups' values of a neighbourhood solution into y.
  void read_free_groups(const std::vector<double>& x, std::vector<std::uint8_t>& y) const;

  /// Group values back from a solution (rounded).
  std::vector<std::uint8_t> edge_bits(const std::vector<double>& x) const;

  ilp::Model model;
  SelectionModelStats stats;

 private:
  static constexpr Col kNone = ~Col{0};
  struct Aggregate {
    Col owner, w;
    double constant = 0, upper = 0;
    std::vector<Term> rest;
  };
  struct GeneralFace {
    Col xf = kNone, t = kNone;
    std::vector<Term> terms;
  };
  struct GeoCluster {
    Col var;
    std::vector<Col> cols;
  };
  struct SplitPair {
    Col d, a, b;
  };
  struct TriCluster {
    Col var;
    std::vector<Col> cols;
  };

  Col edge_col(Index e) { return exact_ ? edge_col_[e] : group_col(g_.edge_group[e]); }

  // The column of a group; with an index scope, fixed groups get theirs when first used.
  Col group_col(Index grp) {
    if (group_col_[grp] == kNone) add_group_col(grp);
    return group_col_[grp];
  }
  void add_group_col(Index grp);

  // The parts of the model (formulation.cpp has what each one builds).
  void build_fast_vars();
  void build_exact_vars();
  std::vector<Term> face_terms(Index f);
  void build_faces();
  bool face_touches_free(Index f) const;
  double group_size(Col col) const;
  void add_general_face(const std::vector<Term>& terms, double k);
  void build_count(std::uint64_t target, double slack);
  void add_split(Col a, Col b);
  void build_split_pairs();
  void build_geo_clusters();
  void build_tri_clusters();

  const PolyMesh& mesh_;
  const Connectivity& conn_;
  const AnalysisResult& analysis_;
  const Groups& g_;
  const GroupConstraints& gc_;
  const FaceGroups& fg_;
  const std::vector<double>& importance_;
  const SelectionParams& params_;
  bool exact_ = false;
  const std::vector<std::uint8_t>* free_ = nullptr;
  const std::vector<std::uint8_t>* base_ = nullptr;
  const ScopeIndex* index_ = nullptr;
  const std::vector<Index>* free_list_ = nullptr;
  std::uint64_t base_count_ = 0;
  std::vector<Index> col_group_;  // column → group (kInvalidIndex for other columns)
  std::vector<Col> group_col_, edge_col_;
  std::vector<Term> count_terms_;
  double count_constant_ = 0.0;
  std::vector<Aggregate> aggregates_;
  std::vector<GeneralFace> general_;
  std::vector<GeoCluster> geo_;
  std::vector<SplitPair> split_;
  std::vector<TriCluster> tri_;
  Col p_ = kNone, q_ = kNone;
};

// ------------------------------------------------------------------------------------------
// Solving the models (select_edges() calls these after its searches).

// One solve of a built model (a whole-model MIP: the banded model of phase 1 or the open one of
// phase 2) by params.solver for `seconds`, with the model's initial solution as cutoff or MIP
// start (SelectionParams::greedy_as_mip_start). Fills result.solve (without the solution
// vector), solver_ran and seconds_solve, or result.note when the backend is unknown; returns the
// solution vector (empty if none).
std::vector<double> solve_model(const ilp::Model& model, const SelectionParams& params, double seconds,
                                SelectionResult& result);

// Large-neighbourhood search (SelectionParams::Strategy) from the selection y (group bits, N' in
// Eq. 2's band) for `seconds`: neighbourhood MIPs of the fast model, everything outside fixed at
// the incumbent, each improvement kept (neighbourhoods.cpp). Fills the neighbourhood statistics
// of `result` and result.solve (a summary); returns the group bits it ends at.
std::vector<std::uint8_t> neighbourhood_search(const PolyMesh& mesh, const Connectivity& conn,
                                               const AnalysisResult& analysis, const Groups& groups,
                                               const GroupConstraints& gc, const FaceGroups& fg,
                                               const std::vector<double>& importance,
                                               const std::vector<Index>& adj_offsets,
                                               const std::vector<Index>& adjacent, std::uint64_t target,
                                               const SelectionParams& params, std::vector<std::uint8_t> y,
                                               double seconds, SelectionResult& result);

}  // namespace quadlod::select_detail
