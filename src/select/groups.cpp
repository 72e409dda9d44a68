// The decision space of the edge selection (groups.h): decision groups (Eq. 4), Eqs. 6–8 and the
// face terms of Eq. 1 in group space, the incremental SelectionState, Eq. 1 / Eq. 9 on group
// bits, and the stage's public helpers edge_importance (Q(e) of Eq. 9), predicted_tri_equivalent
// (N' of Eq. 1) and predicted_new_triangles.
#include "select/groups.h"

#include "geometry/quadric.h"
#include "mesh/union_find.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace quadlod {

std::vector<double> edge_importance(const PolyMesh& mesh, const Connectivity& conn, double cap) {
  // Vertex quadrics: area-weighted planes of the incident faces (Garland & Heckbert 1997).
  std::vector<Quadric> vq(mesh.num_vertices());
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Vec3 area = face_area_vector(mesh, f);
    const double a = area.norm();
    if (!(a > 0.0)) continue;
    const Quadric q = a * Quadric::plane(face_centroid(mesh, f), area / a);
    for (Index v : mesh.face_vertices(f)) vq[v] += q;
  }
  std::vector<double> q(conn.num_edges, 0.0);
  double sum = 0.0;
  Index positive = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    q[e] = (vq[a] + vq[b]).minimize_on_segment(mesh.positions[a], mesh.positions[b]).error;
    if (q[e] > 0.0) {
      sum += q[e];
      ++positive;
    }
  }
  if (positive == 0) return q;
  const double mean = sum / positive;
  for (double& v : q) v = std::min(v / mean, cap);
  return q;
}

std::uint64_t predicted_tri_equivalent(const PolyMesh& mesh, const Connectivity& conn,
                                       const std::vector<std::uint8_t>& edge_kept) {
  std::uint64_t n = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    Index kept = 0;
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) kept += edge_kept[conn.corner_edge[c]];
    n += kept > 2 ? kept - 2 : 0;
  }
  return n;
}

std::uint64_t predicted_new_triangles(const PolyMesh& mesh, const Connectivity& conn,
                                      const std::vector<std::uint8_t>& edge_kept) {
  std::uint64_t n = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    if (mesh.face_size(f) != 4) continue;
    Index kept = 0;
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) kept += edge_kept[conn.corner_edge[c]];
    n += kept == 3;
  }
  return n;
}

std::vector<double> selection_importance(const PolyMesh& mesh, const Connectivity& conn, const SelectionParams& params) {
  std::vector<double> importance = edge_importance(mesh, conn, params.importance_cap);
  if (params.extra_importance.size() == importance.size())
    for (std::size_t e = 0; e < importance.size(); ++e) importance[e] += params.extra_importance[e];
  return importance;
}

