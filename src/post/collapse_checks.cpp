// The guarantees of the cluster collapse (cluster_collapse.h, point 3 and the feature rules of
// point 4), checked on the neighbourhood of every cluster each round: Collapser's face checks
// (degenerate, flipped, facing away from the input surface, folded at a corner), vertex checks
// (new non-manifold edge or vertex, new boundary, duplicate faces, strict feature lines), the
// feature-edge tolerance and the Hausdorff bound. A violation blames the clusters involved; the
// driver (cluster_collapse.cpp) splits them. The class: collapser.h.
#include "geometry/bvh.h"
#include "mesh/union_find.h"
#include "post/collapser.h"
#include "util/parallel.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace quadlod::collapse_detail {

// --- checks ----------------------------------------------------------------------------------------

void Collapser::blame(Index r, CollapseRefusal why) {
  if (cluster_size(r) < 2) return;
  const auto reason = static_cast<std::uint8_t>(why);
  if (blame_reason_[r] == kNoReason) blamed_.push_back(r);
  blame_reason_[r] = std::min(blame_reason_[r], reason);
}

void Collapser::blame_piece(const Index* corners, Index len, CollapseRefusal why) {
  for (Index i = 0; i < len; ++i) blame(root_of_corner(corners[i]), why);
}

namespace {

// A corner's turn: (next − cur) × (prev − cur); along +n at a convex corner of a CCW polygon.
inline Vec3 corner_turn(const Vec3& prev, const Vec3& cur, const Vec3& next) {
  return (next - cur).cross(prev - cur);
}

}  // namespace

// Face checks on every piece of a dirty face: degenerate, flipped, folded at a corner. The
// reference is the input face the piece comes from (its normal and its corners' convexity).
// Reads the state only (so dirty faces are checked on several threads); the refusals go to
// `found`, in the order blame() is to see them.
void Collapser::check_face(Index f, std::vector<FaceBlame>& found) const {
  auto blame = [&](Index r, CollapseRefusal why) { found.push_back({r, why}); };
  auto blame_piece = [&](const Index* corners, Index len, CollapseRefusal why) {
    for (Index i = 0; i < len; ++i) blame(root_of_corner(corners[i]), why);
  };
  const bool input_flat = !(face_area_[f] > zero_area_);
  const Vec3& n_in = face_n_[f];
  Index off = piece_base(f);
  for (Index p = 0; p < piece_count_[f]; ++p) {
    const Index len = piece_buf_[off];
    const Index* cs = piece_buf_.data() + off + 1;
    off += len + 1;
    auto at = [&](Index i) -> const Vec3& { return pos_[root_of_corner(cs[i])]; };
    // A side shrunk to a point: two clusters placed on one spot. Only its two clusters are
    // refused, and only if the input corners were apart (an input's own zero-length sides stay).
    bool shrunk = false;
    for (Index i = 0; i < len; ++i) {
      const Index j = i + 1 == len ? 0 : i + 1;
      if ((at(i) - at(j)).squaredNorm() > zero_length_sq_) continue;
      const Vec3& a_in = mesh_.positions[conn_.corner_vertex[cs[i]]];
      const Vec3& b_in = mesh_.positions[conn_.corner_vertex[cs[j]]];
      if ((a_in - b_in).squaredNorm() <= zero_length_sq_) continue;
      blame(root_of_corner(cs[i]), CollapseRefusal::DegenerateFace);
      blame(root_of_corner(cs[j]), CollapseRefusal::DegenerateFace);
      shrunk = true;
    }
    if (shrunk) continue;
    const Vec3 av = area_vector(len, at);
    const double area = av.norm();
    if (input_flat) {
      // No reference normal and a degenerate input face is not ours to fix, but what it turns
      // into must still face the input surface (that rule needs no source normal).
      if (area > zero_area_ && surface_ && !faces_input_surface(len, at, av))
        blame_piece(cs, len, CollapseRefusal::Orientation);
      continue;
    }
    if (!(area > zero_area_)) {
      blame_piece(cs, len, CollapseRefusal::DegenerateFace);
      continue;
    }
    if (av.dot(n_in) < cos_flip_ * area) {
      blame_piece(cs, len, CollapseRefusal::Flip);
      continue;
    }
    if (surface_ && !faces_input_surface(len, at, av)) {
      blame_piece(cs, len, CollapseRefusal::Orientation);
      continue;
    }
    if (!params_.check_corner_folds || len < 4) continue;
    for (Index i = 0; i < len; ++i) {
      const Vec3& prev = at(i == 0 ? len - 1 : i - 1);
      const Vec3& cur = at(i);
      const Vec3& next = at(i + 1 == len ? 0 : i + 1);
      const double scale = (next - cur).norm() * (prev - cur).norm();
      if (!(corner_turn(prev, cur, next).dot(n_in) < -sin_fold_ * scale)) continue;
      // Reflex now: a fold only if the input corner was convex.
      const Index c = cs[i];
      const Vec3& pin = mesh_.positions[conn_.corner_vertex[conn_.corner_prev[c]]];
      const Vec3& cin = mesh_.positions[conn_.corner_vertex[c]];
      const Vec3& nin = mesh_.positions[conn_.corner_vertex[conn_.corner_next[c]]];
      const double scale_in = (nin - cin).norm() * (pin - cin).norm();
      if (corner_turn(pin, cin, nin).dot(n_in) > 1e-9 * scale_in) {
        blame_piece(cs, len, CollapseRefusal::FoldedCorner);
        break;
      }
    }
  }
}

