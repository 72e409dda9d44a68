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

#include "select/greedy.h"
#include "select/groups.h"
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

// Local search over single-group flips (beyond the paper; docs/formulation.md, "Speed"): from a
// feasible selection, repeatedly flip one group (collapse a kept one, or keep a collapsed one)
// whenever that lowers Eq. 9 and keeps Eq. 2's band and Eq. 8, by exact incremental deltas, until
// a full pass finds nothing or time runs out. Then pairs of adjacent groups are swapped (one
// collapsed, one kept), which keeps the count roughly where it is, so that moves the count term
// alone would block are found too. Milliseconds per pass on the largest corpus meshes.
struct FlipSearchStats {
  Index passes = 0;
  Index flips = 0;
  Index swaps = 0;
  Index exchanges = 0;
  Index chains = 0;
  Index compounds = 0;
  bool converged = false;
};

// Chain moves: flip a run of groups linked by λ_tri split pairs (consecutive segments of one
// poly-chord, cut by breakpoints §3.2.2) as one move. Flipping one segment of a chord whose
// neighbours stay splits two quad side pairs (+2 λ_tri), so single flips cannot walk a chord
// segment by segment even where collapsing the whole run pays. From each seed the run grows
// breadth-first over split partners that have the seed's value, flipping each (exact incremental
// deltas; a collapse only where Eq. 8 allows it), up to `max_chain` groups; the prefix with the
// best Eq. 9 change that lies in Eq. 2's band is kept if it lowers Eq. 9, the rest is undone.
//
//     seg 1     seg 2     seg 3          collapsing seg 2 alone splits the quads at both
//   ┌──┬──┐  ┌──┬──┐  ┌──┬──┐          breakpoints (2 λ_tri); seg 1–3 together split none
//   └──┴──┘  └──┴──┘  └──┴──┘
//
// chain_walk is that walk under any count term: `count_term(N')` replaces |N' − N| and only
// prefixes with `in_band(N')` count (the priced descent of the recombination passes μ N' and
// no band). Returns the number of chains applied.
template <class CountTerm, class InBand>
Index chain_walk(SelectionState& st, const Groups& g, const GroupConstraints& gc, const SelectionParams& params,
                 const Stopwatch& clock, double seconds, CountTerm&& count_term, InBand&& in_band) {
  constexpr std::size_t max_chain = 64;
  constexpr double eps = 1e-9;
  std::vector<Index> stamp(g.count, kInvalidIndex), queue;
  std::vector<std::pair<Index, std::int64_t>> flipped;  // group, Δcount when flipped
  Index applied = 0;
  for (Index seed = 0; seed < g.count && clock.seconds() < seconds; ++seed) {
    if (g.fixed[seed]) continue;
    const std::uint8_t v = st.y[seed];
    // Only seeds with a partner of the same value: otherwise this is a single flip.
    if (std::none_of(gc.group_split[seed].begin(), gc.group_split[seed].end(),
                     [&](Index b) { return !g.fixed[b] && st.y[b] == v; }))
      continue;
    const std::int64_t c0 = st.count;
    const double ct0 = count_term(c0);
    double rest = 0.0, best_gain = -eps;
    std::size_t best_len = 0;
    flipped.clear();
    queue.assign(1, seed);
    stamp[seed] = seed;
    for (std::size_t head = 0; head < queue.size() && flipped.size() < max_chain; ++head) {
      const Index a = queue[head];
      if (st.y[a] != v || (v && !st.may_collapse(a))) continue;
      const std::int64_t dc = st.delta_count(a);
      rest += st.delta_rest(a, params);
      st.flip(a, dc);
      flipped.emplace_back(a, dc);
      const double gain = count_term(st.count) - ct0 + rest;
      if (in_band(st.count) && gain < best_gain) {
        best_gain = gain;
        best_len = flipped.size();
      }
      for (Index b : gc.group_split[a])
        if (!g.fixed[b] && stamp[b] != seed && st.y[b] == v) {
          stamp[b] = seed;
          queue.push_back(b);
        }
    }
    while (flipped.size() > best_len) {  // undo beyond the best prefix, last flip first
      st.flip(flipped.back().first, -flipped.back().second);
      flipped.pop_back();
    }
    applied += best_len > 0;
  }
  return applied;
}

// Swaps: keep a collapsed group b and collapse a kept neighbour a (one that shares a face), as
// one move; per b the best a is taken if the pair lowers Eq. 9 and the new count is
// `in_band`. As in chain_walk, `count_term(N')` stands for |N' − N| (the priced descent passes
// μ N' and no band). With `keep_must_pay` a b whose own change without the count term does
// not lower Eq. 9 is skipped: keeping it must pay for something besides the count. Returns the
// number of swaps applied.
template <class CountTerm, class InBand>
Index swap_walk(SelectionState& st, const Groups& g, const SelectionParams& params, const std::vector<Index>& adj_offsets,
                const std::vector<Index>& adjacent, const Stopwatch& clock, double seconds, CountTerm&& count_term,
                InBand&& in_band, bool keep_must_pay) {
  constexpr double eps = 1e-9;
  Index applied = 0;
  for (Index b = 0; b < g.count && clock.seconds() < seconds; ++b) {
    if (g.fixed[b] || st.y[b]) continue;
    const double rb = st.delta_rest(b, params);
    if (keep_must_pay && rb >= 0.0) continue;
    const std::int64_t before = st.count;
    const std::int64_t db = st.delta_count(b);
    st.flip(b, db);
    Index best_a = kInvalidIndex;
    std::int64_t best_da = 0;
    double best_gain = -eps;
    for (Index k = adj_offsets[b]; k < adj_offsets[b + 1]; ++k) {
      const Index a = adjacent[k];
      if (g.fixed[a] || !st.y[a] || !st.may_collapse(a)) continue;
      const std::int64_t da = st.delta_count(a);
      if (!in_band(st.count + da)) continue;
      const double gain = count_term(st.count + da) - count_term(before) + rb + st.delta_rest(a, params);
      if (gain < best_gain) {
        best_gain = gain;
        best_a = a;
        best_da = da;
      }
    }
    if (best_a != kInvalidIndex) {
      st.flip(best_a, best_da);
      ++applied;
    } else {
      st.flip(b, -db);  // undo
    }
  }
  return applied;
}

bool chain_moves(SelectionState& st, const Groups& g, const GroupConstraints& gc, std::uint64_t target,
                 const SelectionParams& params, const Stopwatch& clock, double seconds, FlipSearchStats& stats) {
  const double n = double(target), band = params.epsilon_n * n;
  const Index applied = chain_walk(
      st, g, gc, params, clock, seconds, [&](std::int64_t c) { return std::abs(double(c) - n); },
      [&](std::int64_t c) { return std::abs(double(c) - n) <= band; });
  stats.chains += applied;
  return applied > 0;
}

