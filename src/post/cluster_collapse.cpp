// Cluster collapse — paper §3.3.2 ("QEM-based Simplification"). Contract: cluster_collapse.h;
// the weights and what they are based on: docs/cluster_collapse.md.
//
// Papers and code this file follows:
//   * Garland & Heckbert 1997, "Surface simplification using quadric error metrics": plane
//     quadrics of the faces around a vertex, summed over the cluster.
//   * Knodt 2025, "Single edge collapse quad-dominant mesh reduction" (TOG 44(4)), the per-vertex
//     weights §3.3.2 adopts. Taken from the author's public simplified re-implementation,
//     github.com/JulianKnodt/simple_qem (src/qem.rs, src/quadric.rs; its readme says it is not the
//     code used for the paper): face planes weighted by the corner's interior angle; for every
//     face edge, the plane through the edge that contains the face normal, weighted by
//     (dihedral angle / π, at least 0.01; 4 on boundary and non-manifold edges) · |e| / mean |e|,
//     added to both endpoints; placement under a volume-preservation constraint.
//   * Lindstrom & Turk 1998, "Fast and memory efficient polygonal simplification": volume
//     preservation as one linear equality constraint on the new position.
//   * Trettner & Kobbelt 2020, "Fast and robust QEF minimization using probabilistic quadrics":
//     an isotropic term so the 3×3 system is never singular.
//
// This file: setup, placement, splitting refused clusters, rebuilding faces, the driver, and the
// public functions. The class is declared in collapser.h; its checks are in collapse_checks.cpp,
// its UV-island guarantee in collapse_islands.cpp, its output in collapse_output.cpp.
#include "post/cluster_collapse.h"
#include "mesh/symmetry.h"

#include "geometry/bvh.h"
#include "geometry/quadric.h"
#include "geometry/sampling.h"
#include "mesh/union_find.h"
#include "post/collapser.h"
#include "util/parallel.h"
#include "util/progress.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <utility>