// docs/metrics.md §6b, as `quadlod eval` applies it to a finished output face: from the centroid of
// the corners, the nearest input triangle facing the piece's way (area vectors with dot >= 0)
// may be at most twice as far as the nearest input triangle of either orientation, plus the
// tolerance. Over a fold, a piece that slid onto the sheet facing away fails it even when it
// still agrees with its own input face.
constexpr double kAgreeCos = 1e-3;  // cos 89.94°

template <class PositionOf>
bool Collapser::faces_input_surface(Index len, PositionOf&& at, const Vec3& av) const {
  Vec3 c = Vec3::Zero();
  for (Index i = 0; i < len; ++i) c += at(i);
  c /= static_cast<double>(len);
  const NearestHit any = surface_->bvh.nearest(c);
  if (any.primitive == kInvalidIndex) return true;
  const double reach = 2.0 * std::sqrt(any.distance_sq) + orientation_tol_;
  // Stricter than eval's dot >= 0: a triangle within kAgreeCos of perpendicular, or of zero area,
  // does not count as agreeing here, so rounding (eval reads the output back from 9-digit text
  // and works on a rescaled copy) cannot make eval find an agreeing triangle farther away.
  const double min_dot = kAgreeCos * av.norm();
  const NearestHit agreeing = surface_->bvh.nearest_if(
      c, [&](Index t) { return surface_->normal[t].dot(av) >= min_dot; }, kInvalidIndex, reach * reach);
  return agreeing.primitive != kInvalidIndex && std::sqrt(agreeing.distance_sq) <= reach;
}

// The output faces around output vertex v (a root): the pieces, of the input faces around its
// members, that contain v.
void Collapser::gather_fan(Index v) {
  fan_.clear();
  ++fan_token_;
  if (!corner_piece_.empty()) return gather_fan_indexed(v);
  for (Index m : members(v)) {
    for (Index c : conn_.corners_at_vertex(m)) {
      const Index f = conn_.corner_face[c];
      if (face_fan_token_[f] == fan_token_) continue;
      face_fan_token_[f] = fan_token_;
      Index off = piece_base(f);
      for (Index p = 0; p < piece_count_[f]; ++p) {
        const Index len = piece_buf_[off];
        const Index first = off + 1;
        for (Index i = 0; i < len; ++i)
          if (root_of_corner(piece_buf_[first + i]) == v) {
            fan_.push_back({f, first, i, len});
            break;
          }
        off = first + len;
      }
    }
  }
}