// Pair exchanges: keep one collapsed group and collapse one kept group *anywhere* on the mesh,
// as one move. The count term alone blocks most single flips near N (each costs |ΔN'|), and
// adjacent swaps only see neighbours; an exchange pairs, e.g., keeping a group whose collapse
// emptied an Eq. 6 cluster (−λ_geo) with collapsing a cheap group of about the same ΔN' elsewhere.
// Candidates come from a table of the best single moves per ΔN' value (the two flips' deltas add
// up when the groups share no face or cluster); every candidate is re-evaluated exactly before it
// is applied (the second flip's delta is computed after the first), so a move is taken only if it
// lowers Eq. 9 and keeps Eq. 2's band and Eq. 8. Returns whether something was applied.
bool pair_exchanges(SelectionState& st, const Groups& g, std::uint64_t target, const SelectionParams& params,
                    const Stopwatch& clock, double seconds, FlipSearchStats& stats) {
  const double n = double(target), band = params.epsilon_n * n, eps = 1e-9;
  auto count_term = [&](std::int64_t c) { return std::abs(double(c) - n); };
  auto in_band = [&](std::int64_t c) { return std::abs(double(c) - n) <= band; };
  struct Move {
    std::int64_t dc;
    double dr;
    Index grp;
  };
  // Single moves, sorted by ΔN' and then by their other cost; the best `per_bucket` of each ΔN'.
  constexpr std::size_t per_bucket = 3;
  std::vector<Move> collapse, keep;
  for (Index grp = 0; grp < g.count; ++grp) {
    if (g.fixed[grp]) continue;
    if (st.y[grp]) {
      if (!st.may_collapse(grp)) continue;
      const std::int64_t dc = st.delta_count(grp);
      if (dc < 0) collapse.push_back({dc, st.delta_rest(grp, params), grp});
    } else {
      const std::int64_t dc = st.delta_count(grp);
      if (dc > 0) keep.push_back({dc, st.delta_rest(grp, params), grp});
    }
  }
  auto buckets = [&](std::vector<Move>& moves) {
    std::sort(moves.begin(), moves.end(), [](const Move& l, const Move& r) {
      return l.dc != r.dc ? l.dc < r.dc : (l.dr != r.dr ? l.dr < r.dr : l.grp < r.grp);
    });
    std::vector<std::size_t> starts;  // first index of each ΔN' value
    for (std::size_t i = 0; i < moves.size(); ++i)
      if (i == 0 || moves[i].dc != moves[i - 1].dc) starts.push_back(i);
    starts.push_back(moves.size());
    return starts;
  };
  const std::vector<std::size_t> cs = buckets(collapse), ks = buckets(keep);
  struct Candidate {
    double gain;
    Index a, b;  // collapse a, keep b
  };
  std::vector<Candidate> candidates;
  const std::int64_t c0 = st.count;
  for (std::size_t i = 0; i + 1 < cs.size(); ++i) {
    const Move& a = collapse[cs[i]];
    for (std::size_t j = 0; j + 1 < ks.size(); ++j) {
      const Move& b = keep[ks[j]];
      const std::int64_t c = c0 + a.dc + b.dc;
      if (!in_band(c)) continue;
      const double base = count_term(c) - count_term(c0);
      if (base + a.dr + b.dr >= -eps) continue;
      for (std::size_t x = cs[i]; x < std::min(cs[i + 1], cs[i] + per_bucket); ++x)
        for (std::size_t z = ks[j]; z < std::min(ks[j + 1], ks[j] + per_bucket); ++z) {
          const double gain = base + collapse[x].dr + keep[z].dr;
          if (gain < -eps) candidates.push_back({gain, collapse[x].grp, keep[z].grp});
        }
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& l, const Candidate& r) {
    return l.gain != r.gain ? l.gain < r.gain : (l.a != r.a ? l.a < r.a : l.b < r.b);
  });
  std::vector<std::uint8_t> used(g.count, 0);
  bool applied = false;
  for (const Candidate& cand : candidates) {
    if (clock.seconds() >= seconds) break;
    if (used[cand.a] || used[cand.b] || !st.y[cand.a] || st.y[cand.b]) continue;
    const std::int64_t before = st.count;
    const double rb = st.delta_rest(cand.b, params);
    const std::int64_t db = st.delta_count(cand.b);
    st.flip(cand.b, db);
    bool take = st.may_collapse(cand.a);
    std::int64_t da = 0;
    if (take) {
      da = st.delta_count(cand.a);
      take = in_band(st.count + da) &&
             count_term(st.count + da) - count_term(before) + rb + st.delta_rest(cand.a, params) < -eps;
    }
    if (take) {
      st.flip(cand.a, da);
      used[cand.a] = used[cand.b] = 1;
      ++stats.exchanges;
      applied = true;
    } else {
      st.flip(cand.b, -db);  // undo
    }
  }
  return applied;
}

// Compound moves (an ejection chain; beyond the paper, docs/formulation.md, "Speed"): flip a seed
// group, then flip nearby groups the other way — cheapest Eq. 9 change per triangle-equivalent
// first — until N' is back across its value before the move. The typical one re-opens an emptied
// Eq. 6 cluster: keeping one of its groups saves λ_geo but adds its faces to N' (|ΔN'| of a long
// chord is tens of triangle-equivalents, far more than λ_geo, so the single flip and the pair
// exchanges rarely pay), and several small groups around it, collapsed, remove those faces again
// without emptying another cluster. The reverse (collapse a large group, keep small ones around
// it) comes with the same code. Candidates: groups that now hold the seed's new value (so they flip
// the other way), met by a breadth-first walk over groups that share a face, up to
// `compound_candidates`. The prefix of the chain with the
// best Eq. 9 change inside Eq. 2's band is kept (its flips are in `flipped`); the rest is undone.
// Returns that change, or +∞ with the state unchanged when no prefix lies in the band.
//
//        keep ║            ║ = the seed's chord, kept again: its cluster keeps an edge (−λ_geo),
//    ─────────╫──────      N' rises by its faces;
//     ┆   ┆   ║   ┆   ┆    ┆ = small chords around it, collapsed: N' falls back
struct CompoundScratch {
  std::vector<Index> queue;
  std::vector<std::uint32_t> stamp;
  std::uint32_t round = 0;
  struct Candidate {
    double key;
    Index grp;
  };
  std::vector<Candidate> candidates;
};

double compound_move(SelectionState& st, Index seed, const Groups& g, const std::vector<Index>& adj_offsets,
                     const std::vector<Index>& adjacent, std::uint64_t target, const SelectionParams& params,
                     CompoundScratch& s, std::vector<std::pair<Index, std::int64_t>>& flipped) {
  const double n = double(target), band = params.epsilon_n * n;
  auto count_term = [&](std::int64_t c) { return std::abs(double(c) - n); };
  auto in_band = [&](std::int64_t c) { return std::abs(double(c) - n) <= band; };
  flipped.clear();
  if (g.fixed[seed] || (st.y[seed] && !st.may_collapse(seed))) return INFINITY;
  const std::int64_t c0 = st.count, dc0 = st.delta_count(seed);
  if (dc0 == 0) return INFINITY;  // nothing to compensate: a single flip
  const double ct0 = count_term(c0);
  double rest = st.delta_rest(seed, params);
  st.flip(seed, dc0);
  flipped.emplace_back(seed, dc0);
  const std::uint8_t v = st.y[seed];  // candidates hold the seed's new value and flip away from it
  const std::int64_t dir = dc0 > 0 ? 1 : -1;
  if (s.stamp.size() != g.count) s.stamp.assign(g.count, 0), s.round = 0;
  if (++s.round == 0) std::fill(s.stamp.begin(), s.stamp.end(), 0), s.round = 1;
  s.queue.assign(1, seed);
  s.stamp[seed] = s.round;
  s.candidates.clear();
  const std::size_t max_candidates = params.compound_candidates, max_visits = 8 * max_candidates;
  for (std::size_t head = 0; head < s.queue.size() && s.candidates.size() < max_candidates; ++head) {
    const Index a = s.queue[head];
    if (a != seed && !g.fixed[a] && st.y[a] == v && (!v || st.may_collapse(a))) {
      const std::int64_t dc = st.delta_count(a);
      if (dc * dir < 0) s.candidates.push_back({st.delta_rest(a, params) / double(std::abs(dc)), a});
    }
    for (Index k = adj_offsets[a]; k < adj_offsets[a + 1] && s.queue.size() < max_visits; ++k)
      if (s.stamp[adjacent[k]] != s.round) {
        s.stamp[adjacent[k]] = s.round;
        s.queue.push_back(adjacent[k]);
      }
  }
  std::sort(s.candidates.begin(), s.candidates.end(), [](const CompoundScratch::Candidate& l,
                                                         const CompoundScratch::Candidate& r) {
    return l.key != r.key ? l.key < r.key : l.grp < r.grp;
  });
  double best = in_band(st.count) ? count_term(st.count) - ct0 + rest : INFINITY;
  std::size_t best_len = in_band(st.count) ? 1 : 0;
  for (const auto& cand : s.candidates) {
    if ((st.count - c0) * dir <= 0) break;  // N' is back
    const Index a = cand.grp;
    if (st.y[a] != v || (v && !st.may_collapse(a))) continue;
    const std::int64_t dc = st.delta_count(a);  // exact now: earlier flips may share its faces
    if (dc * dir >= 0) continue;
    rest += st.delta_rest(a, params);
    st.flip(a, dc);
    flipped.emplace_back(a, dc);
    const double change = count_term(st.count) - ct0 + rest;
    if (in_band(st.count) && change < best) {
      best = change;
      best_len = flipped.size();
    }
  }
  while (flipped.size() > best_len) {
    st.flip(flipped.back().first, -flipped.back().second);
    flipped.pop_back();
  }
  return best_len > 0 ? best : INFINITY;
}

