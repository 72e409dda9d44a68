// Global edge selection, paper §3.2 (Eqs. 1–9). See select/selection.h for the two formulations and
// docs/formulation.md for the derivations and the choices where the paper is ambiguous.
//
// Face count (Eq. 1). A face f of k corners whose kept edges number S_f becomes a face of S_f
// corners when S_f ≥ 3 and vanishes otherwise (Eq. 3 makes x_f = [S_f ≥ 3]), so its
// triangle-equivalent count is
//     t_f = x_f · (S_f − 2) = max(0, S_f − 2)                    (quad: 4 → 2, 3 → 1, ≤ 2 → 0)
// which the paper's |F_tri| + 2|F_quad| is for triangles and quads.
//
// Fast face terms. With edges grouped (all opposing edges of a segment share one variable y_g),
// most quads have both opposite pairs in single groups a and b:
//
//        b ────────── b          S_f = 2y_a + 2y_b,   t_f = 2·y_a·y_b
//        │            │
//        a    quad    a          More generally, if one group a covers m_a ≥ 2 of the k ≥ 4
//        │            │          edges and the rest R (≤ 2 edges) is linear, then
//        b ────────── b          t_f = y_a · (m_a − 2 + R)          (y_a = 0 ⇒ S_f = R ≤ 2 ⇒ 0)
//
// so all faces "owned" by group a contribute y_a · S_a with S_a = Σ (m_a − 2 + R) ≤ U_a = Σ (k−2),
// one product per group linearised by three rows (McCormick, exact for binary y_a):
//     w_a ≤ U_a y_a,   w_a ≤ S_a,   w_a ≥ S_a − U_a (1 − y_a).
// That replaces three rows per quad by three rows per group. Faces of one group are linear,
// triangles of several groups get an AND variable, and the rest (quads cut by breakpoints on both
// pairs, n-gons) get the paper's per-face rows.
#include "select/selection.h"

#include "select/anneal.h"
#include "select/greedy.h"
#include "select/groups.h"
#include "select/moves.h"
#include "select/recombine.h"
#include "util/progress.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <queue>
#include <random>
#include <thread>