namespace quadlod {

namespace collapse_detail {

// --- setup ---------------------------------------------------------------------------------------

void Collapser::precompute() {
  nv_ = mesh_.num_vertices();
  nf_ = mesh_.num_faces();
  ne_ = conn_.num_edges;
  diag_ = bounding_box(mesh_).diagonal();
  if (!(diag_ > 0.0) || !std::isfinite(diag_)) diag_ = 1.0;

  // Per edge and per face on all threads (each item written by one chunk); the sum in edge order.
  edge_len_.resize(ne_);
  parallel_chunks(std::size_t(ne_), params_.threads, params_.min_parallel_faces, [&](std::size_t b, std::size_t e, std::size_t) {
    for (std::size_t i = b; i < e; ++i) {
      const auto [v, w] = conn_.edge_vertices[i];
      edge_len_[i] = (mesh_.positions[v] - mesh_.positions[w]).norm();
    }
  });
  double sum = 0.0;
  Index counted = 0;
  for (Index e = 0; e < ne_; ++e)
    if (edge_len_[e] > 0.0) {
      sum += edge_len_[e];
      ++counted;
    }
  h_ = counted > 0 ? sum / counted : diag_;

  zero_area_ = std::max(0.0, params_.zero_area_epsilon) * diag_ * diag_;
  zero_length_sq_ = std::pow(std::max(0.0, params_.zero_length_epsilon) * diag_, 2);
  const double flip = std::clamp(params_.flip_angle_deg, 1e-6, 180.0);
  cos_flip_ = std::cos(flip * std::numbers::pi / 180.0);
  sin_fold_ = std::sin(std::clamp(params_.corner_fold_tolerance_deg, 0.0, 90.0) * std::numbers::pi / 180.0);
  hausdorff_tol_ = params_.max_hausdorff > 0.0 ? params_.max_hausdorff * diag_ : 0.0;

  face_n_.resize(nf_);
  face_area_.resize(nf_);
  parallel_chunks(std::size_t(nf_), params_.threads, params_.min_parallel_faces, [&](std::size_t b, std::size_t e, std::size_t) {
    for (Index f = Index(b); f < Index(e); ++f) {
      const Vec3 av = face_area_vector(mesh_, f);
      face_area_[f] = av.norm();
      face_n_[f] = face_area_[f] > 0.0 ? Vec3(av / face_area_[f]) : Vec3::Zero();
    }
  });
  input_nm_.assign(nv_, -1);
  if (params_.check_surface_orientation) {
    surface_ = params_.surface_reference;
    if (!surface_) {
      own_surface_ = make_surface_reference(mesh_);
      surface_ = &own_surface_;
    }
    orientation_tol_ = std::max(0.0, params_.orientation_tolerance) * surface_->longest_side;
  }
  if (params_.protected_vertices && params_.protected_vertices->size() == nv_)
    protected_ = std::span<const std::uint8_t>(*params_.protected_vertices);
  features_on_ = params_.respect_features;
  if (features_on_) {
    feat_ptr_ = params_.feature_edges;
    if (!feat_ptr_) {
      own_feat_ = find_feature_edges(mesh_, conn_, params_.features);
      feat_ptr_ = &own_feat_;
    }
    reference_ = params_.feature_reference;
    if (!reference_) {
      own_reference_ = make_feature_reference(mesh_, conn_, *feat_ptr_);
      reference_ = &own_reference_;
    }
    protect_islands();
    protect_parts();
  }
  build_vertex_terms();
}

// Per-vertex quadrics, after Knodt's simple_qem (see the file comment). Two deliberate changes:
//   * a face plane is weighted by the corner's share of the face *area*, split among corners by
//     interior angle (area θ_c / Σθ), instead of by the angle alone: §3.3.2 asks for area
//     weighting and the angle split keeps Knodt's per-corner distribution;
//   * edge planes carry |e| · h / 2π instead of |e| / h, so edge and face terms have the same
//     units (area) and, on a regular quad grid, the same ratio as in Knodt's code.
void Collapser::build_vertex_terms() {
  if (params_.vertex_quadrics) {
    terms_ = &params_.vertex_quadrics->terms;
    return;
  }
  // The texture's lines weigh as in simplify()'s quadrics (QuadricPlacementParams::
  // texture_line_edges): the collapse places a cluster on them by its quadric alone.
  QuadricPlacementParams placement = params_.placement;
  std::vector<std::uint8_t> texture_lines;
  if (features_on_ && !placement.texture_line_edges) {
    texture_lines = texture_line_edges(*feat_ptr_);
    placement.texture_line_edges = &texture_lines;
  }
  own_quadrics_ = build_vertex_quadrics(mesh_, conn_, face_n_, face_area_, h_, placement);
  terms_ = &own_quadrics_.terms;
}

void Collapser::initial_clusters(const std::vector<std::uint8_t>& edge_kept) {
  collapsed_.assign(ne_, 0);
  UnionFind uf(nv_);
  for (Index e = 0; e < ne_; ++e) {
    if (edge_kept[e] != 0) continue;
    ++stats_.collapsed_edges_in;
    const auto [a, b] = conn_.edge_vertices[e];
    if (a == b) continue;
    collapsed_[e] = 1;
    uf.unite(a, b);
  }
  // Root = smallest member (deterministic, and keeps output ids in input order).
  root_.assign(nv_, kInvalidIndex);
  std::vector<Index> smallest(nv_, kInvalidIndex);
  for (Index v = 0; v < nv_; ++v) {
    Index& s = smallest[uf.find(v)];
    if (s == kInvalidIndex) s = v;  // v ascending: first seen is smallest
  }
  for (Index v = 0; v < nv_; ++v) root_[v] = smallest[uf.find(v)];

  // Members by counting sort on the root, ascending inside each cluster.
  seg_begin_.assign(nv_, 0);
  seg_end_.assign(nv_, 0);
  for (Index v = 0; v < nv_; ++v) ++seg_end_[root_[v]];
  Index offset = 0;
  for (Index v = 0; v < nv_; ++v) {
    seg_begin_[v] = offset;
    offset += seg_end_[v];
    seg_end_[v] = seg_begin_[v];
  }
  member_list_.resize(nv_);
  for (Index v = 0; v < nv_; ++v) member_list_[seg_end_[root_[v]]++] = v;
}

// --- placement -----------------------------------------------------------------------------------

// The cluster's position: its feature line's where it touches one (place_on_feature), else the
// minimiser of its quadric (geometry/cluster_quadric.h, the same placement the selection's shape
// cost prices).
void Collapser::place(Index r) {
  const auto ms = members(r);
  ClusterTerms t;
  for (Index m : ms) t.add_vertex((*terms_)[m], mesh_.positions[m]);
  snap_edges_.clear();
  if (params_.mirror) {
    placed_now_.push_back(r);
    placed_on_feature_[r] = 0;
  }
  // Issue 34: a protected member does not move; the cluster sits on it (the one with the smallest
  // id if there are two: check_vertex refuses that cluster anyway).
  if (!protected_.empty())
    for (Index m : ms)
      if (protected_[m]) {
        pos_[r] = mesh_.positions[m];
        ++stats_.placements_at_protected;
        placed_round_[r] = round_;
        return;
      }
  if (features_on_) {
    // place_on_feature minimises the regularised quadric along the line.
    if (place_on_feature(r, regularized_quadric(t, h_, params_.placement))) {
      placed_round_[r] = round_;
      if (params_.mirror) placed_on_feature_[r] = 1;
      return;
    }
  }
  ClusterPlacement pl = place_cluster(t, h_, params_.placement, [&](auto&& visit) {
    for (Index m : ms) visit(mesh_.positions[m]);
  });
  // A cluster on a texture line whose quadric put it within texture_line_snap of an edge of the
  // line around it lands on the line: what is left is the regulariser's pull, and on the line
  // the UVs of each side meet exactly (a flat grid's seam column: 0.0019 off, 0.7 % of an edge).
  if (!snap_edges_.empty()) {
    double best = INFINITY, length = 0.0;
    Vec3 onto = pl.position;
    for (Index e : snap_edges_) {
      const auto [a, b] = conn_.edge_vertices[e];
      const Vec3 q = closest_point_on_segment(pl.position, mesh_.positions[a], mesh_.positions[b]);
      length += edge_len_[e];
      if (const double d = (q - pl.position).norm(); d < best) {
        best = d;
        onto = q;
      }
    }
    if (best <= params_.texture_line_snap * length / double(snap_edges_.size())) pl.position = onto;
  }
  stats_.placements_pseudo_inverse += pl.pseudo_inverse;
  stats_.placements_volume_constrained += pl.volume_constrained;
  stats_.placements_fallback += pl.fallback;
  pos_[r] = pl.position;
  placed_round_[r] = round_;
}

// --- symmetry (issue 34) -------------------------------------------------------------------------

// The root of r's mirror cluster when it is one: every member's partner in it, the same size.
// r itself for a cluster that is its own mirror; kInvalidIndex otherwise.
Index Collapser::mirror_root(Index r) const {
  const std::vector<Index>& partner = params_.mirror->partner;
  const Index first = partner[members(r)[0]];
  if (first == kInvalidIndex) return kInvalidIndex;
  const Index r2 = root_[first];
  if (cluster_size(r2) != cluster_size(r)) return kInvalidIndex;
  for (Index m : members(r))
    if (partner[m] == kInvalidIndex || root_[partner[m]] != r2) return kInvalidIndex;
  return r2;
}

// Mirrored placements (docs/symmetry.md, "Placement"): the clusters placed this round, and their
// mirror clusters, end as exact reflections of each other; a cluster that is its own mirror sits
// on the plane. The quadrics of a mirror pair are mirror images, so the two placements differ by
// rounding only — except where the input's attributes are not mirrored (a UV seam on one side
// only places that side's cluster on its line): then the side on a feature line is reflected.
bool Collapser::holds_protected(Index r) const {
  if (protected_.empty()) return false;
  for (Index m : members(r))
    if (protected_[m]) return true;
  return false;
}

void Collapser::mirror_placements(std::vector<Index>* dirty) {
  const MirrorPlane& plane = params_.mirror->plane;
  for (Index r : placed_now_) {
    if (root_[r] != r || cluster_size(r) < 2 || placed_round_[r] != round_) continue;
    const Index r2 = mirror_root(r);
    if (r2 == kInvalidIndex) continue;
    // A protected vertex keeps its exact input position (issue 34, docs/protect.md) over its
    // mirror: a cluster holding one, or whose mirror holds one, is not reflected.
    if (holds_protected(r) || holds_protected(r2)) continue;
    if (r2 == r) {
      pos_[r][plane.axis] = plane.centre;
      continue;
    }
    const bool now2 = placed_round_[r2] == round_;
    Index from = r;
    if (now2) {
      if (placed_on_feature_[r] != placed_on_feature_[r2]) from = placed_on_feature_[r] ? r : r2;
      else from = std::min(r, r2);
    }
    const Index to = from == r ? r2 : r;
    pos_[to] = plane.reflect(pos_[from]);
    if (now2 || !dirty) continue;
    placed_round_[to] = round_;
    for (Index m : members(to))
      for (Index c : conn_.corners_at_vertex(m)) {
        const Index f = conn_.corner_face[c];
        if (face_dirty_token_[f] == dirty_token_) continue;
        face_dirty_token_[f] = dirty_token_;
        dirty->push_back(f);
      }
  }
  placed_now_.clear();
}

// Feature-constrained placement (issue 7). A cluster with exactly one feature corner sits on it.
// A cluster touching a strict line — or, when it touches no strict line and no corner, exactly
// one hard line — is placed at the minimiser of its quadric over the feature segments with an
// endpoint in the cluster: the run of the line inside the cluster and the segment on either side.
//
//        ─────●═════●═════●──────      ● members on the line, ══ collapsed feature edges
//          s0    s1    s2    s3        candidates: s0 … s3; the vertex lands on one of them,
//                                      so the output line stays on the input polyline.
//
// Returns false when the cluster is not constrained (no feature, or two hard lines meeting: a
// bevel between creases may collapse, placed by the plain quadric).
namespace {

// A quadric error below another by more than rounding: members run in increasing id, so a tie
// (a symmetric pair of corners: the two ends of a strip's collapsed end edge, the columns of a
// per-face layout's chord) keeps the smaller id, and neighbouring clusters pick the same side.
bool clearly_less(double err, double best) { return err < best - 1e-9 * std::abs(best); }

}  // namespace

bool Collapser::place_on_feature(Index r, const Quadric& q) {
  Index corners = 0, corner = kInvalidIndex;
  bool strict = false, any = false;
  // Vertices whose only feature is a hard edge follow their quadric unless place_on_hard_edges.
  auto counts = [&](Index m) {
    return feat_ptr_->on_feature(m) &&
           (params_.place_on_hard_edges || (feat_ptr_->vertex_bits[m] & ~std::uint32_t(kFeatureHardEdge)) != 0);
  };
  Index strict_corner = kInvalidIndex;
  double strict_corner_err = INFINITY;
  bool shape_line = false;  // a member on an open boundary or a non-manifold edge
  mark_crossing_side(r);
  for (Index m : members(r)) {
    if (!counts(m)) continue;
    any = true;
    strict = strict || feat_ptr_->on_strict(m);
    shape_line = shape_line || (feat_ptr_->vertex_bits[m] & (kFeatureBoundary | kFeatureNonManifold));
    if (feat_ptr_->vertex_corner[m]) {
      ++corners;
      corner = m;
      // Strict corners (junctions, ends, turns of seams and boundaries) never move: a cluster
      // that merges several along their lines lands on the one its quadric likes best.
      // A tie keeps the smaller id (clearly_less), the side mark_crossing_side picks too.
      const double err = q(mesh_.positions[m]);
      if (feat_ptr_->on_strict(m) && side_[m] && (strict_corner == kInvalidIndex || clearly_less(err, strict_corner_err))) {
        strict_corner_err = err;
        strict_corner = m;
      }
    }
  }
  if (!any) return false;
  if (strict_corner != kInvalidIndex) {
    pos_[r] = mesh_.positions[strict_corner];
    ++stats_.placements_at_feature_corner;
    return true;
  }
  // On the texture's lines only (UV seams, material borders), between their corners: the plain
  // quadric, with check_feature_edges' tolerance as the guarantee (a cluster whose line edges
  // leave the input line is refused, and the rounds look elsewhere). Placing such clusters on the
  // input polyline cost flightgear_caravan 3.8× the Chamfer of its bare geometry at 0.4 (1.2× this
  // way), with no seam torn either way (docs/attributes.md, "Issue 32"). Boundaries and
  // non-manifold edges, the lines of the shape, stay on their polyline, and corners stay where
  // they are.
  if (strict && !shape_line && !on_line_[r]) {
    // ... but a placement that lands within texture_line_snap of the line goes onto it (place()),
    // and one whose line edges leave the input line goes onto it next round (on_line_).
    placed_free_[r] = 1;
    snap_edges_.clear();
    for (Index m : members(r))
      for (Index c : conn_.corners_at_vertex(m))
        for (Index ec : {c, conn_.corner_prev[c]})
          if (const Index e = conn_.corner_edge[ec]; feat_ptr_->is_strict(e)) snap_edges_.push_back(e);
    return false;
  }
  if (corners == 1) {
    pos_[r] = mesh_.positions[corner];
    ++stats_.placements_at_feature_corner;
    return true;
  }
  // Several corners of non-strict UV seams only: a per-face UV layout (FeatureParams::
  // per_face_layout_fraction), where every edge is a seam and every vertex a corner. The cluster
  // lands on the member corner its quadric likes best (a half-edge collapse): the output edges
  // then join input vertices and, across a collapsed chord, follow the input edges they replace,
  // so the output seams stay on input seams (opensubdiv_bishop_cage at 0.4: seams_torn 155 → 9;
  // docs/attributes.md). Hard-edge corners keep the plain quadric: two creases may merge.
  bool seams_only = corners >= 2 && !strict;
  for (Index m : members(r))
    if (feat_ptr_->on_feature(m) && !(feat_ptr_->vertex_bits[m] & kFeatureUvSeam)) seams_only = false;
  if (seams_only) {
    double best_err = INFINITY;
    corner = kInvalidIndex;
    for (Index m : members(r)) {
      if (!feat_ptr_->vertex_corner[m]) continue;
      const double err = q(mesh_.positions[m]);
      if (corner == kInvalidIndex || clearly_less(err, best_err)) {
        best_err = err;
        corner = m;
      }
    }
    pos_[r] = mesh_.positions[corner];
    ++stats_.placements_at_feature_corner;
    return true;
  }
  // Candidate segments: feature edges (strict ones if the cluster is on a strict line) with an
  // endpoint in the cluster; without a strict line they must all belong to one hard line.
  edges_tmp_.clear();
  Index line = kInvalidIndex;
  for (Index m : members(r)) {
    if (!feat_ptr_->on_feature(m)) continue;
    for (Index c : conn_.corners_at_vertex(m))
      for (Index ec : {c, conn_.corner_prev[c]}) {
        const Index e = conn_.corner_edge[ec];
        if (!feat_ptr_->is_feature(e) || (strict && (!feat_ptr_->is_strict(e) || !side_[m]))) continue;
        if (!strict) {
          if (line == kInvalidIndex) line = feat_ptr_->edge_line[e];
          else if (feat_ptr_->edge_line[e] != line) return false;
        }
        edges_tmp_.push_back(e);
      }
  }
  if (edges_tmp_.empty() || (!strict && corners > 0)) return false;
  std::sort(edges_tmp_.begin(), edges_tmp_.end());
  edges_tmp_.erase(std::unique(edges_tmp_.begin(), edges_tmp_.end()), edges_tmp_.end());
  // Q along p0 + t·d is quadratic in t: minimiser t = −dᵀ(A p0 + b) / dᵀAd, clamped to [0, 1].
  double best_err = INFINITY;
  Vec3 best = Vec3::Zero();
  for (Index e : edges_tmp_) {
    const auto [a, b] = conn_.edge_vertices[e];
    const Vec3& p0 = mesh_.positions[a];
    const Vec3 d = mesh_.positions[b] - p0;
    const double dad = d.dot(q.A * d);
    double t = 0.0;
    if (dad > 0.0) t = std::clamp(-d.dot(q.A * p0 + q.b) / dad, 0.0, 1.0);
    for (double cand : {t, 0.0, 1.0}) {
      const Vec3 x = p0 + cand * d;
      const double err = q(x);
      if (err < best_err) {
        best_err = err;
        best = x;
      }
    }
  }
  if (!std::isfinite(best_err)) return false;
  pos_[r] = best;
  ++stats_.placements_on_feature_line;
  return true;
}

// The side a crossing lands on. A cluster whose strict members are not all joined by collapsed
// strict edges merges several lines through an island that may cross (features_valid): it lands
// on the lines of the part that holds its smallest strict member, so the clusters along a
// collapsed strip pick the same side of it wherever the vertex order runs the same way along its
// two sides (rows of a strip are numbered in order by every modeller we read), and the merged
// line follows one input line instead of zig-zagging across the strip (which check_feature_edges'
// tolerance would refuse). side_[m] = 1 for the members placement may anchor to.
void Collapser::mark_crossing_side(Index r) {
  const auto ms = members(r);
  if (side_.size() != nv_) side_.assign(nv_, 0);
  for (Index m : ms) side_[m] = 1;
  Index first = kInvalidIndex;
  for (Index m : ms)
    if (feat_ptr_->on_strict(m)) {
      first = m;
      break;
    }
  if (first == kInvalidIndex) return;
  // The strict part of `first`: a walk over collapsed strict edges inside the cluster.
  for (Index m : ms) side_[m] = feat_ptr_->on_strict(m) ? 0 : 1;
  std::vector<Index>& stack = side_stack_;
  stack.assign(1, first);
  side_[first] = 1;
  while (!stack.empty()) {
    const Index m = stack.back();
    stack.pop_back();
    for (Index c : conn_.corners_at_vertex(m))
      for (Index ec : {c, conn_.corner_prev[c]}) {
        const Index e = conn_.corner_edge[ec];
        if (!collapsed_[e] || !feat_ptr_->is_strict(e)) continue;
        const Index o = conn_.other_vertex(e, m);
        if (root_[o] != r || side_[o]) continue;
        side_[o] = 1;
        stack.push_back(o);
      }
  }
}

// --- refusal: splitting a cluster --------------------------------------------------------------
//
// A refused cluster is cut along its longest collapsed edges: Kruskal over its collapsed edges by
// increasing length stops when two components remain, and every collapsed edge between them
// becomes kept (single-linkage bisection). A two-vertex cluster, or any cluster once
// max_bisect_rounds are used up, is dissolved: all its collapsed edges become kept.
//
//      a ══ b ══ c ─────── d ══ e          ══ collapsed, ── kept (before)
//                 (longest collapsed link c══d, say)
//      a ══ b ══ c ─────── d ══ e     →    {a,b,c} and {d,e}: c──d restored as kept
//
// The faces around the old cluster become dirty: they are rebuilt and checked again next round.
void Collapser::split(Index r, CollapseRefusal why, bool dissolve) {
  const std::uint8_t reason = static_cast<std::uint8_t>(why);
  ++stats_.refused[reason];
  const Index b = seg_begin_[r], e = seg_end_[r];

  // Internal collapsed edges.
  edges_tmp_.clear();
  for (Index i = b; i < e; ++i) {
    const Index m = member_list_[i];
    for (Index c : conn_.corners_at_vertex(m)) {
      for (Index ec : {c, conn_.corner_prev[c]}) {
        const Index edge = conn_.corner_edge[ec];
        if (collapsed_[edge] && root_[conn_.other_vertex(edge, m)] == r) edges_tmp_.push_back(edge);
      }
    }
    pos_[m] = mesh_.positions[m];
    for (Index c : conn_.corners_at_vertex(m)) {
      const Index f = conn_.corner_face[c];
      if (face_dirty_token_[f] == dirty_token_) continue;
      face_dirty_token_[f] = dirty_token_;
      face_blame_[f] = reason;
      next_dirty_.push_back(f);
    }
  }
  std::sort(edges_tmp_.begin(), edges_tmp_.end());
  edges_tmp_.erase(std::unique(edges_tmp_.begin(), edges_tmp_.end()), edges_tmp_.end());

  if (dissolve || e - b <= 2) {
    ++stats_.clusters_dissolved;
    for (Index edge : edges_tmp_) collapsed_[edge] = 0;
    stats_.edges_restored += static_cast<Index>(edges_tmp_.size());
    for (Index i = b; i < e; ++i) {
      const Index m = member_list_[i];
      root_[m] = m;
      seg_begin_[m] = i;
      seg_end_[m] = i + 1;
    }
    return;
  }

  ++stats_.clusters_bisected;
  const Index size = e - b;
  // Local ids: position in the segment (members are sorted, so a binary search finds them).
  auto local = [&](Index v) {
    return static_cast<Index>(std::lower_bound(member_list_.begin() + b, member_list_.begin() + e, v) -
                              (member_list_.begin() + b));
  };
  std::sort(edges_tmp_.begin(), edges_tmp_.end(), [&](Index x, Index y) {
    return edge_len_[x] != edge_len_[y] ? edge_len_[x] < edge_len_[y] : x < y;
  });
  UnionFind uf(size);
  Index components = size;
  for (Index edge : edges_tmp_) {
    const auto [p, q] = conn_.edge_vertices[edge];
    const Index lp = local(p), lq = local(q);
    if (uf.find(lp) == uf.find(lq)) continue;
    if (components == 2) break;  // this edge would join the last two parts: it is cut
    uf.unite(lp, lq);
    --components;
  }
  for (Index edge : edges_tmp_) {
    const auto [p, q] = conn_.edge_vertices[edge];
    if (uf.find(local(p)) != uf.find(local(q))) {
      collapsed_[edge] = 0;
      ++stats_.edges_restored;
    }
  }
  // Stable partition of the segment: the part of the first member, then the other part.
  const Index first_part = uf.find(0);
  tmp_a_.clear();
  tmp_b_.clear();
  for (Index i = 0; i < size; ++i)
    (uf.find(i) == first_part ? tmp_a_ : tmp_b_).push_back(member_list_[b + i]);
  std::copy(tmp_a_.begin(), tmp_a_.end(), member_list_.begin() + b);
  std::copy(tmp_b_.begin(), tmp_b_.end(), member_list_.begin() + b + tmp_a_.size());
  const Index mid = b + static_cast<Index>(tmp_a_.size());
  for (auto [lo, hi] : {std::pair{b, mid}, std::pair{mid, e}}) {
    const Index nr = member_list_[lo];  // smallest of the part (segment stays sorted)
    for (Index i = lo; i < hi; ++i) root_[member_list_[i]] = nr;
    seg_begin_[nr] = lo;
    seg_end_[nr] = hi;
    if (hi - lo > 1) to_place_.push_back(nr);
  }
}

// --- rebuilding a face ---------------------------------------------------------------------------
//
// Corners map through the clusters; of each run of consecutive corners in one cluster only the
// first survives (it keeps its own uv / normal index). A face left with < 3 corners is dropped.
// Collapsing the opposing edges of a chord (══, clusters X0 = {a0,b0}, X1 = {a1,b1}):
//
//      z1 ── a1 ══ b1 ── c1             z1 ── X1 ── c1     chord quad (a0 b0 b1 a1)
//      │     │  q  │     │      →       │     │     │       → (X0 X0 X1 X1) → (X0 X1): dropped;
//      z0 ── a0 ══ b0 ── c0             z0 ── X0 ── c0     its neighbours keep 4 distinct
//                                                           corners: still quads.
//
// A single collapsed edge a══b between two quads makes both triangles:
//      (z0 a b z1) → (z0 X z1)      and      (a c0 c1 b) → (X c0 c1).
//
// A face that meets one cluster at two non-adjacent corners is "pinched": it is cut at the
// repeated vertex into simple loops, each kept if it has >= 3 corners:
//
//      (a b c a' d e) with a' ~ a   →   (a b c) and (a d e);      (a b a' c) → (a b), (a c): dropped
void Collapser::rebuild_face(Index f) {
  const Index b = mesh_.face_begin(f), k = mesh_.face_size(f);
  kept_.clear();
  for (Index i = 0; i < k; ++i) {
    const Index c = b + i;
    const Index prev = i == 0 ? b + k - 1 : c - 1;
    if (root_of_corner(c) != root_of_corner(prev)) kept_.push_back(c);
  }
  Index out = piece_base(f);
  Index pieces = 0;
  std::uint32_t tri_eq = 0;
  bool pinched = false;
  const bool indexed = !corner_piece_.empty();
  if (indexed) std::fill(corner_piece_.begin() + b, corner_piece_.begin() + b + k, kInvalidIndex);
  auto emit = [&](const Index* cs, Index len) {
    if (len < 3) return;
    if (indexed)
      for (Index i = 0; i < len; ++i) {
        corner_piece_[cs[i]] = out;
        corner_piece_pos_[cs[i]] = i;
      }
    piece_buf_[out++] = len;
    for (Index i = 0; i < len; ++i) piece_buf_[out++] = cs[i];
    ++pieces;
    tri_eq += tri_equivalent(len);
  };
  // Cut at repeated vertices with a stack: when a vertex comes back, the corners since its first
  // visit form a closed loop; the first visit stays on the stack for the rest of the walk.
  stack_.clear();
  for (Index c : kept_) {
    const Index r = root_of_corner(c);
    const Index at = stack_pos_[r];
    if (at != kInvalidIndex) {
      pinched = true;
      emit(stack_.data() + at, static_cast<Index>(stack_.size()) - at);
      for (Index j = at + 1; j < stack_.size(); ++j) stack_pos_[root_of_corner(stack_[j])] = kInvalidIndex;
      stack_.resize(at + 1);
    } else {
      stack_pos_[r] = static_cast<Index>(stack_.size());
      stack_.push_back(c);
    }
  }
  emit(stack_.data(), static_cast<Index>(stack_.size()));
  for (Index c : stack_) stack_pos_[root_of_corner(c)] = kInvalidIndex;
  piece_count_[f] = pieces;
  face_tri_eq_[f] = tri_eq;
  face_pinched_[f] = pinched ? 1 : 0;
}

// --- driver ----------------------------------------------------------------------------------------

void Collapser::run(const std::vector<std::uint8_t>& edge_kept, ClusterCollapseResult& out) {
  precompute();
  initial_clusters(edge_kept);

  pos_ = mesh_.positions;
  placed_round_.assign(nv_, kInvalidIndex);
  placed_free_.assign(nv_, 0);
  on_line_.assign(nv_, 0);
  replace_round_.assign(nv_, kInvalidIndex);
  blame_reason_.assign(nv_, kNoReason);
  vert_token_.assign(nv_, 0);
  stack_pos_.assign(nv_, kInvalidIndex);
  face_dirty_token_.assign(nf_, 0);
  face_fan_token_.assign(nf_, 0);
  face_blame_.assign(nf_, kNoReason);
  piece_buf_.assign(2 * static_cast<std::size_t>(mesh_.num_corners()), 0);
  piece_count_.assign(nf_, 0);
  Index max_degree = 0;
  for (Index f = 0; f < nf_; ++f) max_degree = std::max(max_degree, mesh_.face_size(f));
  if (max_degree > kIndexedFanDegree) {
    corner_piece_.assign(mesh_.num_corners(), kInvalidIndex);
    corner_piece_pos_.assign(mesh_.num_corners(), 0);
    face_fan_rank_.assign(nf_, 0);
  }
  face_tri_eq_.assign(nf_, 0);
  face_pinched_.assign(nf_, 0);

  round_ = 0;
  if (params_.mirror) {
    placed_now_.clear();
    placed_on_feature_.assign(nv_, 0);
  }
  for (Index v = 0; v < nv_; ++v)
    if (root_[v] == v && cluster_size(v) > 1) place(v);
  if (params_.mirror) mirror_placements(nullptr);
  std::vector<Index> dirty;
  for (Index f = 0; f < nf_; ++f) {
    rebuild_face(f);
    stats_.tri_equivalent_in += tri_equivalent(mesh_.face_size(f));
    stats_.tri_equivalent_wanted += face_tri_eq_[f];
    for (Index c = mesh_.face_begin(f); c < mesh_.face_end(f); ++c)
      if (cluster_size(root_of_corner(c)) > 1) {
        dirty.push_back(f);
        break;
      }
  }

  while (true) {
    ++stats_.rounds;
    blamed_.clear();
    replace_.clear();
    check(dirty);
    if (blamed_.empty() && !part_begin_.empty()) check_parts(all_faces_list());
    if (blamed_.empty() && !face_island_.empty()) {
      // A round can split an island none of whose faces it touched: collapsing a coincident
      // sheet onto an island's edge makes that edge non-manifold (cg57 at 0.6). So before the
      // collapse is final, every island is checked once more — but for those check(dirty) just
      // found whole: nothing changed since (on a UV grid, one island of the whole mesh: a
      // second full check per pass, issue 20).
      check_islands(all_faces_list(), /*skip_checked=*/true);
    }
    if (blamed_.empty() && replace_.empty()) break;
    // Refuse: split every blamed cluster (they are distinct clusters of this round).
    const bool dissolve = round_ >= params_.max_bisect_rounds;
    ++dirty_token_;
    next_dirty_.clear();
    to_place_.clear();
    for (Index r : blamed_) {
      const auto why = static_cast<CollapseRefusal>(blame_reason_[r]);
      blame_reason_[r] = kNoReason;
      split(r, why, dissolve);
    }
    ++round_;
    for (Index r : to_place_) place(r);
    // Clusters going onto their texture line (place_on_line_again), unless a split this round
    // took them apart: placed again, their faces checked again.
    for (Index r : replace_) {
      if (root_[r] != r || cluster_size(r) < 2 || placed_round_[r] == round_) continue;
      place(r);
      for (Index m : members(r))
        for (Index c : conn_.corners_at_vertex(m)) {
          const Index f = conn_.corner_face[c];
          if (face_dirty_token_[f] == dirty_token_) continue;
          face_dirty_token_[f] = dirty_token_;
          next_dirty_.push_back(f);
        }
    }
    if (params_.mirror) mirror_placements(&next_dirty_);
    for (Index f : next_dirty_) {
      const std::int64_t before = face_tri_eq_[f];
      rebuild_face(f);
      if (face_blame_[f] != kNoReason)
        stats_.refused_tri_equivalents[face_blame_[f]] += std::int64_t(face_tri_eq_[f]) - before;
      face_blame_[f] = kNoReason;
    }
    dirty.swap(next_dirty_);
  }
  if (features_on_)
    for (Index r = 0; r < nv_; ++r) {
      if (root_[r] != r || cluster_size(r) < 2) continue;
      mark_crossing_side(r);
      for (Index m : members(r))
        if (feat_ptr_->on_strict(m) && !side_[m]) {
          ++stats_.line_crossings;
          break;
        }
    }
  assemble(edge_kept, out);
}

}  // namespace collapse_detail

using collapse_detail::Collapser;

SurfaceReference make_surface_reference(const PolyMesh& mesh, int threads) {
  SurfaceReference ref;
  TriangleSoup soup = fan_triangulate(mesh);
  ref.normal.resize(soup.triangles.size());
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    const auto& tri = soup.triangles[t];
    const Vec3 n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    const double len = n.norm();
    ref.normal[t] = len > 0.0 && std::isfinite(len) ? Vec3(n / len) : Vec3::Zero();
  }
  BvhBuildParams bvh_params;
  bvh_params.threads = threads;
  ref.bvh = TriangleBvh(soup.triangles, bvh_params);
  const double side = bounding_box(mesh).longest_side();
  ref.longest_side = side > 0.0 && std::isfinite(side) ? side : 1.0;
  return ref;
}