namespace select_detail {

Groups make_groups(const Connectivity& conn, const AnalysisResult& analysis,
                   const std::vector<double>& importance, const SelectionParams& params) {
  UnionFind uf(conn.num_edges);
  if (params.consistency)
    for (const Segment& s : analysis.segmentation.segments)
      for (std::size_t i = 1; i < s.opposing_edges.size(); ++i)
        uf.unite(s.opposing_edges[0], s.opposing_edges[i]);
  Groups g;
  g.edge_group = uf.dense_labels(g.count);
  g.offsets.assign(std::size_t{g.count} + 1, 0);
  for (Index e = 0; e < conn.num_edges; ++e) ++g.offsets[g.edge_group[e] + 1];
  std::partial_sum(g.offsets.begin(), g.offsets.end(), g.offsets.begin());
  g.edges.resize(conn.num_edges);
  std::vector<Index> fill(g.offsets.begin(), g.offsets.end() - 1);
  for (Index e = 0; e < conn.num_edges; ++e) g.edges[fill[g.edge_group[e]]++] = e;
  g.fixed.assign(g.count, 0);
  g.importance.assign(g.count, 0.0);
  for (Index e = 0; e < conn.num_edges; ++e) {
    g.importance[g.edge_group[e]] += importance[e];
    if (params.keep_nonmanifold_edges && conn.is_nonmanifold_edge(e)) g.fixed[g.edge_group[e]] = 1;
    if (!params.keep_edges.empty() && params.keep_edges[e]) g.fixed[g.edge_group[e]] = 1;
  }
  return g;
}

// Distinct groups of a list of edges, sorted.
std::vector<Index> distinct_groups(const Groups& g, const std::vector<Index>& edges) {
  std::vector<Index> out;
  out.reserve(edges.size());
  for (Index e : edges) out.push_back(g.edge_group[e]);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

GroupConstraints make_group_constraints(const PolyMesh& mesh, const Connectivity& conn, const Groups& g,
                                        const AnalysisResult& analysis, const SelectionParams& params) {
  GroupConstraints c;
  c.group_geo.resize(g.count);
  c.group_tri.resize(g.count);
  c.group_split.resize(g.count);
  if (params.lambda_tri > 0.0)
    for_each_opposite_pair(mesh, conn, [&](Index e, Index f) {
      const Index a = g.edge_group[e], b = g.edge_group[f];
      if (a == b || (g.fixed[a] && g.fixed[b])) return;
      c.split_pairs.emplace_back(a, b);
      c.group_split[a].push_back(b);
      c.group_split[b].push_back(a);
    });
  if (!params.geometry) return c;
  for (const EdgeCluster& cluster : analysis.medial.clusters) {
    auto groups = distinct_groups(g, cluster.edges);
    if (groups.empty() || std::any_of(groups.begin(), groups.end(), [&](Index x) { return g.fixed[x]; }))
      continue;
    for (Index x : groups) c.group_geo[x].push_back(static_cast<Index>(c.geo.size()));
    c.geo.push_back(std::move(groups));
  }
  for (const TriangleCluster& cluster : analysis.triangles.clusters) {
    auto groups = distinct_groups(g, cluster.edges);
    for (Index x : groups) c.group_tri[x].push_back(static_cast<Index>(c.tri.size()));
    c.tri.push_back(std::move(groups));
  }
  c.tri_neighbours = analysis.triangles.neighbours;
  return c;
}

FaceGroups make_face_groups(const PolyMesh& mesh, const Connectivity& conn, const Groups& g) {
  FaceGroups fg;
  fg.offsets.push_back(0);
  std::vector<Index> scratch;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    scratch.clear();
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c)
      scratch.push_back(g.edge_group[conn.corner_edge[c]]);
    std::sort(scratch.begin(), scratch.end());
    for (std::size_t i = 0; i < scratch.size();) {
      std::size_t j = i;
      while (j < scratch.size() && scratch[j] == scratch[i]) ++j;
      fg.group.push_back(scratch[i]);
      fg.mult.push_back(static_cast<Index>(j - i));
      i = j;
    }
    fg.offsets.push_back(static_cast<Index>(fg.group.size()));
    fg.degree.push_back(mesh.face_size(f));
  }
  return fg;
}