// Compound moves in the descent: every free group as a seed, a move kept when it lowers Eq. 9.
bool compound_moves(SelectionState& st, const Groups& g, const std::vector<Index>& adj_offsets,
                    const std::vector<Index>& adjacent, std::uint64_t target, const SelectionParams& params,
                    const Stopwatch& clock, double seconds, FlipSearchStats& stats) {
  CompoundScratch scratch;
  std::vector<std::pair<Index, std::int64_t>> flipped;
  bool applied = false;
  for (Index seed = 0; seed < g.count && clock.seconds() < seconds; ++seed) {
    const double change = compound_move(st, seed, g, adj_offsets, adjacent, target, params, scratch, flipped);
    if (change < -1e-9) {
      ++stats.compounds;
      applied = true;
    } else {
      while (!flipped.empty()) {
        st.flip(flipped.back().first, -flipped.back().second);
        flipped.pop_back();
      }
    }
  }
  return applied;
}

std::vector<std::uint8_t> flip_search(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                      std::vector<std::uint8_t> y, std::uint64_t target,
                                      const SelectionParams& params, double seconds,
                                      const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                      FlipSearchStats& stats) {
  Stopwatch clock;
  SelectionState st(g, gc, fg, std::move(y));
  const double n = double(target), band = params.epsilon_n * n, eps = 1e-9;
  auto count_term = [&](std::int64_t c) { return std::abs(double(c) - n); };
  auto in_band = [&](std::int64_t c) { return std::abs(double(c) - n) <= band; };

  bool improved = true;
  while (improved && clock.seconds() < seconds) {
    improved = false;
    ++stats.passes;
    for (Index grp = 0; grp < g.count && clock.seconds() < seconds; ++grp) {
      if (g.fixed[grp] || (st.y[grp] && !st.may_collapse(grp))) continue;
      const std::int64_t dc = st.delta_count(grp);
      if (!in_band(st.count + dc)) continue;
      if (count_term(st.count + dc) - count_term(st.count) + st.delta_rest(grp, params) < -eps) {
        st.flip(grp, dc);
        ++stats.flips;
        improved = true;
      }
    }
    if (const Index swaps = swap_walk(st, g, params, adj_offsets, adjacent, clock, seconds, count_term, in_band, true)) {
      stats.swaps += swaps;
      improved = true;
    }
    if (params.chain_moves && clock.seconds() < seconds)
      improved |= chain_moves(st, g, gc, target, params, clock, seconds, stats);
    if (params.compound_moves && !improved && clock.seconds() < seconds)
      improved = compound_moves(st, g, adj_offsets, adjacent, target, params, clock, seconds, stats);
    if (params.pair_exchanges && !improved && clock.seconds() < seconds)
      improved = pair_exchanges(st, g, target, params, clock, seconds, stats);
  }
  stats.converged = !improved;
  return std::move(st.y);
}

// The two-group and chain moves of the annealing (anneal() and anneal_component()). Their flips
// are journaled in `flipped`, so that a rejected move is undone; `rest` collects their change of
// Eq. 9 without the count term (the caller prices the count from st.count).
struct MoveScratch {
  std::vector<std::pair<Index, std::int64_t>> flipped;
  std::vector<Index> queue;
  std::vector<std::uint32_t> stamp;
  std::uint32_t round = 0;
};

// Flips grp unless collapsing it would break Eq. 8 (then nothing is done: false).
bool flip_journaled(SelectionState& st, Index grp, const SelectionParams& params, double& rest, MoveScratch& ms) {
  if (st.y[grp] && !st.may_collapse(grp)) return false;
  const std::int64_t dc = st.delta_count(grp);
  rest += st.delta_rest(grp, params);
  st.flip(grp, dc);
  ms.flipped.emplace_back(grp, dc);
  return true;
}

void undo_journaled(SelectionState& st, MoveScratch& ms) {
  while (!ms.flipped.empty()) {
    st.flip(ms.flipped.back().first, -ms.flipped.back().second);
    ms.flipped.pop_back();
  }
}

// Swaps a with a random group of the other value that shares a face with it (a must have one).
// The kept one first: keeping never breaks Eq. 8. false = nothing flipped.
bool swap_move(SelectionState& st, const Groups& g, Index a, const std::vector<Index>& adj_offsets,
               const std::vector<Index>& adjacent, std::mt19937_64& rng, const SelectionParams& params,
               double& rest, MoveScratch& ms) {
  const Index b = adjacent[adj_offsets[a] + rng() % (adj_offsets[a + 1] - adj_offsets[a])];
  if (g.fixed[b] || st.y[b] == st.y[a]) return false;
  const Index keep = st.y[a] ? b : a, drop = st.y[a] ? a : b;
  flip_journaled(st, keep, params, rest, ms);
  if (!flip_journaled(st, drop, params, rest, ms)) {
    undo_journaled(st, ms);
    return false;
  }
  return true;
}

// Flips 2 – 16 groups of a's value, breadth-first along split partners from a (λ_tri pairs).
// false = nothing flipped.
bool chain_move(SelectionState& st, const Groups& g, const GroupConstraints& gc, Index a, std::mt19937_64& rng,
                const SelectionParams& params, double& rest, MoveScratch& ms) {
  if (ms.stamp.size() != g.count) ms.stamp.assign(g.count, 0);
  const std::uint8_t v = st.y[a];
  const std::size_t length = 2 + rng() % 15;
  ms.queue.assign(1, a);
  ms.stamp[a] = ++ms.round;
  for (std::size_t head = 0; head < ms.queue.size() && ms.flipped.size() < length; ++head) {
    const Index x = ms.queue[head];
    if (st.y[x] != v || !flip_journaled(st, x, params, rest, ms)) continue;
    for (Index b : gc.group_split[x])
      if (!g.fixed[b] && ms.stamp[b] != ms.round && st.y[b] == v) {
        ms.stamp[b] = ms.round;
        ms.queue.push_back(b);
      }
  }
  return !ms.flipped.empty();
}

// Simulated annealing over the local-search moves (beyond the paper; docs/formulation.md,
// "Speed"): random single flips, swaps with an adjacent group of the other value, and chains of
// random length along λ_tri split partners (see chain_moves), each evaluated exactly through the
// incremental state, never leaving Eq. 2's band or breaking Eq. 8; a worsening move of Δ is
// taken with probability exp(−Δ/T), T falling geometrically from t0 to t1 over the budget (time,
// or anneal_moves_per_group moves per free group, whichever ends first). The
// best selection seen is returned. Microseconds per move, so millions of moves fit where the
// neighbourhood MIPs manage a few hundred; the MIPs then polish its result.
//
// What an annealing run minimises (AnnealGoal::Kind):
// * Band: Eq. 9 in Eq. 2's band, with the penalty continuation below.
// * Priced: cost + μ N' instead, the count term of Eq. 9 replaced by a price μ per
//   triangle-equivalent, with no band and no continuation, which makes every independent
//   component a problem of its own (the Lagrangian relaxation the recombination uses). Its end
//   state lies anywhere in N' and is only an alternative for the recombination.
// * Reach: from a start outside the band (a greedy selection the hard constraints stopped short
//   of it), Eq. 9 plus ρ per triangle-equivalent outside the band, moving freely; the best state
//   is the one nearest the band, then the lowest Eq. 9 (SelectionParams::reach_time_fraction).
struct AnnealGoal {
  enum class Kind { Band, Priced, Reach };
  Kind kind = Kind::Band;
  double weight = 0.0;  // Priced: μ; Reach: ρ
  static AnnealGoal priced(double mu) { return {Kind::Priced, mu}; }
  static AnnealGoal reach(double rho) { return {Kind::Reach, rho}; }
};