FeatureReference make_feature_reference(const PolyMesh& mesh, const Connectivity& conn, const FeatureEdges& feat) {
  constexpr std::uint8_t kKinds[4] = {kFeatureBoundary, kFeatureNonManifold, kFeatureUvSeam, kFeatureMaterialBorder};
  FeatureReference ref;
  std::vector<std::array<Vec3, 2>> segments;
  for (int k = 0; k < 4; ++k) {
    segments.clear();
    for (Index e = 0; e < conn.num_edges; ++e)
      if ((feat.is_strict(e) || kKinds[k] == kFeatureUvSeam) && (feat.edge_bits[e] & kKinds[k]))
        segments.push_back({mesh.positions[conn.edge_vertices[e][0]], mesh.positions[conn.edge_vertices[e][1]]});
    if (!segments.empty()) ref.by_kind[k] = SegmentBvh(segments);
  }
  return ref;
}

const char* to_string(CollapseRefusal reason) {
  switch (reason) {
    case CollapseRefusal::NonManifoldEdge: return "nonmanifold_edge";
    case CollapseRefusal::NonManifoldVertex: return "nonmanifold_vertex";
    case CollapseRefusal::NewBoundary: return "new_boundary";
    case CollapseRefusal::DuplicateFace: return "duplicate_face";
    case CollapseRefusal::DegenerateFace: return "degenerate_face";
    case CollapseRefusal::Flip: return "flip";
    case CollapseRefusal::FoldedCorner: return "folded_corner";
    case CollapseRefusal::Orientation: return "orientation";
    case CollapseRefusal::Hausdorff: return "hausdorff";
    case CollapseRefusal::Feature: return "feature";
    case CollapseRefusal::Island: return "island";
    case CollapseRefusal::Part: return "part";
    case CollapseRefusal::Protected: return "protected";
  }
  return "unknown";
}