SelectionState::SelectionState(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                               std::vector<std::uint8_t> bits)
    : y(std::move(bits)), g_(g) {
  // Everything a move evaluation touches is laid out per group in flat arrays (CSR), not in
  // the vectors of vectors of GroupConstraints: the annealing evaluates millions of moves and
  // was bound by these loads (perf on c172p: delta_count, delta_rest and may_collapse 54 % of
  // the selection's time).
  const Index nf = static_cast<Index>(fg.degree.size());
  face_offsets_.assign(std::size_t{g.count} + 1, 0);
  for (Index f = 0; f < nf; ++f)
    for (Index i = fg.offsets[f]; i < fg.offsets[f + 1]; ++i) ++face_offsets_[fg.group[i] + 1];
  std::partial_sum(face_offsets_.begin(), face_offsets_.end(), face_offsets_.begin());
  faces_.resize(face_offsets_.back());
  face_mult_.resize(face_offsets_.back());
  std::vector<Index> fill(face_offsets_.begin(), face_offsets_.end() - 1);
  for (Index f = 0; f < nf; ++f)
    for (Index i = fg.offsets[f]; i < fg.offsets[f + 1]; ++i) {
      faces_[fill[fg.group[i]]] = f;
      face_mult_[fill[fg.group[i]]++] = fg.mult[i];
    }
  // S_f, the kept edges of every face, kept up to date by flip().
  face_kept_.assign(nf, 0);
  for (Index f = 0; f < nf; ++f) {
    for (Index i = fg.offsets[f]; i < fg.offsets[f + 1]; ++i) face_kept_[f] += y[fg.group[i]] * fg.mult[i];
    count += face_kept_[f] > 2 ? face_kept_[f] - 2 : 0;
  }
  auto flatten = [&](const std::vector<std::vector<Index>>& lists, std::vector<Index>& offsets,
                     std::vector<Index>& items) {
    offsets.assign(1, 0);
    for (const auto& l : lists) {
      items.insert(items.end(), l.begin(), l.end());
      offsets.push_back(static_cast<Index>(items.size()));
    }
  };
  flatten(gc.group_geo, geo_offsets_, geo_);
  flatten(gc.group_split, split_offsets_, split_);
  // Eq. 8 per group: the clusters that must be untouched for grp to collapse (the neighbours
  // of its own clusters), and whether grp lies in such a neighbour itself (then never).
  std::vector<std::vector<Index>> tri_nbrs(gc.tri.size());
  for (const auto& [i, j] : gc.tri_neighbours) tri_nbrs[i].push_back(j);
  std::vector<std::vector<Index>> blocking(g.count);
  never_collapse_.assign(g.count, 0);
  for (Index grp = 0; grp < g.count; ++grp) {
    auto& l = blocking[grp];
    for (Index i : gc.group_tri[grp])
      for (Index j : tri_nbrs[i]) {
        l.push_back(j);
        if (std::binary_search(gc.tri[j].begin(), gc.tri[j].end(), grp)) never_collapse_[grp] = 1;
      }
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
  }
  flatten(blocking, blocking_offsets_, blocking_);
  flatten(gc.group_tri, tri_offsets_, tri_);
  geo_kept_.assign(gc.geo.size(), 0);
  for (std::size_t c = 0; c < gc.geo.size(); ++c)
    for (Index grp : gc.geo[c]) geo_kept_[c] += y[grp];
  tri_collapsed_.assign(gc.tri.size(), 0);
  for (std::size_t c = 0; c < gc.tri.size(); ++c)
    for (Index grp : gc.tri[c]) tri_collapsed_[c] += !y[grp];
}

Index count_collapsed_clusters(const GroupConstraints& gc, const std::vector<std::uint8_t>& y) {
  Index n = 0;
  for (const auto& groups : gc.geo)
    n += std::all_of(groups.begin(), groups.end(), [&](Index grp) { return !y[grp]; });
  return n;
}

// The slope of the count term |N' − N| (Eq. 9) that prices start from, for d = N' − N: 0 in the
// middle of Eq. 2's band, ±1 in its outer halves, where one direction is closed.
double count_slope(std::int64_t d, std::int64_t band) { return 2 * std::abs(d) > band ? (d > 0 ? 1.0 : -1.0) : 0.0; }

// N' (Eq. 1) of y.
std::uint64_t selection_count(const FaceGroups& fg, const std::vector<std::uint8_t>& y) {
  std::uint64_t count = 0;
  for (Index f = 0; f + 1 < fg.offsets.size(); ++f) count += face_count(fg, f, y);
  return count;
}

// Eq. 9 in group space — what the banded fast model evaluates to for the completion of y:
// |N' − N| + λ_geo · (clusters with every group collapsed) − λ_edge · Σ Q̂ y.
double group_objective(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                       const std::vector<std::uint8_t>& y, std::uint64_t target,
                       const SelectionParams& params) {
  const std::uint64_t count = selection_count(fg, y);
  double importance = 0.0;
  for (Index grp = 0; grp < g.count; ++grp) importance += y[grp] * g.importance[grp];
  double split = 0.0;
  for (const auto& [a, b] : gc.split_pairs) split += y[a] != y[b];
  return std::abs(double(count) - double(target)) + params.lambda_geo * double(count_collapsed_clusters(gc, y)) -
         params.lambda_edge * importance + params.lambda_tri * split;
}