namespace quadlod {

using ilp::Col;
using ilp::Term;
using namespace select_detail;

namespace {

// ------------------------------------------------------------------------------------------
// Where each group appears, so that a neighbourhood model touches only what its free groups touch
// instead of scanning every face and cluster (ModelBuilder::set_scope with an index).
struct ScopeIndex {
  std::vector<Index> face_offsets, faces;    // group → faces with an edge in it
  std::vector<Index> split_offsets, splits;  // group → ids into GroupConstraints::split_pairs
  std::vector<Index> tri_offsets, tri_pairs; // Eq. 7 cluster → ids into tri_neighbours (either end)
};

// CSR from (key, value) pairs, keys < n.
void make_csr(Index n, const std::vector<std::pair<Index, Index>>& pairs, std::vector<Index>& offsets,
              std::vector<Index>& values) {
  offsets.assign(std::size_t{n} + 1, 0);
  for (const auto& kv : pairs) ++offsets[kv.first + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  values.resize(pairs.size());
  std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
  for (const auto& [k, v] : pairs) values[fill[k]++] = v;
}

ScopeIndex make_scope_index(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg) {
  ScopeIndex ix;
  std::vector<std::pair<Index, Index>> pairs;
  for (Index f = 0; f + 1 < fg.offsets.size(); ++f)
    for (Index i = fg.offsets[f]; i < fg.offsets[f + 1]; ++i) pairs.emplace_back(fg.group[i], f);
  make_csr(g.count, pairs, ix.face_offsets, ix.faces);
  pairs.clear();
  for (Index k = 0; k < gc.split_pairs.size(); ++k) {
    pairs.emplace_back(gc.split_pairs[k].first, k);
    pairs.emplace_back(gc.split_pairs[k].second, k);
  }
  make_csr(g.count, pairs, ix.split_offsets, ix.splits);
  pairs.clear();
  for (Index k = 0; k < gc.tri_neighbours.size(); ++k) {
    pairs.emplace_back(gc.tri_neighbours[k].first, k);
    if (gc.tri_neighbours[k].second != gc.tri_neighbours[k].first) pairs.emplace_back(gc.tri_neighbours[k].second, k);
  }
  make_csr(static_cast<Index>(gc.tri.size()), pairs, ix.tri_offsets, ix.tri_pairs);
  return ix;
}

// Sorted distinct values of lists[key] over the keys.
std::vector<Index> gather(const std::vector<Index>& keys, const std::vector<Index>& offsets,
                          const std::vector<Index>& values) {
  std::vector<Index> out;
  for (Index k : keys) out.insert(out.end(), values.begin() + offsets[k], values.begin() + offsets[k + 1]);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

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
  void build(std::uint64_t target, bool band, double open_slack = ilp::kInf) {
    exact_ = params_.formulation == Formulation::Exact;
    if (exact_) build_exact_vars();
    else build_fast_vars();
    build_faces();
    build_count(target, band ? params_.epsilon_n * double(target) : open_slack);
    if (params_.lambda_tri > 0.0) build_split_pairs();
    if (params_.geometry) {
      build_geo_clusters();
      build_tri_clusters();
    }
  }

  /// The full column vector for a group assignment.
  std::vector<double> complete(const std::vector<std::uint8_t>& y, std::uint64_t target) const {
    std::vector<double> x(model.num_cols(), 0.0);
    auto value_of_col = [&](Col c) { return x[c]; };
    if (exact_) {
      for (Index e = 0; e < conn_.num_edges; ++e) x[edge_col_[e]] = y[g_.edge_group[e]];
    } else {
      for (Col c = 0; c < col_group_.size(); ++c)
        if (col_group_[c] != kInvalidIndex) x[c] = y[col_group_[c]];
    }
    (void)value_of_col;
    for (const Aggregate& a : aggregates_) {
      double s = a.constant;
      for (const Term& t : a.rest) s += t.coef * x[t.col];
      x[a.w] = x[a.owner] * s;
    }
    for (const GeneralFace& gf : general_) {
      double s = 0;
      for (const Term& t : gf.terms) s += t.coef * x[t.col];
      if (gf.xf != kNone) x[gf.xf] = s >= 3.0 - 1e-9 ? 1.0 : 0.0;
      x[gf.t] = std::max(0.0, s - 2.0);
    }
    double count = 0;
    for (const Term& t : count_terms_) count += t.coef * x[t.col];
    count += count_constant_;
    const double diff = count - double(target);
    x[p_] = std::max(0.0, diff);
    x[q_] = std::max(0.0, -diff);
    for (const SplitPair& sp : split_) x[sp.d] = std::abs(x[sp.a] - x[sp.b]);
    for (const GeoCluster& c : geo_) {
      bool all_collapsed = true;
      for (Col col : c.cols) all_collapsed &= x[col] < 0.5;
      x[c.var] = all_collapsed ? 1.0 : 0.0;
    }
    for (const TriCluster& c : tri_) {
      if (c.var == kNone) continue;
      bool any_collapsed = false;
      for (Col col : c.cols) any_collapsed |= x[col] < 0.5;
      x[c.var] = any_collapsed ? 1.0 : 0.0;
    }
    return x;
  }

  /// Group values of a fast-formulation solution (rounded).
  std::vector<std::uint8_t> group_bits(const std::vector<double>& x) const {
    std::vector<std::uint8_t> y(g_.count);
    for (Index grp = 0; grp < g_.count; ++grp) y[grp] = x[group_col_[grp]] > 0.5;
    return y;
  }
  /// Writes the free groups' values of a neighbourhood solution into y.
  void read_free_groups(const std::vector<double>& x, std::vector<std::uint8_t>& y) const {
    for (Col c = 0; c < col_group_.size(); ++c)
      if (col_group_[c] != kInvalidIndex && (*free_)[col_group_[c]]) y[col_group_[c]] = x[c] > 0.5;
  }

  /// Group values back from a solution (rounded).
  std::vector<std::uint8_t> edge_bits(const std::vector<double>& x) const {
    std::vector<std::uint8_t> kept(conn_.num_edges);
    for (Index e = 0; e < conn_.num_edges; ++e)
      kept[e] = x[exact_ ? edge_col_[e] : group_col_[g_.edge_group[e]]] > 0.5;
    return kept;
  }

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
  void add_group_col(Index grp) {
    double lo = g_.fixed[grp] ? 1.0 : 0.0, hi = 1.0;
    if (free_ && !(*free_)[grp]) lo = hi = (*base_)[grp];
    group_col_[grp] = model.add_var(ilp::VarType::Binary, lo, hi, -params_.lambda_edge * g_.importance[grp]);
    col_group_.resize(model.num_cols(), kInvalidIndex);
    col_group_[group_col_[grp]] = grp;
  }

  void build_fast_vars() {
    group_col_.assign(g_.count, kNone);
    if (index_) {
      for (Index grp : *free_list_) add_group_col(grp);
    } else {
      for (Index grp = 0; grp < g_.count; ++grp) add_group_col(grp);
    }
    stats.edge_groups = g_.count;
    stats.fixed_kept_groups = static_cast<Index>(std::count(g_.fixed.begin(), g_.fixed.end(), 1));
  }

  void build_exact_vars() {
    edge_col_.resize(conn_.num_edges);
    for (Index e = 0; e < conn_.num_edges; ++e) {
      const double lo = g_.fixed[g_.edge_group[e]] ? 1.0 : 0.0;
      edge_col_[e] = model.add_var(ilp::VarType::Binary, lo, 1.0, -params_.lambda_edge * importance_[e]);
    }
    stats.edge_groups = conn_.num_edges;
    // Eq. 4: x_e = x_e' within every segment.
    if (params_.consistency)
      for (const Segment& s : analysis_.segmentation.segments)
        for (std::size_t i = 1; i < s.opposing_edges.size(); ++i)
          model.add_eq({{edge_col_[s.opposing_edges[i]], 1.0}, {edge_col_[s.opposing_edges[0]], -1.0}}, 0.0);
  }

  // Terms Σ m x over the face's columns (merged per column).
  std::vector<Term> face_terms(Index f) {
    std::vector<Term> terms;
    for (Index c = mesh_.face_begin(f); c < mesh_.face_end(f); ++c) {
      const Col col = edge_col(conn_.corner_edge[c]);
      auto it = std::find_if(terms.begin(), terms.end(), [&](const Term& t) { return t.col == col; });
      if (it == terms.end()) terms.push_back({col, 1.0});
      else it->coef += 1.0;
    }
    return terms;
  }

  void build_faces() {
    std::vector<std::vector<Term>> owner_rest(model.num_cols());
    std::vector<double> owner_constant(model.num_cols(), 0.0), owner_upper(model.num_cols(), 0.0);
    std::vector<Index> owned(model.num_cols(), 0);
    std::vector<Index> scoped;  // with an index: the faces of the free groups
    if (index_) {
      scoped = gather(*free_list_, index_->face_offsets, index_->faces);
      count_constant_ = double(base_count_);
      for (Index f : scoped) count_constant_ -= double(face_count(fg_, f, *base_));
    }
    const Index face_end = index_ ? static_cast<Index>(scoped.size()) : mesh_.num_faces();
    for (Index fi = 0; fi < face_end; ++fi) {
      const Index f = index_ ? scoped[fi] : fi;
      if (free_ && !index_ && !face_touches_free(f)) {
        count_constant_ += double(face_count(fg_, f, *base_));
        continue;
      }
      const double k = mesh_.face_size(f);
      std::vector<Term> terms = face_terms(f);
      if (owned.size() < model.num_cols()) {  // fixed groups' columns made on the way
        owner_rest.resize(model.num_cols());
        owner_constant.resize(model.num_cols(), 0.0);
        owner_upper.resize(model.num_cols(), 0.0);
        owned.resize(model.num_cols(), 0);
      }
      if (!exact_) {
        if (terms.size() == 1) {  // one group: t_f = (k − 2) y
          count_terms_.push_back({terms[0].col, k - 2.0});
          ++stats.linear_faces;
          continue;
        }
        // Owner: a group with m ≥ 2 and at most two other edges; prefer the larger group.
        Col owner = kNone;
        double owner_mult = 0;
        for (const Term& t : terms)
          if (t.coef >= 2.0 && k - t.coef <= 2.0 && k >= 4 &&
              (owner == kNone || group_size(t.col) > group_size(owner))) {
            owner = t.col;
            owner_mult = t.coef;
          }
        if (owner != kNone) {
          for (const Term& t : terms)
            if (t.col != owner) owner_rest[owner].push_back(t);
          owner_constant[owner] += owner_mult - 2.0;
          owner_upper[owner] += k - 2.0;
          ++owned[owner];
          continue;
        }
        if (k == 3) {  // triangle over several groups: z = AND (continuous, exact for binary y)
          const Col z = model.add_continuous(0.0, 1.0);
          double s = 0;
          for (const Term& t : terms) {
            model.add_le({{z, t.coef}, {t.col, -t.coef}}, 0.0);  // m z ≤ m y
            s += t.coef;
          }
          std::vector<Term> row = terms;
          row.push_back({z, -1.0});
          model.add_le(row, 2.0);  // z ≥ S − 2
          general_.push_back({kNone, z, terms});
          count_terms_.push_back({z, 1.0});
          ++stats.triangle_faces;
          continue;
        }
      }
      add_general_face(terms, k);
    }
    // Aggregates in group order (the column order of the scan), whatever order the columns got.
    std::vector<Col> owners;
    for (Col c = 0; c < owned.size(); ++c)
      if (owned[c]) owners.push_back(c);
    std::sort(owners.begin(), owners.end(), [&](Col l, Col r) { return col_group_[l] < col_group_[r]; });
    for (Col owner : owners) {
      Aggregate a;
      a.owner = owner;
      a.constant = owner_constant[owner];
      a.upper = owner_upper[owner];
      a.rest = std::move(owner_rest[owner]);
      // Merge rest terms per column.
      std::sort(a.rest.begin(), a.rest.end(), [](const Term& l, const Term& r) { return l.col < r.col; });
      std::vector<Term> merged;
      for (const Term& t : a.rest) {
        if (!merged.empty() && merged.back().col == t.col) merged.back().coef += t.coef;
        else merged.push_back(t);
      }
      a.rest = std::move(merged);
      a.w = model.add_continuous(0.0, a.upper);
      // w ≤ U y
      model.add_le({{a.w, 1.0}, {owner, -a.upper}}, 0.0);
      // w ≤ S = constant + rest
      std::vector<Term> row = a.rest;
      for (Term& t : row) t.coef = -t.coef;
      row.push_back({a.w, 1.0});
      model.add_le(row, a.constant);
      // w ≥ S − U(1 − y)  ⇔  w − rest − U y ≥ constant − U
      row.push_back({owner, -a.upper});
      model.add_ge(row, a.constant - a.upper);
      count_terms_.push_back({a.w, 1.0});
      aggregates_.push_back(std::move(a));
      ++stats.owner_aggregates;
    }
  }

  bool face_touches_free(Index f) const {
    for (Index i = fg_.offsets[f]; i < fg_.offsets[f + 1]; ++i)
      if ((*free_)[fg_.group[i]]) return true;
    return false;
  }

  double group_size(Col col) const {
    const Index grp = col < col_group_.size() ? col_group_[col] : kInvalidIndex;
    return grp != kInvalidIndex ? double(g_.offsets[grp + 1] - g_.offsets[grp]) : 0.0;
  }

  // The paper's per-face rows: Eq. 3 and t_f = x_f (S_f − 2) linearised.
  void add_general_face(const std::vector<Term>& terms, double k) {
    GeneralFace gf;
    gf.terms = terms;
    gf.xf = model.add_binary();
    gf.t = model.add_continuous(0.0, k - 2.0);
    std::vector<Term> row = terms;
    row.push_back({gf.xf, -3.0});
    model.add_ge(row, 0.0);  // Eq. 3: S ≥ 3 x_f
    row.back().coef = -(k - 2.0);
    model.add_le(row, 2.0);  // Eq. 3: S − 2 ≤ (k − 2) x_f   (the paper's 4 x_f for quads)
    model.add_le({{gf.t, 1.0}, {gf.xf, -(k - 2.0)}}, 0.0);  // t ≤ (k − 2) x_f
    row = terms;
    for (Term& t : row) t.coef = -t.coef;
    row.push_back({gf.t, 1.0});
    model.add_ge(row, -2.0);  // t ≥ S − 2
    row.push_back({gf.xf, 2.0});
    model.add_le(row, 0.0);   // t ≤ S − 2 x_f
    count_terms_.push_back({gf.t, 1.0});
    general_.push_back(std::move(gf));
    ++stats.general_faces;
  }

  // Eqs. 1–2 and the |N' − N| term of Eq. 9: N' − p + q = N with p, q ≥ 0 in the objective;
  // the band of Eq. 2 is p, q ≤ ϵ_N N (bounds, no extra row).
  void build_count(std::uint64_t target, double slack) {
    const double n = double(target);
    p_ = model.add_continuous(0.0, slack, 1.0);
    q_ = model.add_continuous(0.0, slack, 1.0);
    std::vector<Term> row = count_terms_;
    row.push_back({p_, -1.0});
    row.push_back({q_, 1.0});
    model.add_eq(row, n - count_constant_);
  }

  // λ_tri term (beyond the paper): d ≥ |x_a − x_b| for opposite quad edges decided apart (only
  // the binding side: d is minimised). Exact: per edge pair across a segment boundary; fast: per
  // group pair (a quad side pair whose edges lie in two groups).
  void add_split(Col a, Col b) {
    const Col d = model.add_continuous(0.0, 1.0, params_.lambda_tri);
    model.add_ge({{d, 1.0}, {a, -1.0}, {b, 1.0}}, 0.0);
    model.add_ge({{d, 1.0}, {a, 1.0}, {b, -1.0}}, 0.0);
    split_.push_back({d, a, b});
  }
  void build_split_pairs() {
    if (exact_) {
      for_each_opposite_pair(mesh_, conn_, [&](Index e, Index f) {
        const Index a = g_.edge_group[e], b = g_.edge_group[f];
        if (a != b && !(g_.fixed[a] && g_.fixed[b])) add_split(edge_col_[e], edge_col_[f]);
      });
    } else {
      if (index_) {
        for (Index k : gather(*free_list_, index_->split_offsets, index_->splits))
          add_split(group_col(gc_.split_pairs[k].first), group_col(gc_.split_pairs[k].second));
      } else {
        for (const auto& [a, b] : gc_.split_pairs)
          if (!free_ || (*free_)[a] || (*free_)[b]) add_split(group_col(a), group_col(b));
      }
    }
    stats.split_pairs = static_cast<Index>(split_.size());
  }

  // Eq. 6: x_C = 1 iff every edge of cluster C is collapsed; λ_geo x_C in the objective.
  void build_geo_clusters() {
    if (exact_) {
      for (const EdgeCluster& cluster : analysis_.medial.clusters) {
        std::vector<Col> cols;
        for (Index e : cluster.edges) cols.push_back(edge_col_[e]);
        std::sort(cols.begin(), cols.end());
        cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
        const Col xc = model.add_continuous(0.0, 1.0, params_.lambda_geo);
        std::vector<Term> row{{xc, 1.0}};
        for (Col c : cols) {
          model.add_le({{xc, 1.0}, {c, 1.0}}, 1.0);  // x_C ≤ 1 − x_e
          row.push_back({c, 1.0});
        }
        model.add_ge(row, 1.0);  // x_C ≥ 1 − Σ x_e
        geo_.push_back({xc, std::move(cols)});
      }
    } else {
      // Only the binding side: with λ_geo > 0 a minimiser never raises x_C above what
      // x_C ≥ 1 − Σ y forces, so x_C ≤ 1 − y rows are redundant at every optimum.
      std::vector<Index> scoped;
      if (index_) {
        for (Index grp : *free_list_) scoped.insert(scoped.end(), gc_.group_geo[grp].begin(), gc_.group_geo[grp].end());
        std::sort(scoped.begin(), scoped.end());
        scoped.erase(std::unique(scoped.begin(), scoped.end()), scoped.end());
      }
      const Index end = index_ ? static_cast<Index>(scoped.size()) : static_cast<Index>(gc_.geo.size());
      for (Index ci = 0; ci < end; ++ci) {
        const auto& groups = gc_.geo[index_ ? scoped[ci] : ci];
        if (free_) {
          // Outside the neighbourhood, or kept by a fixed group: a constant of the objective.
          bool any_free = false, kept = false;
          for (Index grp : groups) {
            any_free |= (*free_)[grp] != 0;
            kept |= !(*free_)[grp] && (*base_)[grp];
          }
          if (!any_free || kept) continue;
        }
        const Col xc = model.add_continuous(0.0, 1.0, params_.lambda_geo);
        std::vector<Term> row{{xc, 1.0}};
        std::vector<Col> cols;
        for (Index grp : groups) {
          row.push_back({group_col(grp), 1.0});
          cols.push_back(group_col(grp));
        }
        model.add_ge(row, 1.0);
        geo_.push_back({xc, std::move(cols)});
      }
    }
    stats.geo_clusters = static_cast<Index>(geo_.size());
  }

  // Eqs. 7–8: x_Ct = 1 iff some edge of C_t is collapsed; then every neighbour keeps all edges.
  void build_tri_clusters() {
    const auto nt = static_cast<Index>(analysis_.triangles.clusters.size());
    const auto& neighbours = analysis_.triangles.neighbours;
    // In a neighbourhood only clusters with a free group and their Eq. 8 partners take part.
    std::vector<std::uint8_t> active(nt, 1), needed(nt, 1);
    std::vector<Index> pairs;  // Eq. 8 pairs with an active end (index scope)
    if (index_) {
      std::fill(active.begin(), active.end(), 0);
      std::fill(needed.begin(), needed.end(), 0);
      std::vector<Index> act;
      for (Index grp : *free_list_) act.insert(act.end(), gc_.group_tri[grp].begin(), gc_.group_tri[grp].end());
      for (Index i : act) active[i] = needed[i] = 1;
      pairs = gather(act, index_->tri_offsets, index_->tri_pairs);
      for (Index k : pairs) needed[neighbours[k].first] = needed[neighbours[k].second] = 1;
    } else if (free_) {
      for (Index i = 0; i < nt; ++i) {
        active[i] = 0;
        for (Index grp : gc_.tri[i]) active[i] |= (*free_)[grp];
      }
      needed = active;
      for (const auto& [i, j] : neighbours)
        if (active[i] || active[j]) needed[i] = needed[j] = 1;
    }
    std::vector<Index> slot(nt, kInvalidIndex);  // cluster → tri_ entry
    for (Index i = 0; i < nt; ++i) {
      if (!needed[i]) continue;
      std::vector<Col> cols;
      for (Index e : analysis_.triangles.clusters[i].edges) cols.push_back(edge_col(e));
      std::sort(cols.begin(), cols.end());
      if (!exact_) cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
      Col var;
      const double size = double(cols.size());
      if (exact_) {
        // The paper's rows; x_Ct binary, because with a continuous x_Ct the first row only
        // forces x_Ct ≥ 1/|C| when one edge is dropped (docs/formulation.md).
        var = model.add_binary();
        std::vector<Term> row{{var, size}};
        for (Col c : cols) row.push_back({c, 1.0});
        model.add_ge(row, size);        // Σ x_e + |C| x_Ct ≥ |C|
        row[0].coef = 1.0;
        model.add_le(row, size);        // x_Ct ≤ |C| − Σ x_e
      } else {
        var = model.add_continuous(0.0, 1.0);
        for (Col c : cols) model.add_ge({{var, 1.0}, {c, 1.0}}, 1.0);  // x_Ct ≥ 1 − y_g
      }
      slot[i] = static_cast<Index>(tri_.size());
      tri_.push_back({var, std::move(cols)});
    }
    auto add_eq8 = [&](Index i, Index j) {
      const auto& cj = tri_[slot[j]].cols;
      std::vector<Term> row{{tri_[slot[i]].var, double(cj.size())}};
      for (Col c : cj) row.push_back({c, -1.0});
      model.add_le(row, 0.0);  // Eq. 8: |C_j| x_Ct(i) ≤ Σ_{e ∈ C_j} x_e
      ++stats.tri_neighbour_rows;
    };
    if (index_) {
      for (Index k : pairs) add_eq8(neighbours[k].first, neighbours[k].second);
    } else {
      for (const auto& [i, j] : neighbours)
        if (active[i] || active[j]) add_eq8(i, j);
    }
    stats.tri_clusters = static_cast<Index>(tri_.size());
  }

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

// Neighbourhoods of one sweep of the large-neighbourhood search: a partition of the free groups
// into regions of `size` groups (the last one smaller). A region grows breadth-first over groups
// that share a face from the first seed in `order` that no region took yet, only over untaken
// groups; when that runs out (a small part of the mesh, or enclosed by earlier regions) it goes
// on from the next untaken seed, so a region may hold several patches — the count row couples
// them anyway. Fixed groups are crossed but never freed. Each region lists its free groups.
std::vector<std::vector<Index>> neighbourhood_partition(const Groups& g, const std::vector<Index>& adj_offsets,
                                                        const std::vector<Index>& adjacent,
                                                        const std::vector<Index>& order, Index size) {
  std::vector<std::vector<Index>> regions;
  std::vector<std::uint8_t> seen(g.count, 0);  // queued by some region
  std::vector<Index> queue, region;
  for (Index seed : order) {
    if (g.fixed[seed] || seen[seed]) continue;
    queue.assign(1, seed);
    seen[seed] = 1;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const Index a = queue[head];
      if (!g.fixed[a]) {
        region.push_back(a);
        if (region.size() >= size) {  // full: groups still queued go back to the pool
          for (std::size_t k = head + 1; k < queue.size(); ++k) seen[queue[k]] = 0;
          break;
        }
      }
      for (Index k = adj_offsets[a]; k < adj_offsets[a + 1]; ++k)
        if (!seen[adjacent[k]]) {
          seen[adjacent[k]] = 1;
          queue.push_back(adjacent[k]);
        }
    }
    if (region.size() >= size) regions.push_back(std::move(region)), region.clear();
  }
  if (!region.empty()) regions.push_back(std::move(region));
  return regions;
}

}  // namespace

SelectionResult select_edges(const PolyMesh& mesh, const Connectivity& conn,
                             const AnalysisResult& analysis, std::uint64_t target,
                             const SelectionParams& params) {
  SelectionResult result;
  Stopwatch clock;
  result.input_tri_equivalent = tri_equivalent_count(mesh);
  result.target = target;
  result.edge_kept.assign(conn.num_edges, 1);
  result.predicted = result.greedy_predicted = result.input_tri_equivalent;
  if (target >= result.input_tri_equivalent) {
    result.note = "target " + std::to_string(target) + " is at or above the input size " +
                  std::to_string(result.input_tri_equivalent) + ": nothing to do";
    result.stop_reason = "nothing to do";
    return result;
  }

  Stopwatch prepare_clock;
  const std::vector<double> importance = edge_importance(mesh, conn, params.importance_cap);
  const Groups groups = make_groups(conn, analysis, importance, params);
  for (double q : importance) result.baseline_objective -= params.lambda_edge * q;
  const GroupConstraints gc = make_group_constraints(mesh, conn, groups, analysis, params);
  const FaceGroups fg = make_face_groups(mesh, conn, groups);
  std::vector<Index> adj_offsets, adjacent;  // groups that share a face
  group_adjacency(groups, fg, adj_offsets, adjacent);
  result.seconds_prepare = prepare_clock.seconds();

  Stopwatch greedy_clock;
  const GreedyResult greedy = greedy_select(groups, gc, fg, target, params);
  result.seconds_greedy = greedy_clock.seconds();
  result.greedy_predicted = greedy.count;
  const double lo = (1.0 - params.epsilon_n) * double(target);
  const double hi = (1.0 + params.epsilon_n) * double(target);
  auto in_band = [&](std::uint64_t c) { return double(c) >= lo && double(c) <= hi; };
  bool reachable = in_band(greedy.count);
  result.seconds_build = 0.0;
  const double time_limit = params.solve.time_limit_seconds;
  const int threads = ilp::backend::resolve_threads(params.solve);

  // The greedy stopped outside the band (fast formulation): an annealing that may leave the
  // greedy's choices looks for the band first (reach_band). Its state nearest the band is the
  // start of everything below, in the band or not.
  std::vector<std::uint8_t> closest = greedy.y;
  if (!reachable && time_limit > 0.0 && params.formulation == Formulation::Fast && params.reach_time_fraction > 0.0) {
    Stopwatch reach_clock;
    AnnealStats rs;
    closest = reach_band(groups, gc, fg, greedy.y, target, params,
                         params.reach_time_fraction * time_limit - clock.seconds(), adj_offsets, adjacent, threads, rs);
    result.reach_ran = true;
    result.reach_moves = rs.moves;
    result.reach_predicted = selection_count(fg, closest);
    result.seconds_reach = reach_clock.seconds();
    reachable = in_band(result.reach_predicted);
  }

  // Phase 1: Eq. 2 as a hard band. The greedy (or reached) selection is the start when it lies
  // in the band; otherwise the solver has to find a feasible point itself, with half of what is
  // left of the budget. Phase 2 (only if phase 1 ends without a solution): no band, the
  // selection nearest the band as start, so the result is the closest count found (reported in
  // `note`).
  auto run = [&](ModelBuilder& builder, double seconds) -> std::vector<double> {
    std::string error;
    auto solver = ilp::make_solver(params.solver, &error);
    if (!solver) {
      result.note = error;
      return {};
    }
    Stopwatch solve_clock;
    ilp::SolveParams sp = params.solve;
    sp.start_as_mip_start = params.greedy_as_mip_start;
    sp.time_limit_seconds = seconds;
    sp.stall_seconds = params.whole_stall_seconds;
    if (!params.quiet && !sp.on_progress)
      sp.on_progress = [](const ilp::Progress& p) {
        std::fprintf(stderr, "\rselect      objective %.4f  bound %.4f  %6.1f s", p.objective,
                     p.best_bound, p.seconds);
        std::fflush(stderr);
      };
    result.solve = solver->solve(builder.model, sp);
    if (!params.quiet) std::fprintf(stderr, "\n");
    result.solver_ran = true;
    result.seconds_solve += solve_clock.seconds();
    std::vector<double> x = std::move(result.solve.solution);
    result.solve.solution.clear();
    return x;
  };

  // Large-neighbourhood search (SelectionParams::Strategy): BFS over groups that share a face
  // collects `neighbourhood_groups` free groups around a seed; the fast model restricted to them
  // (everything else fixed at the incumbent, the greedy selection as cutoff) is solved and an
  // improvement is kept. Seeds sweep the groups in index order; a sweep without improvement ends
  // the search.
  auto neighbourhood_search = [&](std::vector<std::uint8_t> y, double seconds) {
    Stopwatch lns_clock;
    double best = group_objective(groups, gc, fg, y, target, params);
    std::vector<std::uint8_t> free(groups.count, 0);
    Index improved_in_sweep = 0, idle_sweeps = 0;
    ilp::SolveResult summary;
    summary.backend = params.solver;
    summary.call = ilp::CallStatus::Ok;
    auto solver = ilp::make_solver(params.solver, &summary.message);
    if (!solver) return y;
    // Sweep k solves the regions of one partition of the groups (neighbourhood_partition): seeds
    // in index order for the first sweep, in a shuffled order (seeded by k) after that, so the
    // region borders of one sweep lie inside regions of the next. Two sweeps in a row without an
    // improvement end the search.
    std::vector<Index> order(groups.count);
    std::iota(order.begin(), order.end(), Index{0});
    std::vector<std::vector<Index>> regions;
    std::size_t next_region = 0;
    std::mt19937 rng(params.solve.seed);
    const ScopeIndex scope_index = make_scope_index(groups, gc, fg);
    auto count_of = [&](const std::vector<std::uint8_t>& bits) {
      std::uint64_t n = 0;
      for (Index f = 0; f + 1 < fg.offsets.size(); ++f) n += face_count(fg, f, bits);
      return n;
    };
    std::uint64_t count = count_of(y);
    std::vector<Index> free_list;
    while (lns_clock.seconds() < seconds) {
      if (next_region == regions.size()) {
        if (!regions.empty()) {
          ++result.neighbourhood_sweeps;
          idle_sweeps = improved_in_sweep == 0 ? idle_sweeps + 1 : 0;
          if (idle_sweeps >= 2 || (idle_sweeps == 1 && regions.size() == 1)) {
            result.neighbourhoods_converged = true;
            break;
          }
          improved_in_sweep = 0;
          std::shuffle(order.begin(), order.end(), rng);
        }
        regions = neighbourhood_partition(groups, adj_offsets, adjacent, order, params.neighbourhood_groups);
        next_region = 0;
        if (regions.empty()) break;
      }
      free_list = regions[next_region++];
      std::sort(free_list.begin(), free_list.end());
      for (Index a : free_list) free[a] = 1;
      Stopwatch build_clock;
      ModelBuilder sub(mesh, conn, analysis, groups, gc, fg, importance, params);
      sub.set_scope(free, y, scope_index, free_list, count);
      sub.build(target, true);
      sub.model.set_initial_solution(sub.complete(y, target));
      result.seconds_neighbourhood_build += build_clock.seconds();
      ilp::SolveParams sp = params.solve;
      sp.start_as_mip_start = params.greedy_as_mip_start;
      sp.time_limit_seconds =
          std::max(1e-3, std::min(params.neighbourhood_time_limit, seconds - lns_clock.seconds()));
      sp.isolate_process = params.isolate_neighbourhoods;
      sp.light = params.light_neighbourhoods;
      const ilp::ReducedModel reduced = ilp::without_fixed_columns(sub.model);
      const ilp::SolveResult r = solver->solve(reduced.model, sp);
      ++result.neighbourhoods;
      summary.nodes += r.nodes;
      summary.iterations += r.iterations;
      // The neighbourhood model holds every term of Eq. 9 that its free groups change, so the
      // change of its objective is the change of Eq. 9.
      const double change = r.objective - reduced.model.evaluate(reduced.model.initial_solution());
      if (r.has_solution() && !r.solution_is_start && reduced.violated_constant_rows == 0 &&
          change < -1e-9 * std::max(1.0, std::abs(best))) {
        {
          sub.read_free_groups(reduced.expand(sub.model, r.solution), y);
          best += change;
          count = count_of(y);
          assert(std::abs(best - group_objective(groups, gc, fg, y, target, params)) <=
                 1e-6 * std::max(1.0, std::abs(best)));
          ++result.neighbourhoods_improved;
          ++improved_in_sweep;
          if (!params.quiet) {
            std::fprintf(stderr, "\rselect      neighbourhood %u  objective %.4f  %6.1f s",
                         result.neighbourhoods, best, lns_clock.seconds());
            std::fflush(stderr);
          }
        }
      }
      for (Index a : free_list) free[a] = 0;
    }
    if (!params.quiet && result.neighbourhoods_improved) std::fprintf(stderr, "\n");
    summary.status = ilp::SolveStatus::Feasible;  // no bound: a neighbourhood optimum is not a global one
    summary.objective = best;
    summary.seconds = lns_clock.seconds();
    summary.solution_is_start = result.neighbourhoods_improved == 0;
    summary.start = ilp::StartStatus::NotUsed;
    result.solve = std::move(summary);
    result.solver_ran = true;
    result.seconds_solve += lns_clock.seconds();
    return y;
  };

  // The whole model is built before the local search, so that the annealing's and the descent's
  // shares of the budget (fractions of the time since select_edges() began) account for it: built
  // after them, it overran 0.625 s budgets by 0.1-0.2 s on cg57.
  Stopwatch build_clock;
  ModelBuilder banded(mesh, conn, analysis, groups, gc, fg, importance, params);
  banded.build(target, true);
  result.model = banded.stats;
  result.model.size = banded.model.size();
  result.seconds_build = build_clock.seconds();

  // The greedy selection (or reach_band's), annealed and polished by the descent, is the start
  // of every solve (skipped for a greedy-only run and when neither lies in the band).
  std::vector<std::uint8_t> start_y = closest;
  std::vector<std::vector<std::uint8_t>> alternatives;  // other annealing runs, for the recombination
  if (reachable && time_limit > 0.0) {
    // Fast formulation: simulated annealing from the greedy selection until anneal_time_fraction
    // of the budget has passed, then the deterministic local search as a final descent.
    if (params.anneal_time_fraction > 0.0 && params.formulation == Formulation::Fast) {
      Stopwatch anneal_clock;
      AnnealStats as;
      start_y = anneal_runs(groups, gc, fg, std::move(start_y), target, params,
                            params.anneal_time_fraction * time_limit - clock.seconds(), adj_offsets, adjacent,
                            threads, as, &alternatives);
      result.anneal_moves = as.moves;
      result.anneal_accepted = as.accepted;
      result.anneal_compounds = as.compounds;
      result.anneal_converged = as.schedule_done;
      result.anneal_runs = as.runs;
      result.anneal_priced_runs = as.priced_runs;
      result.priced_component_runs = as.component_runs;
      result.seconds_anneal = anneal_clock.seconds();
    }
    // The recombination (after annealing only) takes its share from the end of the descent's.
    const double recombination_fraction =
        params.formulation == Formulation::Fast && result.anneal_moves > 0 ? params.recombination_fraction : 0.0;
    Stopwatch flip_clock;
    FlipSearchStats fs;
    // After annealing the descent only gets what is left up to descent_end_fraction of the
    // budget (the neighbourhood MIPs get the rest).
    const double flip_budget =
        result.anneal_moves > 0
            ? std::min(params.flip_search_time_fraction * time_limit,
                       std::max(0.0, (params.descent_end_fraction - recombination_fraction) * time_limit - clock.seconds()))
            : params.flip_search_time_fraction * time_limit;
    start_y = flip_search(groups, gc, fg, std::move(start_y), target, params, flip_budget, adj_offsets, adjacent, fs);
    result.flip_passes = fs.passes;
    result.flips = fs.flips;
    result.swaps = fs.swaps;
    result.exchanges = fs.exchanges;
    result.chains = fs.chains;
    result.compounds = fs.compounds;
    result.flip_search_converged = fs.converged;
    result.seconds_flip_search = flip_clock.seconds();
    // Recombination of independent parts after the descent (fast formulation, after
    // annealing), then a second descent if it changed anything.
    if (recombination_fraction > 0.0) {
      Stopwatch recombine_clock;
      RecombineStats rs;
      const double before = group_objective(groups, gc, fg, start_y, target, params);
      const std::vector<std::uint8_t> unrecombined = start_y;
      start_y = recombine_components(groups, gc, fg, std::move(start_y), target, params,
                                     params.descent_end_fraction * time_limit - clock.seconds(), adj_offsets,
                                     adjacent, rs, alternatives);
      result.recombination_rounds = rs.rounds;
      result.recombination_improved = rs.improved;
      result.recombination_moved = rs.moved;
      result.components = rs.components;
      result.largest_component = rs.largest;
      result.seconds_recombination = recombine_clock.seconds();
      result.recombination_gain = before - group_objective(groups, gc, fg, start_y, target, params);
      if (result.recombination_gain < -1e-6 * std::max(1.0, std::abs(before))) {  // never: the programme is exact
        assert(false);
        start_y = unrecombined;
        result.recombination_gain = 0.0;
        rs.improved = 0;
      }
      if (rs.improved > 0) {
        FlipSearchStats fs2;
        start_y = flip_search(groups, gc, fg, std::move(start_y), target, params,
                              std::max(0.0, params.descent_end_fraction * time_limit - clock.seconds()), adj_offsets,
                              adjacent, fs2);
      }
    }
  }

  const std::vector<double> banded_start = banded.complete(start_y, target);
  if (reachable) banded.model.set_initial_solution(banded_start);

  std::vector<double> solution;
  bool proven_out_of_reach = false;  // phase 1 proved the band infeasible
  const ModelBuilder* used = &banded;
  const auto free_groups = static_cast<Index>(std::count(groups.fixed.begin(), groups.fixed.end(), 0));
  const bool neighbourhoods =
      params.formulation == Formulation::Fast &&
      (params.strategy == SelectionParams::Strategy::Neighbourhoods ||
       (params.strategy == SelectionParams::Strategy::Auto && free_groups > params.whole_model_groups));
  result.strategy = time_limit > 0.0 ? (neighbourhoods ? "neighbourhoods" : "whole") : "greedy";
  // Too large for a whole-model MIP to find the band when the greedy misses it (phases below).
  const bool large = free_groups > params.whole_model_groups;
  if (reachable) {
    result.greedy_objective = banded.model.evaluate(banded.complete(greedy.y, target));
    result.flip_search_objective = banded.model.evaluate(banded_start);
    // The budget covers the whole selection: what building the model and the greedy took is
    // subtracted (at least 10 % of it is left to the solver).
    // (After annealing, which already ran to its share of the budget, nothing is guaranteed.)
    const double budget = std::max(result.anneal_moves > 0 ? 0.0 : 0.1 * time_limit, time_limit - clock.seconds());
    if (time_limit > 0.0 && neighbourhoods) {
      solution = banded.complete(neighbourhood_search(start_y, budget), target);
    } else {
      solution = time_limit > 0.0 ? run(banded, budget) : banded_start;
    }
    if (solution.empty()) solution = banded_start;
    result.band_enforced = true;
  } else if (time_limit > 0.0 && !(neighbourhoods && large)) {
    // Phase 1 only where the whole model is small enough to be searched (at most
    // whole_model_groups free groups): on the large models of the neighbourhood strategy a
    // whole-model MIP never found a point in the band in its half of the budget (cg57 at 0.4,
    // rounds after pins: 0 of 18), but each call cost 1–3 s beyond its limit (loading 300k rows,
    // the child process).
    solution = run(banded, 0.5 * std::max(0.1 * time_limit, time_limit - clock.seconds()));
    result.band_enforced = !solution.empty();
    proven_out_of_reach = solution.empty() && result.solve.status == ilp::SolveStatus::Infeasible;
  }
  std::optional<ModelBuilder> open;
  if (solution.empty() && time_limit > 0.0 && ((neighbourhoods && large) || result.reach_ran)) {
    // The selection nearest the band stays (the greedy's on a large model, or reach_band's):
    // Eq. 9 without the band would trade count for λ_geo (a search of the open model raised N'
    // by ~3 % on cg57's later rounds, away from the target; on a cube with N' ∈ {12, 4, 0} for
    // N = 3 it kept all 12). The banded model evaluates it like the open one would (same
    // objective; only p's or q's bound is off).
    result.greedy_objective = banded.model.evaluate(banded.complete(greedy.y, target));
    solution = banded.complete(closest, target);
  } else if (solution.empty()) {
    // Phase 2: the band widened to the distance of the selection nearest it (so the result is
    // never farther from N than the closest selection found; Eq. 9 without any band traded
    // count for λ_geo: tpsdemo_red_robot at 0.4, N = 5 152, went to N' = 9 398 where the greedy
    // had 6 183).
    Stopwatch rebuild_clock;
    open.emplace(mesh, conn, analysis, groups, gc, fg, importance, params);
    open->build(target, false, std::abs(double(selection_count(fg, closest)) - double(target)));
    result.greedy_objective = open->model.evaluate(open->complete(greedy.y, target));
    const std::vector<double> start = open->complete(closest, target);
    open->model.set_initial_solution(start);
    result.seconds_build += rebuild_clock.seconds();
    solution = time_limit > 0.0 ? run(*open, std::max(0.1 * time_limit, time_limit - clock.seconds())) : start;
    if (solution.empty()) solution = start;
    used = &*open;
  }
  if (!result.band_enforced && result.reach_ran) {
    result.stop_reason = "band not reached";
  } else if (time_limit <= 0.0 || (!result.band_enforced && neighbourhoods && large)) {
    result.stop_reason = "greedy";
  } else if (result.strategy == "neighbourhoods") {
    result.stop_reason = result.neighbourhoods_converged ? "converged" : "time";
  } else {
    result.stop_reason = result.solve.status == ilp::SolveStatus::Optimal ? "optimal"
                         : result.solve.stalled                            ? "stalled"
                                                                           : "time";
  }
  result.objective = used->model.evaluate(solution);
  result.edge_kept = used->edge_bits(solution);
  result.predicted = predicted_tri_equivalent(mesh, conn, result.edge_kept);
  std::vector<std::uint8_t> y(groups.count, 1);
  for (Index e = 0; e < conn.num_edges; ++e)
    if (!result.edge_kept[e]) y[groups.edge_group[e]] = 0;
  result.collapsed_groups = static_cast<Index>(std::count(y.begin(), y.end(), 0));
  result.collapsed_clusters = count_collapsed_clusters(gc, y);
  // The open search of phase 2 may still land in the band: then the target was not out of reach.
  if (!result.band_enforced && std::abs(double(result.predicted) - double(target)) <= params.epsilon_n * double(target))
    result.band_enforced = true;
  // Out of reach only where the solver proved it; otherwise what was searched, and the nearest.
  if (!result.band_enforced && result.note.empty()) {
    char text[320];
    if (proven_out_of_reach)
      std::snprintf(text, sizeof text,
                    "target %llu is out of reach of the hard constraints (the solver proved that no selection "
                    "lies within %g %% of it): the closest selection found has %llu triangle-equivalents",
                    static_cast<unsigned long long>(target), 100.0 * params.epsilon_n,
                    static_cast<unsigned long long>(result.predicted));
    else
      std::snprintf(text, sizeof text,
                    "no selection within %g %% of the target %llu was found under the hard constraints (%s): the "
                    "closest selection found has %llu triangle-equivalents",
                    100.0 * params.epsilon_n, static_cast<unsigned long long>(target),
                    result.reach_ran && result.solver_ran ? "searched by annealing and the MIP solver"
                    : result.reach_ran                    ? "searched by annealing"
                    : result.solver_ran                   ? "searched by the MIP solver"
                                                          : "greedy only, no search",
                    static_cast<unsigned long long>(result.predicted));
    result.note = text;
  }
  return result;
}

namespace detail {

ilp::Model neighbourhood_model(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                               std::uint64_t target, const SelectionParams& params,
                               const std::vector<std::uint8_t>& edge_kept, const std::vector<Index>& free_edges,
                               bool indexed) {
  const Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  std::vector<std::uint8_t> free(p.groups.count, 0);
  std::vector<Index> free_list;
  for (Index e : free_edges) {
    const Index grp = p.groups.edge_group[e];
    if (!p.groups.fixed[grp] && !free[grp]) {
      free[grp] = 1;
      free_list.push_back(grp);
    }
  }
  std::sort(free_list.begin(), free_list.end());
  const ScopeIndex index = make_scope_index(p.groups, p.gc, p.fg);
  std::uint64_t count = 0;
  for (Index f = 0; f + 1 < p.fg.offsets.size(); ++f) count += face_count(p.fg, f, p.y);
  ModelBuilder sub(mesh, conn, analysis, p.groups, p.gc, p.fg, p.importance, params);
  if (indexed) sub.set_scope(free, p.y, index, free_list, count);
  else sub.set_scope(free, p.y);
  sub.build(target, true);
  sub.model.set_initial_solution(sub.complete(p.y, target));
  return ilp::without_fixed_columns(sub.model).model;
}

std::vector<std::uint8_t> local_search(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                       std::uint64_t target, const SelectionParams& params,
                                       const std::vector<std::uint8_t>& edge_kept, double seconds) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  AnnealStats as;
  if (params.anneal_time_fraction > 0.0)
    p.y = anneal_runs(p.groups, p.gc, p.fg, std::move(p.y), target, params, seconds, p.adj_offsets, p.adjacent,
                      ilp::backend::resolve_threads(params.solve), as, nullptr);
  FlipSearchStats stats;
  return p.edge_bits(conn, flip_search(p.groups, p.gc, p.fg, p.y, target, params, seconds, p.adj_offsets,
                                       p.adjacent, stats));
}

}  // namespace detail

}  // namespace quadlod