Index ClusterCollapseStats::total_refusals() const {
  Index total = 0;
  for (Index r : refused) total += r;
  return total;
}

ClusterCollapseResult collapse_clusters(const PolyMesh& mesh, const Connectivity& conn,
                                        const std::vector<std::uint8_t>& edge_kept,
                                        const ClusterCollapseParams& params) {
  const Stopwatch clock;
  ClusterCollapseResult result;
  std::string error;
  if (conn.num_vertices != mesh.num_vertices() || conn.num_faces != mesh.num_faces() ||
      conn.corner_vertex.size() != mesh.num_corners())
    error = "connectivity does not match the mesh (" + std::to_string(conn.num_vertices) +
            " vertices, " + std::to_string(conn.num_faces) + " faces vs " +
            std::to_string(mesh.num_vertices()) + ", " + std::to_string(mesh.num_faces()) + ")";
  else if (edge_kept.size() != conn.num_edges)
    error = "edge_kept has " + std::to_string(edge_kept.size()) + " entries for " +
            std::to_string(conn.num_edges) + " edges";
  if (!error.empty()) {
    result.status = ClusterCollapseStatus::InvalidInput;
    result.error = std::move(error);
    result.mesh = mesh;
    result.vertex_map.resize(mesh.num_vertices());
    std::iota(result.vertex_map.begin(), result.vertex_map.end(), Index{0});
    result.edge_collapsed_final.assign(conn.num_edges, 0);
    result.face_source.resize(mesh.num_faces());
    std::iota(result.face_source.begin(), result.face_source.end(), Index{0});
    result.stats.faces_in = result.stats.faces_out = mesh.num_faces();
    result.seconds = clock.seconds();
    return result;
  }
  Collapser collapser(mesh, conn, params, result.stats);
  collapser.run(edge_kept, result);
  result.seconds = clock.seconds();
  return result;
}