// Groups that share a face, as CSR.
void group_adjacency(const Groups& g, const FaceGroups& fg, std::vector<Index>& offsets,
                     std::vector<Index>& adjacent) {
  std::vector<std::vector<Index>> lists(g.count);
  for (Index f = 0; f + 1 < fg.offsets.size(); ++f)
    for (Index i = fg.offsets[f]; i < fg.offsets[f + 1]; ++i)
      for (Index j = fg.offsets[f]; j < fg.offsets[f + 1]; ++j)
        if (i != j) lists[fg.group[i]].push_back(fg.group[j]);
  offsets.assign(std::size_t{g.count} + 1, 0);
  adjacent.clear();
  for (Index grp = 0; grp < g.count; ++grp) {
    auto& l = lists[grp];
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    adjacent.insert(adjacent.end(), l.begin(), l.end());
    offsets[grp + 1] = static_cast<Index>(adjacent.size());
  }
}

FreeComponents free_components(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg) {
  UnionFind uf(g.count);
  auto join = [&](auto begin, auto end) {
    Index first = kInvalidIndex;
    for (auto it = begin; it != end; ++it) {
      if (g.fixed[*it]) continue;
      if (first == kInvalidIndex) first = *it;
      else uf.unite(first, *it);
    }
  };
  for (Index f = 0; f + 1 < fg.offsets.size(); ++f) join(fg.group.begin() + fg.offsets[f], fg.group.begin() + fg.offsets[f + 1]);
  for (const auto& c : gc.geo) join(c.begin(), c.end());
  for (const auto& c : gc.tri) join(c.begin(), c.end());
  std::vector<Index> both;
  for (const auto& [i, j] : gc.tri_neighbours) {
    both = gc.tri[i];
    both.insert(both.end(), gc.tri[j].begin(), gc.tri[j].end());
    join(both.begin(), both.end());
  }
  for (const auto& [a, b] : gc.split_pairs) {
    const Index pair[2] = {a, b};
    join(pair, pair + 2);
  }
  FreeComponents fc;
  fc.of_group.assign(g.count, kInvalidIndex);
  std::vector<Index> of_root(g.count, kInvalidIndex);
  for (Index x = 0; x < g.count; ++x) {
    if (g.fixed[x]) continue;
    const Index r = uf.find(x);
    if (of_root[r] == kInvalidIndex) of_root[r] = fc.count++;
    fc.of_group[x] = of_root[r];
  }
  fc.offsets.assign(std::size_t{fc.count} + 1, 0);
  for (Index x = 0; x < g.count; ++x)
    if (fc.of_group[x] != kInvalidIndex) ++fc.offsets[fc.of_group[x] + 1];
  std::partial_sum(fc.offsets.begin(), fc.offsets.end(), fc.offsets.begin());
  fc.groups.resize(fc.offsets.back());
  std::vector<Index> fill(fc.offsets.begin(), fc.offsets.end() - 1);
  for (Index x = 0; x < g.count; ++x)
    if (fc.of_group[x] != kInvalidIndex) fc.groups[fill[fc.of_group[x]]++] = x;
  return fc;
}

Prepared prepare(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                 const SelectionParams& params, const std::vector<std::uint8_t>& edge_kept) {
  Prepared p;
  p.importance = selection_importance(mesh, conn, params);
  p.groups = make_groups(conn, analysis, p.importance, params);
  p.gc = make_group_constraints(mesh, conn, p.groups, analysis, params);
  p.fg = make_face_groups(mesh, conn, p.groups);
  p.y.assign(p.groups.count, 1);
  for (Index e = 0; e < conn.num_edges; ++e)
    if (!edge_kept[e]) p.y[p.groups.edge_group[e]] = 0;
  return p;
}

}  // namespace select_detail

}  // namespace quadlod