// gather_fan() for meshes with large faces: the same entries in the same order, found through the
// corner → piece index instead of a scan of every piece (quadratic in the face size: a 100 000-gon
// spent 27 s here; issue 23). Faces in the order the members' corners meet them, each face's
// pieces in buffer order; a piece holds each root at most once (rebuild_face cuts a face at a
// repeated root), so each corner of v's cluster in a piece marks exactly one entry.
void Collapser::gather_fan_indexed(Index v) {
  fan_keys_.clear();
  Index rank = 0;
  for (Index m : members(v)) {
    for (Index c : conn_.corners_at_vertex(m)) {
      const Index f = conn_.corner_face[c];
      if (face_fan_token_[f] != fan_token_) {
        face_fan_token_[f] = fan_token_;
        face_fan_rank_[f] = rank++;
      }
      if (corner_piece_[c] != kInvalidIndex) fan_keys_.push_back({face_fan_rank_[f], corner_piece_[c], corner_piece_pos_[c]});
    }
  }
  std::sort(fan_keys_.begin(), fan_keys_.end());
  for (const auto& [face_rank, piece, pos] : fan_keys_)
    fan_.push_back({conn_.corner_face[piece_buf_[piece + 1]], piece + 1, pos, piece_buf_[piece]});
}

// The definition of nonmanifold_vertices() (connectivity.h) for one input vertex, computed only
// for the few vertices whose output fan splits: an endpoint of a non-manifold edge, or corners not
// joined into one fan through manifold edges.
bool Collapser::input_vertex_nonmanifold(Index v) {
  if (input_nm_[v] >= 0) return input_nm_[v] != 0;
  const auto cs = conn_.corners_at_vertex(v);
  bool nm = false;
  for (Index c : cs)
    for (Index ec : {c, conn_.corner_prev[c]}) nm = nm || conn_.is_nonmanifold_edge(conn_.corner_edge[ec]);
  if (!nm && cs.size() > 1) {
    UnionFind uf(static_cast<Index>(cs.size()));
    auto slot = [&](Index corner) -> Index {
      const auto it = std::lower_bound(cs.begin(), cs.end(), corner);
      return it != cs.end() && *it == corner ? static_cast<Index>(it - cs.begin()) : kInvalidIndex;
    };
    for (Index i = 0; i < cs.size(); ++i)
      for (Index e_corner : {cs[i], conn_.corner_prev[cs[i]]}) {
        const Index e = conn_.corner_edge[e_corner];
        if (conn_.edge_face_count(e) != 2) continue;
        const auto pair = conn_.corners_of_edge(e);
        const Index other = pair[0] == e_corner ? pair[1] : pair[0];
        for (Index cand : {other, conn_.corner_next[other]})
          if (const Index j = slot(cand); j != kInvalidIndex) uf.unite(i, j);
      }
    Index roots = 0;
    for (Index i = 0; i < cs.size(); ++i) roots += uf.find(i) == i;
    nm = roots > 1;
  }
  input_nm_[v] = nm ? 1 : 0;
  return nm;
}

bool Collapser::same_input_vertex_set(Index f, Index g) {
  if (mesh_.face_size(f) != mesh_.face_size(g)) return false;
  const auto a = mesh_.face_vertices(f), b = mesh_.face_vertices(g);
  tmp_a_.assign(a.begin(), a.end());
  tmp_b_.assign(b.begin(), b.end());
  std::sort(tmp_a_.begin(), tmp_a_.end());
  std::sort(tmp_b_.begin(), tmp_b_.end());
  return tmp_a_ == tmp_b_;
}