nlohmann::json to_json(const ClusterCollapseStats& s) {
  nlohmann::json refused = nlohmann::json::object();
  nlohmann::json kept = nlohmann::json::object();
  for (std::size_t i = 0; i < kNumCollapseRefusals; ++i) {
    const char* name = to_string(static_cast<CollapseRefusal>(i));
    refused[name] = s.refused[i];
    kept[name] = s.refused_tri_equivalents[i];
  }
  return {
      {"collapsed_edges_in", s.collapsed_edges_in},
      {"collapsed_edges_final", s.collapsed_edges_final},
      {"implied_collapsed_edges", s.implied_collapsed_edges},
      {"clusters", s.clusters},
      {"clustered_vertices", s.clustered_vertices},
      {"largest_cluster", s.largest_cluster},
      {"faces_in", s.faces_in},
      {"faces_out", s.faces_out},
      {"quads_out", s.quads_out},
      {"triangles_out", s.triangles_out},
      {"ngons_out", s.ngons_out},
      {"tri_equivalent_in", s.tri_equivalent_in},
      {"tri_equivalent_out", s.tri_equivalent_out},
      {"tri_equivalent_wanted", s.tri_equivalent_wanted},
      {"faces_dropped", s.faces_dropped},
      {"faces_pinched", s.faces_pinched},
      {"quads_to_triangles", s.quads_to_triangles},
      {"vertices_removed_unused", s.vertices_removed_unused},
      {"placements_volume_constrained", s.placements_volume_constrained},
      {"placements_pseudo_inverse", s.placements_pseudo_inverse},
      {"placements_fallback", s.placements_fallback},
      {"placements_at_feature_corner", s.placements_at_feature_corner},
      {"placements_on_feature_line", s.placements_on_feature_line},
      {"placements_at_protected", s.placements_at_protected},
      {"line_crossings", s.line_crossings},
      {"uv_values_projected", s.uv_values_projected},
      {"normals_recomputed", s.normals_recomputed},
      {"rounds", s.rounds},
      {"clusters_bisected", s.clusters_bisected},
      {"clusters_dissolved", s.clusters_dissolved},
      {"edges_restored", s.edges_restored},
      {"refused", refused},
      {"refused_tri_equivalents", kept},
  };
}

}  // namespace quadlod