struct AnnealStats {
  std::int64_t moves = 0, accepted = 0, compounds = 0;  // compounds: compound moves accepted
  std::int64_t component_runs = 0;  // priced runs by component: annealings of one component
  bool schedule_done = false;  // ended by its move count, not by the time
  int runs = 0;                // annealing runs (anneal_runs)
  int priced_runs = 0;         // of which priced
};

std::vector<std::uint8_t> anneal(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                 std::vector<std::uint8_t> y, std::uint64_t target, const SelectionParams& params,
                                 double seconds, const std::vector<Index>& adj_offsets,
                                 const std::vector<Index>& adjacent, AnnealStats& stats,
                                 AnnealGoal goal = {}) {
  Stopwatch clock;
  SelectionState st(g, gc, fg, std::move(y));
  const double n = double(target), band = params.epsilon_n * n;
  const bool priced = goal.kind == AnnealGoal::Kind::Priced, reach = goal.kind == AnnealGoal::Kind::Reach;
  const bool banded = goal.kind == AnnealGoal::Kind::Band;
  auto beyond = [&](std::int64_t c) { return std::max(0.0, std::abs(double(c) - n) - band); };
  auto count_term = [&](std::int64_t c) {
    return priced ? goal.weight * double(c) : std::abs(double(c) - n) + (reach ? goal.weight * beyond(c) : 0.0);
  };
  auto in_band = [&](std::int64_t c) { return !banded || std::abs(double(c) - n) <= band; };
  std::vector<Index> movable;
  for (Index grp = 0; grp < g.count; ++grp)
    if (!g.fixed[grp]) movable.push_back(grp);
  std::vector<std::uint8_t> best_y = st.y;
  if (movable.empty() || seconds <= 0.0) return best_y;
  std::mt19937_64 rng(params.solve.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double current = 0.0, best = 0.0;  // relative to the start
  MoveScratch moves;
  auto& flipped = moves.flipped;
  const double t0 = params.anneal_t0, t1 = params.anneal_t1;
  double temperature = t0;
  // Penalty continuation (SelectionParams::anneal_count_weight): until the ramp starts the count
  // term weighs w0 and N' may leave Eq. 2's band by band_relax × the band; over the ramp both go
  // linearly to the true objective and the hard band, the excess beyond the band penalised by
  // band_penalty × ramp per triangle-equivalent.
  const double w0 = banded ? params.anneal_count_weight : 1.0, band_relax = params.anneal_band_relax;
  const double rho_max = params.anneal_band_penalty;
  const double count_ramp_start = params.anneal_ramp_start, count_ramp_end = params.anneal_ramp_end;
  double count_weight = w0;
  double ramp = 0.0;  // 0 before the ramp, 1 after it
  auto outside = [&](std::int64_t c) { return banded ? beyond(c) : 0.0; };
  auto annealed = [&](double delta, std::int64_t c0, std::int64_t c1) {
    return delta - (1.0 - count_weight) * (count_term(c1) - count_term(c0)) +
           rho_max * ramp * (outside(c1) - outside(c0));
  };
  // Whether the annealing may go from count c0 to c1.
  auto allowed = [&](std::int64_t c0, std::int64_t c1) {
    if (!banded || in_band(c1)) return true;
    if (ramp >= 1.0) return outside(c1) <= outside(c0);
    return std::abs(double(c1) - n) <= band * (1.0 + band_relax);
  };
  // The best selection is kept as best_y plus a journal of the groups flipped since: a new best
  // copies only those (a full copy per improvement cost O(groups) each time). A journal longer
  // than the groups falls back to one full copy.
  std::vector<Index> journal;
  bool journal_full = false;
  auto record = [&](Index grp) {
    if (journal_full) return;
    journal.push_back(grp);
    if (journal.size() > movable.size()) {
      journal_full = true;
      journal.clear();
    }
  };
  // Reach: the best state is the nearest to the band, then the lowest (penalised) Eq. 9.
  double best_beyond = reach ? beyond(st.count) : 0.0;
  auto accept = [&](double delta) {
    ++stats.accepted;
    current += delta;
    const bool better = reach ? beyond(st.count) < best_beyond - 1e-9 ||
                                    (beyond(st.count) <= best_beyond + 1e-9 && current < best - 1e-9)
                              : current < best - 1e-9 && in_band(st.count);
    if (better) {
      best = current;
      best_beyond = reach ? beyond(st.count) : 0.0;
      if (journal_full) best_y = st.y;
      else
        for (Index grp : journal) best_y[grp] = st.y[grp];
      journal.clear();
      journal_full = false;
    }
  };
  CompoundScratch compound;
  // (compound moves judge Eq. 9's count term and band themselves: only in banded runs)
  const double compound_share = params.compound_moves && banded ? params.anneal_compound_share : 0.0;
  // The schedule runs on time or on moves, whichever ends first (small meshes: moves).
  const double max_moves = params.anneal_moves_per_group * double(movable.size());
  for (;; ++stats.moves) {
    if ((stats.moves & 1023) == 0) {
      const double by_time = clock.seconds() / seconds, by_moves = double(stats.moves) / max_moves;
      if (by_time >= 1.0 || by_moves >= 1.0) {
        stats.schedule_done = by_moves >= 1.0;
        break;
      }
      const double progress = std::max(by_time, by_moves);
      temperature = t0 * std::pow(t1 / t0, progress);
      ramp = progress >= count_ramp_end     ? 1.0
             : progress <= count_ramp_start ? 0.0
                                            : (progress - count_ramp_start) / (count_ramp_end - count_ramp_start);
      count_weight = w0 + (1.0 - w0) * ramp;
    }
    const Index a = movable[rng() % movable.size()];
    const std::int64_t c0 = st.count;
    double rest = 0.0;
    flipped.clear();
    if (compound_share > 0.0 && unit(rng) < compound_share) {
      const double delta = compound_move(st, a, g, adj_offsets, adjacent, target, params, compound, flipped);
      if (!(delta < INFINITY)) continue;  // nothing in the band; the state is unchanged
      const double da = annealed(delta, c0, st.count);
      if (da > 0.0 && unit(rng) >= std::exp(-da / temperature)) {
        undo_journaled(st, moves);
        continue;
      }
      ++stats.compounds;
      for (const auto& fl : flipped) record(fl.first);
      accept(delta);
      continue;
    }
    const std::uint64_t kind = rng() % 3;
    if (kind == 0 || (kind == 1 && adj_offsets[a] == adj_offsets[a + 1])) {
      // A single flip is judged before it is made: most moves are rejected, and flipping and
      // undoing them costs as much as the evaluation. Eq. 8 is checked last, only for a move
      // that would be taken (most are not).
      const std::int64_t dc = st.delta_count(a);
      if (!allowed(c0, c0 + dc)) continue;
      const double delta = count_term(c0 + dc) - count_term(c0) + st.delta_rest(a, params);
      const double da = annealed(delta, c0, c0 + dc);
      if (da > 0.0 && unit(rng) >= std::exp(-da / temperature)) continue;
      if (st.y[a] && !st.may_collapse(a)) continue;
      st.flip(a, dc);
      record(a);
      accept(delta);
      continue;
    } else if (kind == 1) {
      if (!swap_move(st, g, a, adj_offsets, adjacent, rng, params, rest, moves)) continue;
    } else if (!chain_move(st, g, gc, a, rng, params, rest, moves)) {
      continue;
    }
    const double delta = count_term(st.count) - count_term(c0) + rest;
    const double da = annealed(delta, c0, st.count);
    if (!allowed(c0, st.count) || (da > 0.0 && unit(rng) >= std::exp(-da / temperature))) {
      undo_journaled(st, moves);
      continue;
    }
    for (const auto& fl : flipped) record(fl.first);
    accept(delta);
  }
  return best_y;
}

// One annealing chain. Where the schedule ends by its move count (small meshes: ram's whole
// schedule takes 0.3 s), the penalty continuation spends 60 % of a short schedule on the relaxed
// problem and can end above an annealing on Eq. 9 throughout (round-1 selection at 0.4, 5 s:
// opensubdiv_car_cage 1 362.2 → 1 583.9, hitachi395 650.5 → 698.5, frankie 876.8 → 909.4 when the
// continuation came in). So there the plain schedule (SelectionParams::anneal_plain_when_short)
// runs too, from the same start, and the lower Eq. 9 wins (1 362.2, 646.5, 882.2); on large
// meshes the schedule ends by time and only the continuation runs.
std::vector<std::uint8_t> anneal_chain(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                       std::vector<std::uint8_t> y, std::uint64_t target,
                                       const SelectionParams& params, double seconds,
                                       const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                       AnnealStats& stats, AnnealGoal goal = {}) {
  Stopwatch clock;
  const bool continuation = goal.kind == AnnealGoal::Kind::Band && params.anneal_plain_when_short &&
                            (params.anneal_count_weight != 1.0 || params.anneal_band_relax != 0.0);
  std::vector<std::uint8_t> start = continuation ? y : std::vector<std::uint8_t>{};
  std::vector<std::uint8_t> best =
      anneal(g, gc, fg, std::move(y), target, params, seconds, adj_offsets, adjacent, stats, goal);
  if (!continuation || !stats.schedule_done || clock.seconds() >= 0.5 * seconds) return best;
  SelectionParams plain = params;
  plain.anneal_count_weight = 1.0;
  plain.anneal_band_relax = 0.0;
  AnnealStats plain_stats;
  std::vector<std::uint8_t> other =
      anneal(g, gc, fg, std::move(start), target, plain, seconds - clock.seconds(), adj_offsets, adjacent, plain_stats);
  stats.moves += plain_stats.moves;
  stats.accepted += plain_stats.accepted;
  stats.compounds += plain_stats.compounds;
  if (group_objective(g, gc, fg, other, target, params) < group_objective(g, gc, fg, best, target, params)) {
    stats.schedule_done = plain_stats.schedule_done;
    return other;
  }
  return best;
}

// Scratch of anneal_component, kept across calls.
struct ComponentScratch {
  MoveScratch moves;
  std::vector<std::uint8_t> best;
};

// One priced annealing (cost + μ N', no band) of the groups of one free component, in a state
// shared with the other components: no term of Eq. 9 but the count couples components, and the
// price makes the count separable, so the component's moves see only its own groups. The moves
// are those of anneal() (flip, swap with a neighbour, chain along split partners); the schedule
// runs t0 → t1 over `moves` moves, or ends early at the clock's `deadline`. The state ends at the
// best selection of the component the run met; returns its value minus the start's.
double anneal_component(SelectionState& st, const Groups& g, const GroupConstraints& gc,
                        const Index* movable, std::size_t m, double mu, std::int64_t moves,
                        const SelectionParams& params, const std::vector<Index>& adj_offsets,
                        const std::vector<Index>& adjacent, std::mt19937_64& rng, ComponentScratch& sc,
                        const Stopwatch& clock, double deadline, std::int64_t& moves_done) {
  if (m == 0) return 0.0;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  sc.best.resize(m);
  for (std::size_t i = 0; i < m; ++i) sc.best[i] = st.y[movable[i]];
  double current = 0.0, best = 0.0;
  const double t0 = params.anneal_t0, t1 = params.anneal_t1;
  double temperature = t0;
  auto take = [&](double delta) {
    current += delta;
    if (current < best - 1e-9) {
      best = current;
      for (std::size_t i = 0; i < m; ++i) sc.best[i] = st.y[movable[i]];
    }
  };
  auto rejected = [&](double delta) { return delta > 0.0 && unit(rng) >= std::exp(-delta / temperature); };
  std::int64_t k = 0;
  for (; k < moves; ++k) {
    if ((k & 255) == 0) {
      if ((k & 16383) == 0 && k > 0 && clock.seconds() >= deadline) break;
      temperature = t0 * std::pow(t1 / t0, double(k) / double(moves));
    }
    const Index a = movable[rng() % m];
    const std::uint64_t kind = rng() % 3;
    sc.moves.flipped.clear();
    const std::int64_t c0 = st.count;
    if (kind == 0 || (kind == 1 && adj_offsets[a] == adj_offsets[a + 1])) {
      // judged before it is made, as in anneal()
      const std::int64_t dc = st.delta_count(a);
      const double delta = mu * double(dc) + st.delta_rest(a, params);
      if (rejected(delta) || (st.y[a] && !st.may_collapse(a))) continue;
      st.flip(a, dc);
      take(delta);
      continue;
    }
    double rest = 0.0;
    if (kind == 1 ? !swap_move(st, g, a, adj_offsets, adjacent, rng, params, rest, sc.moves)
                  : !chain_move(st, g, gc, a, rng, params, rest, sc.moves))
      continue;
    const double delta = rest + mu * double(st.count - c0);
    if (rejected(delta)) {
      undo_journaled(st, sc.moves);
      continue;
    }
    take(delta);
  }
  moves_done += k;
  // Back to the best state: flip() does not check Eq. 8, and the end state (the best) kept it.
  for (std::size_t i = 0; i < m; ++i)
    if (st.y[movable[i]] != sc.best[i]) st.flip(movable[i], st.delta_count(movable[i]));
  return best;
}

// A priced run by component (SelectionParams::priced_by_component): from `y`, in rounds of
// growing effort. Round r gives every component still open two annealings of
// priced_moves_per_group × factor^r moves per group, each from the component's state in `y`; a
// component whose two annealings end at the same value, equal to its best so far, is closed.
// Rounds go on up to priced_moves_per_group_max while `seconds` last. Every component ends at
// the best state it met (its state in `y` if that is lower). Why: the annealing of the whole mesh
// spends the same moves on every group, but most components of a many-part mesh settle in the
// first round (c172p at 0.4, 5 s: about 2.2 annealings per component and run), and a few reach
// states 8 – 18 lower only now and then at 1 600 moves per group (μ = 0.3, eight seeds;
// docs/formulation.md).
std::vector<std::uint8_t> anneal_priced_components(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                                   const FreeComponents& fc, std::vector<std::uint8_t> y,
                                                   double mu, const SelectionParams& params, double seconds,
                                                   const std::vector<Index>& adj_offsets,
                                                   const std::vector<Index>& adjacent, AnnealStats& stats) {
  Stopwatch clock;
  SelectionState st(g, gc, fg, std::move(y));
  const std::vector<std::uint8_t> start = st.y;
  std::vector<std::uint8_t> best_y = st.y;
  std::vector<double> best(fc.count, 0.0);  // relative to the start
  std::vector<Index> open(fc.count);
  std::iota(open.begin(), open.end(), Index{0});
  std::mt19937_64 rng(params.solve.seed);
  ComponentScratch sc;
  const double factor = std::max(params.priced_moves_factor, 1.0 + 1e-9);
  // At most the moves of a whole-mesh schedule (anneal_moves_per_group per free group): where
  // schedules end by their move count (small meshes), more runs in the same time do better.
  const double budget = params.anneal_moves_per_group * double(fc.offsets.back());
  const std::int64_t moves_before = stats.moves;
  auto spent = [&] { return clock.seconds() >= seconds || double(stats.moves - moves_before) >= budget; };
  for (double per_group = params.priced_moves_per_group;
       !open.empty() && per_group <= params.priced_moves_per_group_max * (1.0 + 1e-9); per_group *= factor) {
    std::size_t kept_open = 0;
    for (std::size_t i = 0; i < open.size(); ++i) {
      const Index c = open[i];
      const Index* movable = &fc.groups[fc.offsets[c]];
      const std::size_t m = fc.offsets[c + 1] - fc.offsets[c];
      const auto moves = static_cast<std::int64_t>(std::ceil(per_group * double(m)));
      double value[2] = {INFINITY, INFINITY};
      for (double& v : value) {
        if (spent()) break;
        for (std::size_t j = 0; j < m; ++j)  // from the start: restarts, not continuations
          if (st.y[movable[j]] != start[movable[j]]) st.flip(movable[j], st.delta_count(movable[j]));
        v = anneal_component(st, g, gc, movable, m, mu, moves, params, adj_offsets, adjacent, rng, sc, clock,
                             seconds, stats.moves);
        ++stats.component_runs;
        if (v < best[c] - 1e-9) {
          best[c] = v;
          for (std::size_t j = 0; j < m; ++j) best_y[movable[j]] = st.y[movable[j]];
        }
      }
      if (spent()) {
        kept_open = 0;
        open.clear();
        break;
      }
      const bool settled = std::abs(value[0] - value[1]) <= 1e-9 && std::abs(value[0] - best[c]) <= 1e-9;
      if (!settled) open[kept_open++] = c;
    }
    open.resize(kept_open);
  }
  return best_y;
}

// Annealing runs on `threads` threads (issue 4; docs/formulation.md, "Speed"). Each thread runs
// annealing chains one after the other from the same start: params.anneal_runs of them, each an
// equal share of what is left of its time, and more while at least half the last run's time is
// left (a schedule that ends by its move count leaves time: small meshes, long budgets), up to
// params.anneal_max_runs per thread. Run i
// (in the order thread 0's first, thread 1's first, …, thread 0's second, …) has seed
// solve.seed + i. The run with the lowest Eq. 9 is returned (ties: the lowest seed); the others,
// best first, go to `alternatives` (at most params.anneal_max_alternatives): the recombination
// takes each independent component from whichever run did best there. On c172p the runs end
// 5-10 % apart in Eq. 9, but not in the same components, so the combination lies below every
// run; one long run per thread, whose results only compete as a best-of-k, ends higher. Every
// other run is a priced one where runs are recombined (below; SelectionParams::anneal_prices).
std::vector<std::uint8_t> anneal_runs(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                      std::vector<std::uint8_t> y, std::uint64_t target,
                                      const SelectionParams& params, double seconds,
                                      const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                      int threads, AnnealStats& stats,
                                      std::vector<std::vector<std::uint8_t>>* alternatives) {
  threads = std::max(threads, 1);
  // Runs split a thread's time only where the recombination can combine them: with one component
  // holding most free groups they only compete as a best-of-n, and one longer run per thread is
  // better (oakeshott_sword_quaddominant, 0.4, 5 s, 2 threads: Eq. 9 -1 849.3 with two runs per
  // thread, -1 870.2, -1 898.4, -1 881.5 with one). The extra runs after schedules that end by
  // their move count stay everywhere: on small meshes their best-of-n beats the neighbourhood
  // MIPs that would get the time instead (5 s, 2 threads, with / without them: collada_duck
  // 142.7 / 167.8, opensubdiv_bishop_cage 97.0 / 103.1, blender_suzanne 641.8 / 646.6;
  // assimp_suzanne_subdiv is the exception, -10 263.7 / -10 288.2).
  int planned = std::max(params.anneal_runs, 1);
  FreeComponents components;
  if (planned > 1) {
    components = free_components(g, gc, fg);
    Index largest = 0;
    for (Index c = 0; c < components.count; ++c)
      largest = std::max(largest, components.offsets[c + 1] - components.offsets[c]);
    if (double(largest) > params.anneal_runs_max_share * double(components.offsets.back())) planned = 1;
  }
  Stopwatch clock;
  struct Run {
    std::uint32_t index;  // seed offset
    bool priced = false;
    double value;         // Eq. 9; INFINITY for a priced run (never the incumbent)
    std::vector<std::uint8_t> y;
    AnnealStats stats;
  };
  std::vector<std::vector<Run>> runs(static_cast<std::size_t>(threads));
  // Where the runs are recombined, every other run of a thread (its second, fourth, …) is a
  // priced one, at a price of the count term's slope at the thread's first run (0 inside the
  // band's middle, ±1 near its edges, as in the recombination) plus the next offset of
  // anneal_prices (mirrored below the band), so that each component also offers states at the
  // exchange rates of triangle-equivalents against Eq. 9's other terms. With priced_by_component
  // it anneals the components one by one from the thread's first run (anneal_priced_components).
  const bool priced_runs = planned > 1 && !params.anneal_prices.empty();
  const auto band = static_cast<std::int64_t>(std::floor(params.epsilon_n * double(target)));
  auto work = [&](int k) {
    double last = 0.0;
    double slope = 0.0;
    for (int r = 0;; ++r) {
      const double left = seconds - clock.seconds();
      if (left <= 0.0 || r >= params.anneal_max_runs || (r >= planned && left < 0.5 * last)) break;
      Run run;
      run.index = static_cast<std::uint32_t>(r * threads + k);
      SelectionParams p = params;
      p.solve.seed = params.solve.seed + run.index;
      std::optional<double> price;
      if (priced_runs && r % 2 == 1) {
        // priced runs in the order thread 0's first, thread 1's first, …
        const auto i = std::size_t(r / 2) * std::size_t(threads) + std::size_t(k);
        const double offset = params.anneal_prices[i % params.anneal_prices.size()];
        price = slope + (slope < 0.0 ? -offset : offset);
      }
      Stopwatch run_clock;
      const double share = left / double(std::max(1, planned - r));
      if (price && params.priced_by_component)  // from the thread's first (plain) run
        run.y = anneal_priced_components(g, gc, fg, components, runs[std::size_t(k)].front().y, *price, p, share,
                                         adj_offsets, adjacent, run.stats);
      else
        run.y = anneal_chain(g, gc, fg, y, target, p, share, adj_offsets, adjacent, run.stats,
                             price ? AnnealGoal::priced(*price) : AnnealGoal{});
      last = run_clock.seconds();
      run.priced = price.has_value();
      run.value = run.priced ? INFINITY : group_objective(g, gc, fg, run.y, target, params);
      if (r == 0) {
        const auto d = static_cast<std::int64_t>(selection_count(fg, run.y)) - static_cast<std::int64_t>(target);
        slope = count_slope(d, band);
      }
      runs[std::size_t(k)].push_back(std::move(run));
    }
  };
  if (threads == 1) {
    work(0);
  } else {
    std::vector<std::thread> workers;
    for (int k = 0; k < threads; ++k) workers.emplace_back(work, k);
    for (std::thread& w : workers) w.join();
  }
  std::vector<Run> all;
  for (auto& thread_runs : runs)
    for (Run& run : thread_runs) all.push_back(std::move(run));
  stats = {};
  if (all.empty()) return y;
  std::sort(all.begin(), all.end(),
            [](const Run& a, const Run& b) { return a.value < b.value || (a.value == b.value && a.index < b.index); });
  for (const Run& run : all) {
    stats.priced_runs += run.priced;
    stats.moves += run.stats.moves;
    stats.accepted += run.stats.accepted;
    stats.compounds += run.stats.compounds;
    stats.component_runs += run.stats.component_runs;
  }
  stats.runs = static_cast<int>(all.size());
  stats.schedule_done = all.front().stats.schedule_done;
  if (alternatives)
    for (std::size_t i = 1; i < all.size() && alternatives->size() < params.anneal_max_alternatives; ++i)
      alternatives->push_back(std::move(all[i].y));
  return std::move(all.front().y);
}

// Reaching Eq. 2's band from a start the hard constraints stopped the greedy short of
// (SelectionParams::reach_time_fraction; docs/formulation.md, "Targets the greedy misses"): one
// Reach annealing run per thread (seed solve.seed + k) for `seconds`; the state nearest the band
// wins, then the lowest Eq. 9. The greedy collapses groups cheapest first and skips any whose
// collapse Eq. 8 forbids at that moment, so where triangle clusters interleave its early choices
// can block more triangle-equivalents than they remove; the annealing undoes such choices.
std::vector<std::uint8_t> reach_band(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                     const std::vector<std::uint8_t>& y, std::uint64_t target,
                                     const SelectionParams& params, double seconds,
                                     const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                     int threads, AnnealStats& stats) {
  threads = std::max(threads, 1);
  std::vector<std::vector<std::uint8_t>> ends(static_cast<std::size_t>(threads));
  std::vector<AnnealStats> run_stats(static_cast<std::size_t>(threads));
  auto work = [&](int k) {
    SelectionParams p = params;
    p.solve.seed = params.solve.seed + static_cast<std::uint32_t>(k);
    p.anneal_t0 = params.reach_t0;
    ends[std::size_t(k)] = anneal(g, gc, fg, y, target, p, seconds, adj_offsets, adjacent, run_stats[std::size_t(k)],
                                  AnnealGoal::reach(params.reach_band_penalty));
  };
  if (threads == 1) {
    work(0);
  } else {
    std::vector<std::thread> workers;
    for (int k = 0; k < threads; ++k) workers.emplace_back(work, k);
    for (std::thread& w : workers) w.join();
  }
  const double n = double(target), band = params.epsilon_n * n;
  auto key = [&](const std::vector<std::uint8_t>& s) {
    const double beyond = std::max(0.0, std::abs(double(selection_count(fg, s)) - n) - band);
    return std::pair(beyond, group_objective(g, gc, fg, s, target, params));
  };
  std::size_t best = 0;
  for (std::size_t k = 1; k < ends.size(); ++k)
    if (key(ends[k]) < key(ends[best])) best = k;
  stats = {};
  for (const AnnealStats& rs : run_stats) {
    stats.moves += rs.moves;
    stats.accepted += rs.accepted;
  }
  stats.runs = threads;
  return std::move(ends[best]);
}

// ------------------------------------------------------------------------------------------
// Recombination of independent parts (beyond the paper; docs/formulation.md, "Speed"). The free
// groups fall into components that share no term of Eq. 9 and no constraint: two free groups are
// in one component if they share a face (t_f), an Eq. 6 cluster, an Eq. 7 cluster or an Eq. 8
// pair of clusters (split pairs share a face). Only the count row |N' − N| (Eqs. 1–2) couples the
// components, so Eq. 9 = |Σ_c N'_c + N'_fixed − N| + Σ_c cost_c(y_c). A price μ per
// triangle-equivalent in place of the count term makes the problem separable (a Lagrangian
// relaxation of Eq. 1): a descent on cost + μ N' from the incumbent improves every component on
// its own. Each price's end state offers every component an alternative (ΔN'_c, Δcost_c); a
// multiple-choice knapsack over the count offset (a dynamic programme over N' − N within Eq. 2's
// band) then picks one alternative per component (or its incumbent) minimising Eq. 9 exactly.
// A component collapsing a chord at a loss of less than a triangle-equivalent per removed one
// can so be paired with a component keeping a chord elsewhere for more than that — a pair the
// count term's price of 1 in both directions hides from every single move and from regions that
// do not hold both parts. c172p (an aircraft of many separate parts) has 968 components, the
// largest of 554 of its 22 131 free groups.

// Per component: its N'_c (faces with a free group in it) and cost_c (Eq. 9 without the count
// term: λ_edge, λ_geo and λ_tri terms of its groups, clusters and split pairs).
void component_totals(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg, const FreeComponents& fc,
                      const std::vector<std::uint8_t>& y, const SelectionParams& params,
                      std::vector<std::int64_t>& count, std::vector<double>& cost) {
  count.assign(fc.count, 0);
  cost.assign(fc.count, 0.0);
  for (Index f = 0; f + 1 < fg.offsets.size(); ++f)
    for (Index i = fg.offsets[f]; i < fg.offsets[f + 1]; ++i)
      if (const Index c = fc.of_group[fg.group[i]]; c != kInvalidIndex) {
        count[c] += face_count(fg, f, y);
        break;
      }
  for (Index x = 0; x < g.count; ++x)
    if (fc.of_group[x] != kInvalidIndex) cost[fc.of_group[x]] -= params.lambda_edge * y[x] * g.importance[x];
  for (const auto& cl : gc.geo)
    if (std::none_of(cl.begin(), cl.end(), [&](Index x) { return y[x]; })) cost[fc.of_group[cl[0]]] += params.lambda_geo;
  for (const auto& [a, b] : gc.split_pairs)
    if (y[a] != y[b]) cost[fc.of_group[g.fixed[a] ? b : a]] += params.lambda_tri;
}

// Descent on cost + μ N' (no count term, no band: the recombination enforces Eq. 2): single
// flips, swaps with an adjacent group of the other value, and chains along split partners (as
// chain_moves), while they lower it; Eq. 8 is kept.
void priced_descent(SelectionState& st, const Groups& g, const GroupConstraints& gc, double mu,
                    const SelectionParams& params, const std::vector<Index>& adj_offsets,
                    const std::vector<Index>& adjacent, const Stopwatch& clock, double seconds) {
  constexpr double eps = 1e-9;
  int passes = 0;
  for (bool improved = true; improved && clock.seconds() < seconds && passes < params.recombination_passes;) {
    improved = false;
    ++passes;
    for (Index a = 0; a < g.count; ++a) {
      if (g.fixed[a]) continue;
      const std::int64_t dc = st.delta_count(a);
      if (st.delta_rest(a, params) + mu * double(dc) < -eps && (!st.y[a] || st.may_collapse(a))) {
        st.flip(a, dc);
        improved = true;
      }
    }
    improved |= swap_walk(
                    st, g, params, adj_offsets, adjacent, clock, seconds, [&](std::int64_t c) { return mu * double(c); },
                    [](std::int64_t) { return true; }, false) > 0;
    improved |= chain_walk(
                    st, g, gc, params, clock, seconds, [&](std::int64_t c) { return mu * double(c); },
                    [](std::int64_t) { return true; }) > 0;
  }
}

struct RecombineStats {
  Index rounds = 0, improved = 0, components = 0, moved = 0;
  Index largest = 0;  // free groups of the largest component
};

// Rounds of: one priced descent per price from the incumbent, then the dynamic programme over
// the components' alternatives; a round that does not lower Eq. 9 ends the search. y must lie in
// Eq. 2's band; the result does too.
std::vector<std::uint8_t> recombine_components(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                               std::vector<std::uint8_t> y, std::uint64_t target,
                                               const SelectionParams& params, double seconds,
                                               const std::vector<Index>& adj_offsets,
                                               const std::vector<Index>& adjacent, RecombineStats& stats,
                                               const std::vector<std::vector<std::uint8_t>>& alternatives = {}) {
  Stopwatch clock;
  const FreeComponents fc = free_components(g, gc, fg);
  stats.components = fc.count;
  for (Index c = 0; c < fc.count; ++c) stats.largest = std::max(stats.largest, fc.offsets[c + 1] - fc.offsets[c]);
  const std::vector<double>& prices = params.recombination_prices;
  if (fc.count == 0 || (prices.empty() && alternatives.empty())) return y;
  const auto n = static_cast<std::int64_t>(target);
  const auto band = static_cast<std::int64_t>(std::floor(params.epsilon_n * double(target)));
  std::vector<std::int64_t> count0, count1;
  std::vector<double> cost0, cost1;
  // The alternatives (other annealing runs), then the end states of the priced descents; an
  // option names its state in a byte.
  std::vector<std::vector<std::uint8_t>> states(std::min<std::size_t>(alternatives.size() + prices.size(), 255));
  struct Option {
    std::int64_t dc;
    double dcost;
    std::uint8_t state;
  };
  std::vector<std::vector<Option>> options(fc.count);
  std::vector<double> dp, next;
  std::vector<std::uint8_t> choice;
  std::vector<Index> with_options;
  while (clock.seconds() < seconds && stats.rounds < params.recombination_rounds) {
    ++stats.rounds;
    component_totals(g, gc, fg, fc, y, params, count0, cost0);
    std::int64_t total = 0;
    {
      SelectionState st(g, gc, fg, y);
      total = st.count;
    }
    for (auto& o : options) o.clear();
    // The count term's slope at the incumbent: 0 between its two sides at N' = N (prices go up
    // from there: keeping a group always gains λ_edge Q), ±1 near the band's edges, where one
    // direction is closed (cg57 sits on the upper edge); the prices are offsets from it.
    const double slope = count_slope(total - n, band);
    for (std::size_t k = 0; k < states.size() && clock.seconds() < seconds; ++k) {
      if (k < alternatives.size()) {
        states[k] = alternatives[k];
      } else {
        const double mu = prices[k - alternatives.size()];
        SelectionState st(g, gc, fg, y);
        priced_descent(st, g, gc, slope + (slope < 0.0 ? -mu : mu), params, adj_offsets, adjacent, clock, seconds);
        states[k] = std::move(st.y);
      }
      component_totals(g, gc, fg, fc, states[k], params, count1, cost1);
      for (Index c = 0; c < fc.count; ++c) {
        const std::int64_t dc = count1[c] - count0[c];
        const double dcost = cost1[c] - cost0[c];
        if (dc == 0 && dcost >= -1e-9) continue;  // no better than the incumbent
        auto& opts = options[c];
        auto same = std::find_if(opts.begin(), opts.end(), [&](const Option& o) { return o.dc == dc; });
        if (same == opts.end()) opts.push_back({dc, dcost, static_cast<std::uint8_t>(k)});
        else if (dcost < same->dcost) *same = {dc, dcost, static_cast<std::uint8_t>(k)};
      }
    }
    // The programme (also when the time cut the descents short: every state they reached is a
    // valid alternative, and the programme takes milliseconds): dp[s] = least Σ Δcost over the components so far with N' − N = s + lo; the
    // range covers Eq. 2's band and the incumbent's count (which may lie outside it: then any
    // combination in the band is taken), widened by the largest |ΔN'| the components' options
    // can add up to, so that partial sums outside the band that end inside it are not lost (the
    // programme is then exact); the widening is capped at max(2 × band, 1 024) for memory.
    std::int64_t reach = 0;
    for (const auto& opts : options) {
      std::int64_t most = 0;
      for (const Option& o : opts) most = std::max(most, std::abs(o.dc));
      reach += most;
    }
    reach = std::min(reach, std::max<std::int64_t>(2 * band, 1024));
    const std::int64_t d0 = total - n, lo = std::min(-band, d0) - reach, hi = std::max(band, d0) + reach;
    const std::size_t width = std::size_t(hi - lo + 1);
    dp.assign(width, INFINITY);
    with_options.clear();
    for (Index c = 0; c < fc.count; ++c)
      if (!options[c].empty()) with_options.push_back(c);
    if (with_options.empty()) break;
    dp[std::size_t(d0 - lo)] = 0.0;
    choice.assign(with_options.size() * width, 0);
    for (std::size_t i = 0; i < with_options.size(); ++i) {
      const auto& opts = options[with_options[i]];
      next = dp;  // choice 0: the incumbent
      std::uint8_t* ch = &choice[i * width];
      for (std::size_t s = 0; s < width; ++s) {
        if (!(dp[s] < INFINITY)) continue;
        for (std::size_t k = 0; k < opts.size(); ++k) {
          const std::int64_t t = std::int64_t(s) + opts[k].dc;
          if (t < 0 || t >= std::int64_t(width)) continue;
          const double v = dp[s] + opts[k].dcost;
          if (v < next[std::size_t(t)] - 1e-12) next[std::size_t(t)] = v, ch[t] = static_cast<std::uint8_t>(k + 1);
        }
      }
      dp.swap(next);
    }
    const double before = std::abs(d0) <= band ? double(std::abs(d0)) : INFINITY;
    std::size_t best_s = std::size_t(d0 - lo);
    double best = before;  // every incumbent kept
    for (std::int64_t d = -band; d <= band; ++d) {
      const std::size_t s = std::size_t(d - lo);
      if (dp[s] < INFINITY && dp[s] + double(std::llabs(d)) < best - 1e-9) best = dp[s] + double(std::llabs(d)), best_s = s;
    }
    if (!(best < before - 1e-9) || !(best < INFINITY)) break;
    // Back-track: component i's choice at state s; the previous state is s − its Δcount.
    for (std::size_t i = with_options.size(); i-- > 0;) {
      const std::uint8_t k = choice[i * width + best_s];
      if (k == 0) continue;
      const Index c = with_options[i];
      const Option& o = options[c][k - 1];
      for (Index j = fc.offsets[c]; j < fc.offsets[c + 1]; ++j) y[fc.groups[j]] = states[o.state][fc.groups[j]];
      best_s = std::size_t(std::int64_t(best_s) - o.dc);
      ++stats.moved;
    }
    ++stats.improved;
  }
  return y;
}

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

std::vector<std::uint8_t> priced_anneal(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                        std::uint64_t target, const SelectionParams& params,
                                        const std::vector<std::uint8_t>& edge_kept, double price, double seconds) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  AnnealStats as;
  return p.edge_bits(conn, anneal_chain(p.groups, p.gc, p.fg, p.y, target, params, seconds, p.adj_offsets,
                                        p.adjacent, as, AnnealGoal::priced(price)));
}

