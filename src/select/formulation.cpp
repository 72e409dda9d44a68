// The models of the edge selection, paper §3.2 (Eqs. 1–9): ModelBuilder and one solve of a built
// model (formulation.h). See src/select/selection.h for the two formulations and
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
#include "select/formulation.h"

#include "ilp/solver.h"
#include "util/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace quadlod::select_detail {

namespace {

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

// Sorted distinct values of lists[key] over the keys.
std::vector<Index> gather(const std::vector<Index>& keys, const std::vector<Index>& offsets,
                          const std::vector<Index>& values) {
  std::vector<Index> out;
  for (Index k : keys) out.insert(out.end(), values.begin() + offsets[k], values.begin() + offsets[k + 1]);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

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

// `band`: Eq. 2 (|N' − N| ≤ ϵ_N N); otherwise |N' − N| ≤ open_slack.
void ModelBuilder::build(std::uint64_t target, bool band, double open_slack) {
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

std::vector<double> ModelBuilder::complete(const std::vector<std::uint8_t>& y, std::uint64_t target) const {
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

std::vector<std::uint8_t> ModelBuilder::group_bits(const std::vector<double>& x) const {
  std::vector<std::uint8_t> y(g_.count);
  for (Index grp = 0; grp < g_.count; ++grp) y[grp] = x[group_col_[grp]] > 0.5;
  return y;
}

void ModelBuilder::read_free_groups(const std::vector<double>& x, std::vector<std::uint8_t>& y) const {
  for (Col c = 0; c < col_group_.size(); ++c)
    if (col_group_[c] != kInvalidIndex && (*free_)[col_group_[c]]) y[col_group_[c]] = x[c] > 0.5;
}

std::vector<std::uint8_t> ModelBuilder::edge_bits(const std::vector<double>& x) const {
  std::vector<std::uint8_t> kept(conn_.num_edges);
  for (Index e = 0; e < conn_.num_edges; ++e)
    kept[e] = x[exact_ ? edge_col_[e] : group_col_[g_.edge_group[e]]] > 0.5;
  return kept;
}

void ModelBuilder::add_group_col(Index grp) {
  double lo = g_.fixed[grp] ? 1.0 : 0.0, hi = 1.0;
  if (free_ && !(*free_)[grp]) lo = hi = (*base_)[grp];
  group_col_[grp] = model.add_var(ilp::VarType::Binary, lo, hi, -params_.lambda_edge * g_.importance[grp]);
  col_group_.resize(model.num_cols(), kInvalidIndex);
  col_group_[group_col_[grp]] = grp;
}

void ModelBuilder::build_fast_vars() {
  group_col_.assign(g_.count, kNone);
  if (index_) {
    for (Index grp : *free_list_) add_group_col(grp);
  } else {
    for (Index grp = 0; grp < g_.count; ++grp) add_group_col(grp);
  }
  stats.edge_groups = g_.count;
  stats.fixed_kept_groups = static_cast<Index>(std::count(g_.fixed.begin(), g_.fixed.end(), 1));
}

void ModelBuilder::build_exact_vars() {
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
std::vector<Term> ModelBuilder::face_terms(Index f) {
  std::vector<Term> terms;
  for (Index c = mesh_.face_begin(f); c < mesh_.face_end(f); ++c) {
    const Col col = edge_col(conn_.corner_edge[c]);
    auto it = std::find_if(terms.begin(), terms.end(), [&](const Term& t) { return t.col == col; });
    if (it == terms.end()) terms.push_back({col, 1.0});
    else it->coef += 1.0;
  }
  return terms;
}

void ModelBuilder::build_faces() {
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
        for (const Term& t : terms) model.add_le({{z, t.coef}, {t.col, -t.coef}}, 0.0);  // m z ≤ m y
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

bool ModelBuilder::face_touches_free(Index f) const {
  for (Index i = fg_.offsets[f]; i < fg_.offsets[f + 1]; ++i)
    if ((*free_)[fg_.group[i]]) return true;
  return false;
}

double ModelBuilder::group_size(Col col) const {
  const Index grp = col < col_group_.size() ? col_group_[col] : kInvalidIndex;
  return grp != kInvalidIndex ? double(g_.offsets[grp + 1] - g_.offsets[grp]) : 0.0;
}

// The paper's per-face rows: Eq. 3 and t_f = x_f (S_f − 2) linearised.
void ModelBuilder::add_general_face(const std::vector<Term>& terms, double k) {
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
void ModelBuilder::build_count(std::uint64_t target, double slack) {
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
void ModelBuilder::add_split(Col a, Col b) {
  const Col d = model.add_continuous(0.0, 1.0, params_.lambda_tri);
  model.add_ge({{d, 1.0}, {a, -1.0}, {b, 1.0}}, 0.0);
  model.add_ge({{d, 1.0}, {a, 1.0}, {b, -1.0}}, 0.0);
  split_.push_back({d, a, b});
}

void ModelBuilder::build_split_pairs() {
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
void ModelBuilder::build_geo_clusters() {
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
void ModelBuilder::build_tri_clusters() {
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

std::vector<double> solve_model(const ilp::Model& model, const SelectionParams& params, double seconds,
                                SelectionResult& result) {
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
  result.solve = solver->solve(model, sp);
  if (!params.quiet) std::fprintf(stderr, "\n");
  result.solver_ran = true;
  result.seconds_solve += solve_clock.seconds();
  std::vector<double> x = std::move(result.solve.solution);
  result.solve.solution.clear();
  return x;
}

}  // namespace quadlod::select_detail