// The strict members of a cluster must be joined inside it through collapsed strict feature
// edges (a line that shortens: along one line, or along several through the junctions where
// they meet) or through collapsed edges of UV islands their lines may cross (an island too
// small for one output face, or below ClusterCollapseParams::crossing_island_area, shrinks
// between its lines). Otherwise two seams (boundaries,
// material borders) would meet in one vertex across a surviving region, or one line would be
// pinched shut. Several strict corners may merge: the cluster lands on the best of them
// (place_on_feature) and check_feature_edges holds every output line to its input line.
bool Collapser::features_valid(Index r) {
  const auto ms = members(r);
  Index strict_members = 0;
  for (Index m : ms) strict_members += feat_ptr_->on_strict(m);
  if (strict_members <= 1) return true;
  const Index b = seg_begin_[r], e = seg_end_[r];
  auto local = [&](Index v) {
    return static_cast<Index>(std::lower_bound(member_list_.begin() + b, member_list_.begin() + e, v) -
                              (member_list_.begin() + b));
  };
  UnionFind uf(e - b), boundary(e - b);
  const bool loops_may_close = params_.max_vanishing_part_area > 0.0;
  for (Index m : ms)
    for (Index c : conn_.corners_at_vertex(m))
      for (Index ec : {c, conn_.corner_prev[c]}) {
        const Index edge = conn_.corner_edge[ec];
        if (!collapsed_[edge] || !(feat_ptr_->is_strict(edge) || edge_in_crossable_island(edge))) continue;
        const Index o = conn_.other_vertex(edge, m);
        if (o == m || root_[o] != r) continue;
        uf.unite(local(m), local(o));
        // A cycle of open-boundary edges inside one cluster: a whole boundary loop collapsed to a
        // point, a hole closed or a part's outline gone (max_vanishing_part_area). Each boundary
        // edge is met once from each end; counted from the smaller.
        if (!loops_may_close && m < o && (feat_ptr_->edge_bits[edge] & kFeatureBoundary)) {
          if (boundary.find(local(m)) == boundary.find(local(o))) return false;
          boundary.unite(local(m), local(o));
        }
      }
  Index first = kInvalidIndex;
  for (Index m : ms) {
    if (!feat_ptr_->on_strict(m)) continue;
    const Index set = uf.find(local(m));
    if (first == kInvalidIndex) first = set;
    else if (set != first) return false;
  }
  return true;
}

// Issue 34 (docs/protect.md): a cluster may hold one protected vertex, which it is placed on
// (place()), but not two (the edge or chain between them would vanish, and one of them would
// move), nor a protected vertex and a strict feature corner (corners never move either, and the
// cluster can sit on only one of them).
bool Collapser::protection_valid(Index r) const {
  Index held = 0;
  Index corners = 0;
  for (Index m : members(r)) {
    if (protected_[m]) {
      ++held;
      continue;
    }
    if (feat_ptr_ && feat_ptr_->vertex_corner[m] && feat_ptr_->on_strict(m)) ++corners;
  }
  return held <= 1 && (held == 0 || corners == 0);
}

// A non-strict edge whose faces all lie in UV islands whose lines may merge through them.
bool Collapser::edge_in_crossable_island(Index e) const {
  if (face_island_.empty()) return false;
  for (Index c : conn_.corners_of_edge(e)) {
    const Index i = face_island_[conn_.corner_face[c]];
    if (i == kInvalidIndex || !island_crossable_[i]) return false;
  }
  return true;
}