std::vector<std::uint8_t> priced_component_anneal(const PolyMesh& mesh, const Connectivity& conn,
                                                  const AnalysisResult& analysis, const SelectionParams& params,
                                                  const std::vector<std::uint8_t>& edge_kept, double price,
                                                  double seconds) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  AnnealStats as;
  const FreeComponents fc = free_components(p.groups, p.gc, p.fg);
  return p.edge_bits(conn, anneal_priced_components(p.groups, p.gc, p.fg, fc, p.y, price, params, seconds,
                                                    p.adj_offsets, p.adjacent, as));
}

std::vector<std::uint8_t> reach_band(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                     std::uint64_t target, const SelectionParams& params,
                                     const std::vector<std::uint8_t>& edge_kept, double seconds) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  AnnealStats as;
  return p.edge_bits(conn, quadlod::reach_band(p.groups, p.gc, p.fg, p.y, target, params, seconds, p.adj_offsets,
                                               p.adjacent, ilp::backend::resolve_threads(params.solve), as));
}

std::vector<std::uint8_t> recombine(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                    std::uint64_t target, const SelectionParams& params,
                                    const std::vector<std::uint8_t>& edge_kept, Index* components,
                                    const std::vector<std::vector<std::uint8_t>>& alternatives) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  std::vector<std::vector<std::uint8_t>> states;
  for (const std::vector<std::uint8_t>& kept : alternatives) states.push_back(prepare(mesh, conn, analysis, params, kept).y);
  RecombineStats stats;
  const std::vector<std::uint8_t> y = recombine_components(p.groups, p.gc, p.fg, p.y, target, params, INFINITY,
                                                           p.adj_offsets, p.adjacent, stats, states);
  if (components) *components = stats.components;
  return p.edge_bits(conn, y);
}

}  // namespace detail

}  // namespace quadlod