// Vertex checks around output vertex v: its edges (new non-manifold, new boundary), its fan (new
// non-manifold vertex), duplicate faces through it, and the Hausdorff bound of a new placement.
// "New" compares with the input edges between the two clusters (all of them manifold / all
// interior) and the members (none non-manifold).
void Collapser::check_vertex(Index v) {
  if (features_on_ && cluster_size(v) > 1 && !features_valid(v)) blame(v, CollapseRefusal::Feature);
  if (!protected_.empty() && cluster_size(v) > 1 && !protection_valid(v)) blame(v, CollapseRefusal::Protected);
  gather_fan(v);
  const Index nfan = static_cast<Index>(fan_.size());
  // Issue 34: a protected vertex keeps a face. When every face around it was dropped (its
  // neighbours merged, or its part shrank away), the clusters around it are refused.
  if (!protected_.empty() && nfan == 0) {
    bool holds = false;
    for (Index m : members(v)) holds = holds || protected_[m];
    if (holds)
      for (Index m : members(v))
        for (Index c : conn_.corners_at_vertex(m)) {
          const Index f = conn_.corner_face[c];
          for (Index k = mesh_.face_begin(f); k < mesh_.face_end(f); ++k) blame(root_of_corner(k), CollapseRefusal::Protected);
        }
  }
  nbr_.clear();
  for (Index i = 0; i < nfan; ++i) {
    const FanEntry& fe = fan_[i];
    const Index* cs = piece_buf_.data() + fe.first;
    nbr_.emplace_back(root_of_corner(cs[fe.pos + 1 == fe.len ? 0 : fe.pos + 1]), i);
    nbr_.emplace_back(root_of_corner(cs[fe.pos == 0 ? fe.len - 1 : fe.pos - 1]), i);
  }
  std::sort(nbr_.begin(), nbr_.end());
  // The input edges behind v's output edges, needed only where an output edge has a face count
  // other than 2 (boundary or non-manifold): the usual interior vertex skips this.
  bool all_two = nbr_.size() % 2 == 0;
  for (std::size_t i = 0; all_two && i < nbr_.size(); i += 2)
    all_two = nbr_[i].first == nbr_[i + 1].first && (i + 2 == nbr_.size() || nbr_[i + 2].first != nbr_[i].first);
  // Also needed where a member lies on an open boundary: an output edge with two faces there may
  // have zipped two boundary runs together (see the count == 2 case below).
  bool boundary_member = false;
  if (features_on_ && all_two)
    for (Index m : members(v)) boundary_member = boundary_member || (feat_ptr_->vertex_bits[m] & kFeatureBoundary);
  pre_.clear();
  if (!all_two || boundary_member) {
    for (Index m : members(v))
      for (Index c : conn_.corners_at_vertex(m))
        for (Index ec : {c, conn_.corner_prev[c]}) {
          const Index e = conn_.corner_edge[ec];
          const Index o = root_[conn_.other_vertex(e, m)];
          if (o != v) pre_.emplace_back(o, conn_.edge_face_count(e));
        }
    std::sort(pre_.begin(), pre_.end());
  }

  fan_parent_.resize(nfan);
  std::iota(fan_parent_.begin(), fan_parent_.end(), Index{0});
  auto find = [&](Index x) {
    while (fan_parent_[x] != x) x = fan_parent_[x] = fan_parent_[fan_parent_[x]];
    return x;
  };
  std::size_t pj = 0;
  for (std::size_t i = 0; i < nbr_.size();) {
    const Index w = nbr_[i].first;
    std::size_t j = i;
    while (j < nbr_.size() && nbr_[j].first == w) ++j;
    const std::size_t count = j - i;
    while (pj < pre_.size() && pre_[pj].first < w) ++pj;
    Index min_in = kInvalidIndex, max_in = 0;
    for (std::size_t q = pj; q < pre_.size() && pre_[q].first == w; ++q) {
      min_in = std::min(min_in, pre_[q].second);
      max_in = std::max(max_in, pre_[q].second);
    }
    if (count > 2 && max_in <= 2) {
      blame(v, CollapseRefusal::NonManifoldEdge);
      blame(w, CollapseRefusal::NonManifoldEdge);
    } else if (count == 1 && min_in != kInvalidIndex && min_in >= 2) {
      blame(v, CollapseRefusal::NewBoundary);
      blame(w, CollapseRefusal::NewBoundary);
    } else if (count == 2) {
      const Index a = find(nbr_[i].second), b = find(nbr_[i + 1].second);
      if (a != b) fan_parent_[a] = b;
      // Two faces on an edge whose input edges between the two clusters include an open boundary
      // edge: the boundary was zipped shut there, to another boundary run sharing both endpoints
      // (a slit: two sheets whose coincident borders meet only at the slit's ends) or to itself.
      // Each cluster only shortens one boundary line, so features_valid cannot see it; the output
      // edge is then a seam (or smooth) where the input had a hole, which §6c counts as torn.
      if (features_on_ && min_in == 1) {
        blame(v, CollapseRefusal::Feature);
        blame(w, CollapseRefusal::Feature);
      }
    }
    i = j;
  }
  Index groups = 0;
  for (Index i = 0; i < nfan; ++i) groups += find(i) == i;
  if (groups > 1) {
    bool member_was_nm = false;
    for (Index m : members(v)) member_was_nm = member_was_nm || input_vertex_nonmanifold(m);
    if (!member_was_nm) {
      if (cluster_size(v) > 1) blame(v, CollapseRefusal::NonManifoldVertex);
      else
        for (const auto& entry : nbr_) blame(entry.first, CollapseRefusal::NonManifoldVertex);
    }
  }

  // Duplicates among the faces through v: key = (size, order-independent hash of the vertex
  // set); vertex sets are sorted and compared only when keys match.
  if (nfan >= 2) {
    key_roots_.clear();
    key_offsets_.assign(1, 0);
    key_hash_.clear();
    for (const FanEntry& fe : fan_) {
      std::uint64_t hsh = 0;
      for (Index i = 0; i < fe.len; ++i) {
        const Index r = root_of_corner(piece_buf_[fe.first + i]);
        key_roots_.push_back(r);
        std::uint64_t x = (r + 0x9E3779B97F4A7C15ull) * 0xBF58476D1CE4E5B9ull;  // splitmix-style
        hsh += (x ^ (x >> 31)) * 0x94D049BB133111EBull;
      }
      key_hash_.push_back(hsh);
      key_offsets_.push_back(static_cast<Index>(key_roots_.size()));
    }
    order_.resize(nfan);
    std::iota(order_.begin(), order_.end(), Index{0});
    std::sort(order_.begin(), order_.end(), [&](Index x, Index y) {
      return fan_[x].len != fan_[y].len ? fan_[x].len < fan_[y].len : key_hash_[x] < key_hash_[y];
    });
    for (Index s = 0; s < nfan;) {
      Index t = s + 1;
      while (t < nfan && fan_[order_[t]].len == fan_[order_[s]].len &&
             key_hash_[order_[t]] == key_hash_[order_[s]])
        ++t;
      if (t - s > 1)
        for (Index x = s; x < t; ++x)
          std::sort(key_roots_.begin() + key_offsets_[order_[x]], key_roots_.begin() + key_offsets_[order_[x] + 1]);
      for (Index x = s; x < t; ++x)
        for (Index y = x + 1; y < t; ++y) {
          const Index i = order_[x], j = order_[y];
          if (!std::equal(key_roots_.begin() + key_offsets_[i], key_roots_.begin() + key_offsets_[i + 1],
                          key_roots_.begin() + key_offsets_[j]))
            continue;
          const Index fi = fan_[i].face, fj = fan_[j].face;
          if (fi != fj && same_input_vertex_set(fi, fj)) continue;  // already duplicates in the input
          blame_piece(piece_buf_.data() + fan_[i].first, fan_[i].len, CollapseRefusal::DuplicateFace);
        }
      s = t;
    }
  }

  if (hausdorff_tol_ > 0.0 && cluster_size(v) > 1 && placed_round_[v] == round_) check_hausdorff(v);
  if (features_on_ && cluster_size(v) > 1) check_feature_edges(v);
}

// Output edges that continue a strict feature line must stay on it: every output edge v–w that
// comes from an input strict feature edge between the two clusters is sampled at ¼, ½, ¾, and each
// sample must lie within feature_tolerance · |v w| of the reference lines of the same kind (the
// original input's, in every pass of a multi-pass reduction). This is the rule `quadlod eval`
// counts as `seams_torn` (docs/metrics.md §6c): a chord that cuts a curved seam or boundary too
// short is refused here instead. Uses nbr_ of check_vertex.
void Collapser::check_feature_edges(Index v) {
  // Strict lines, and the UV seams of a per-face layout (not strict, but eval holds them to the
  // input's seams as any other: seams_torn).
  auto line_edge = [&](Index e) { return feat_ptr_->is_strict(e) || (feat_ptr_->edge_bits[e] & kFeatureUvSeam); };
  bool line_member = false;
  for (Index m : members(v)) line_member = line_member || feat_ptr_->on_strict(m) || (feat_ptr_->vertex_bits[m] & kFeatureUvSeam);
  if (!line_member) return;
  const double tol = std::max(0.0, params_.feature_tolerance);
  constexpr std::uint8_t kKinds[4] = {kFeatureBoundary, kFeatureNonManifold, kFeatureUvSeam, kFeatureMaterialBorder};
  line_edges_.clear();
  for (std::size_t i = 0; i < nbr_.size(); ++i) {
    const Index w = nbr_[i].first;
    if (i > 0 && nbr_[i - 1].first == w) continue;
    // Kinds of the input strict edges between the two clusters: the lines this edge continues.
    std::uint8_t kinds = 0;
    for (Index m : members(v))
      for (Index c : conn_.corners_at_vertex(m))
        for (Index ec : {c, conn_.corner_prev[c]}) {
          const Index e = conn_.corner_edge[ec];
          if (line_edge(e) && root_[conn_.other_vertex(e, m)] == w) kinds |= feat_ptr_->edge_bits[e];
        }
    if (!kinds) continue;
    line_edges_.emplace_back(w, kinds);
    const Vec3 &a = pos_[v], &b = pos_[w];
    const double bound = tol * (b - a).norm() + 1e-12 * diag_;
    bool ok = true;
    for (int k = 0; k < 4 && ok; ++k) {
      if (!(kinds & kKinds[k]) || reference_->by_kind[k].size() == 0) continue;
      for (double t : {0.25, 0.5, 0.75})
        ok = ok && reference_->by_kind[k].nearest(a + t * (b - a)).distance_sq <= bound * bound;
    }
    if (!ok) {
      // A cluster its quadric placed off its texture line goes onto the line next round instead
      // (place_on_line_again); only a placement on the line that still fails is refused.
      const bool v_back = place_on_line_again(v), w_back = place_on_line_again(w);
      if (!v_back && !w_back) {
        blame(v, CollapseRefusal::Feature);
        blame(w, CollapseRefusal::Feature);
      }
    }
  }
  // The other way round, for the lines of the shape (open boundaries, non-manifold edges): every
  // member on one lies within feature_tolerance of an output edge of its kind at v, so a line
  // that shortens never cuts off a tip (assimp_suzanne_subdiv at 0.8: two corners at a
  // boundary's sharp tip merged onto the lower one, and the tip's length became the Hausdorff
  // distance, 16× the rest). UV seams and material borders may shrink inside the surface: their
  // islands vanish that way.
  constexpr std::uint8_t kShape = kFeatureBoundary | kFeatureNonManifold;
  for (Index m : members(v)) {
    const std::uint8_t mine = feat_ptr_->vertex_bits[m] & kShape;
    if (!mine || !feat_ptr_->on_strict(m)) continue;
    const Vec3& p = mesh_.positions[m];
    if (p == pos_[v]) continue;
    bool covered = false, any = false;
    for (const auto& [w, kinds] : line_edges_) {
      if (!(kinds & mine)) continue;
      any = true;
      const Vec3 &a = pos_[v], &b = pos_[w];
      const double bound = tol * (b - a).norm() + 1e-12 * diag_;
      covered = covered || (closest_point_on_segment(p, a, b) - p).squaredNorm() <= bound * bound;
    }
    if (any && !covered) {
      blame(v, CollapseRefusal::Feature);
      return;
    }
  }
}

// A cluster on a texture line that its quadric placed off the line (placed_free_) and whose line
// edges leave the input line: placed on the line next round (on_line_, replace_) instead of
// refused. False when it already was on the line.
bool Collapser::place_on_line_again(Index r) {
  if (!placed_free_[r]) return false;
  if (on_line_[r]) return replace_round_[r] == round_;  // already going onto it this round
  on_line_[r] = 1;
  replace_round_[r] = round_;
  replace_.push_back(r);
  return true;
}

// One-sided distance bound (documented approximation of the Hausdorff distance): the placed vertex
// and the midpoints of its output edges to unmoved (singleton) neighbours, against the union of
// the input faces around the cluster's members (fan-triangulated). Uses the fan_ of check_vertex.
void Collapser::check_hausdorff(Index v) {
  faces_tmp_.clear();
  ++fan_token_;
  for (Index m : members(v))
    for (Index c : conn_.corners_at_vertex(m)) {
      const Index f = conn_.corner_face[c];
      if (face_fan_token_[f] == fan_token_) continue;
      face_fan_token_[f] = fan_token_;
      faces_tmp_.push_back(f);
    }
  const double tol2 = hausdorff_tol_ * hausdorff_tol_;
  auto within = [&](const Vec3& s) {
    for (Index f : faces_tmp_) {
      const Index b = mesh_.face_begin(f), k = mesh_.face_size(f);
      const Vec3& p0 = mesh_.positions[mesh_.corner_vertex[b]];
      for (Index i = 1; i + 1 < k; ++i) {
        const Vec3 cp = closest_point_on_triangle(s, p0, mesh_.positions[mesh_.corner_vertex[b + i]],
                                                  mesh_.positions[mesh_.corner_vertex[b + i + 1]])
                            .point;
        if ((cp - s).squaredNorm() <= tol2) return true;
      }
    }
    return false;
  };
  bool ok = within(pos_[v]);
  for (std::size_t i = 0; ok && i < nbr_.size(); ++i) {
    const Index w = nbr_[i].first;
    if (cluster_size(w) == 1) ok = within(0.5 * (pos_[v] + pos_[w]));
  }
  if (!ok) blame(v, CollapseRefusal::Hausdorff);
}

void Collapser::check(const std::vector<Index>& dirty) {
  std::vector<std::vector<FaceBlame>> found(thread_count(params_.threads));
  const std::size_t chunks = parallel_chunks(dirty.size(), params_.threads, params_.min_parallel_faces,
                                             [&](std::size_t begin, std::size_t end, std::size_t chunk) {
                                               for (std::size_t i = begin; i < end; ++i) check_face(dirty[i], found[chunk]);
                                             });
  for (std::size_t k = 0; k < chunks; ++k)
    for (const FaceBlame& b : found[k]) blame(b.root, b.why);
  // Vertices whose fan may have changed: every vertex of a dirty face (dropped faces included).
  ++vert_tok_;
  std::vector<Index> verts;
  for (Index f : dirty)
    for (Index c = mesh_.face_begin(f); c < mesh_.face_end(f); ++c) {
      const Index r = root_of_corner(c);
      if (vert_token_[r] == vert_tok_) continue;
      vert_token_[r] = vert_tok_;
      verts.push_back(r);
    }
  for (Index v : verts) check_vertex(v);
  if (!part_begin_.empty()) check_parts(dirty);
  if (!face_island_.empty()) check_islands(dirty);
}

}  // namespace quadlod::collapse_detail
