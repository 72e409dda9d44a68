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
#include "post/cluster_collapse.h"

#include "geometry/bvh.h"
#include "geometry/quadric.h"
#include "geometry/sampling.h"
#include "mesh/union_find.h"
#include "util/progress.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <utility>

namespace quadlod {

namespace {

constexpr std::uint8_t kNoReason = 0xFF;

// Area vector (Newell, shifted to the first corner against cancellation far from the origin).
template <typename PositionOf>
Vec3 area_vector(Index k, PositionOf&& at) {
  const Vec3 o = at(0);
  Vec3 sum = Vec3::Zero();
  for (Index i = 1; i + 1 < k; ++i) sum += (at(i) - o).cross(at(i + 1) - o);
  return 0.5 * sum;
}

// A corner's turn: (next − cur) × (prev − cur); along +n at a convex corner of a CCW polygon.
inline Vec3 corner_turn(const Vec3& prev, const Vec3& cur, const Vec3& next) {
  return (next - cur).cross(prev - cur);
}

class Collapser {
 public:
  Collapser(const PolyMesh& mesh, const Connectivity& conn, const ClusterCollapseParams& params,
            ClusterCollapseStats& stats)
      : mesh_(mesh), conn_(conn), params_(params), stats_(stats) {}

  void run(const std::vector<std::uint8_t>& edge_kept, ClusterCollapseResult& out);

 private:
  // --- setup ---------------------------------------------------------------------------------
  void precompute();
  void build_vertex_terms();
  void initial_clusters(const std::vector<std::uint8_t>& edge_kept);

  // --- clusters --------------------------------------------------------------------------------
  Index cluster_size(Index r) const { return seg_end_[r] - seg_begin_[r]; }
  std::span<const Index> members(Index r) const {
    return {member_list_.data() + seg_begin_[r], cluster_size(r)};
  }
  Index root_of_corner(Index c) const { return root_[conn_.corner_vertex[c]]; }
  void place(Index r);
  bool place_on_feature(Index r, const Quadric& q);
  bool features_valid(Index r);
  void check_feature_edges(Index v);
  void split(Index r, CollapseRefusal why, bool dissolve);

  // --- faces -----------------------------------------------------------------------------------
  Index piece_base(Index f) const { return 2 * mesh_.face_begin(f); }
  void rebuild_face(Index f);

  // --- checks ----------------------------------------------------------------------------------
  void check(const std::vector<Index>& dirty);
  void check_face(Index f);
  void check_vertex(Index v);
  void check_hausdorff(Index v);
  template <class PositionOf>
  bool faces_input_surface(Index len, PositionOf&& at, const Vec3& av) const;
  void gather_fan(Index v);
  void blame(Index r, CollapseRefusal why);
  void blame_piece(const Index* corners, Index len, CollapseRefusal why);
  bool same_input_vertex_set(Index f, Index g);
  bool input_vertex_nonmanifold(Index v);

  // --- output ----------------------------------------------------------------------------------
  void assemble(const std::vector<std::uint8_t>& edge_kept, ClusterCollapseResult& out);
  void project_attributes(PolyMesh& om, std::vector<std::vector<Index>>& uv_override,
                          std::vector<Index>& normal_override);

  const PolyMesh& mesh_;
  const Connectivity& conn_;
  const ClusterCollapseParams& params_;
  ClusterCollapseStats& stats_;

  Index nv_ = 0, nf_ = 0, ne_ = 0;
  double diag_ = 1.0;       // input bbox diagonal
  double h_ = 1.0;          // mean input edge length
  double zero_area_ = 0.0;  // absolute area threshold
  double zero_length_sq_ = 0.0;  // squared absolute side-length threshold
  double cos_flip_ = 0.0;
  double sin_fold_ = 0.0;  // a corner is reflex when it turns past 180° + corner_fold_tolerance
  double hausdorff_tol_ = 0.0;

  std::vector<Vec3> face_n_;       // unit normal of each input face (zero if no area)
  std::vector<double> face_area_;  // area of each input face
  std::vector<double> edge_len_;
  std::vector<VertexTerms> terms_;
  std::vector<std::int8_t> input_nm_;  // input vertex non-manifold: 1 / 0, −1 not computed yet
  bool features_on_ = false;
  // UV islands (set 0) the collapse must neither cut in pieces nor, from
  // params_.min_kept_island_area up, remove whole (issue 7); empty when off.
  std::vector<Index> face_island_;  // per input face: its island, or kInvalidIndex
  std::vector<Index> island_begin_, island_faces_;  // faces of island i: [begin[i], begin[i+1])
  std::vector<std::uint8_t> island_keep_;   // 1: must keep a face (area >= min_kept_island_area)
  std::vector<Index> island_pieces_;        // edge-connected pieces of the island in the input
  std::vector<Index> island_token_;
  Index island_tok_ = 0;
  std::vector<Index> root_component_, root_component_token_;  // per root, during check_islands
  // Output sides that two or more pieces of the island being checked lie on, but that do not
  // join them because more than two output faces lie there (find_uv_islands joins faces only
  // across edges with exactly two): {a, b, piece} per piece on such a side.
  struct IslandSide {
    Index a, b, piece;
  };
  std::vector<IslandSide> unjoined_sides_;
  Index component_tok_ = 0;
  void protect_islands();
  void check_islands(const std::vector<Index>& dirty);
  template <class VertexOf>
  Index island_components(Index i, VertexOf&& vertex_of, std::vector<Index>* piece_component);
  Index pieces_on_side(Index a, Index b);
  FeatureEdges own_feat_;
  const FeatureEdges* feat_ptr_ = nullptr;
  FeatureReference own_reference_;
  const FeatureReference* reference_ = nullptr;
  SurfaceReference own_surface_;
  const SurfaceReference* surface_ = nullptr;
  double orientation_tol_ = 0.0;  // absolute slack of the surface orientation check

  // Clusters. Every vertex has a root (the smallest member id of its cluster); a root's members
  // are member_list_[seg_begin_[r], seg_end_[r]), sorted ascending.
  std::vector<std::uint8_t> collapsed_;
  std::vector<Index> root_, member_list_, seg_begin_, seg_end_;
  std::vector<Vec3> pos_;           // output position of each root (input position otherwise)
  std::vector<Index> placed_round_;  // round in which a non-singleton root was last placed

  // Output pieces of every input face, stored in a region of 2·(face size) slots starting at
  // piece_base(f): [len, corner…, len, corner…]. Corners are input corner ids.
  std::vector<Index> piece_buf_;
  std::vector<Index> piece_count_;
  std::vector<std::uint32_t> face_tri_eq_;
  std::vector<std::uint8_t> face_pinched_;
  std::vector<std::uint8_t> face_blame_;  // refusal reason that made the face dirty this round

  // Round state.
  Index round_ = 0;
  std::vector<std::uint8_t> blame_reason_;  // per root, kNoReason when not blamed
  std::vector<Index> blamed_;
  std::vector<Index> next_dirty_, to_place_;
  std::vector<Index> face_dirty_token_, face_fan_token_, vert_token_;
  Index dirty_token_ = 0, fan_token_ = 0, vert_tok_ = 0;

  // Scratch.
  struct FanEntry {
    Index face;   // input face
    Index first;  // offset of the piece's first corner in piece_buf_
    Index pos;    // position of the vertex inside the piece
    Index len;
  };
  std::vector<FanEntry> fan_;
  std::vector<std::pair<Index, Index>> nbr_;  // (neighbour root, fan entry)
  std::vector<std::pair<Index, Index>> pre_;  // (neighbour root, input edge face count)
  std::vector<Index> fan_parent_;
  std::vector<Index> kept_, stack_, stack_pos_;
  std::vector<Index> key_roots_, key_offsets_, order_;
  std::vector<std::uint64_t> key_hash_;
  std::vector<Index> tmp_a_, tmp_b_, faces_tmp_, edges_tmp_;
};

// --- setup ---------------------------------------------------------------------------------------

void Collapser::precompute() {
  nv_ = mesh_.num_vertices();
  nf_ = mesh_.num_faces();
  ne_ = conn_.num_edges;
  diag_ = bounding_box(mesh_).diagonal();
  if (!(diag_ > 0.0) || !std::isfinite(diag_)) diag_ = 1.0;

  edge_len_.resize(ne_);
  double sum = 0.0;
  Index counted = 0;
  for (Index e = 0; e < ne_; ++e) {
    const auto [a, b] = conn_.edge_vertices[e];
    edge_len_[e] = (mesh_.positions[a] - mesh_.positions[b]).norm();
    if (edge_len_[e] > 0.0) {
      sum += edge_len_[e];
      ++counted;
    }
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
  for (Index f = 0; f < nf_; ++f) {
    const Vec3 av = face_area_vector(mesh_, f);
    face_area_[f] = av.norm();
    face_n_[f] = face_area_[f] > 0.0 ? Vec3(av / face_area_[f]) : Vec3::Zero();
  }
  input_nm_.assign(nv_, -1);
  if (params_.check_surface_orientation) {
    surface_ = params_.surface_reference;
    if (!surface_) {
      own_surface_ = make_surface_reference(mesh_);
      surface_ = &own_surface_;
    }
    orientation_tol_ = std::max(0.0, params_.orientation_tolerance) * surface_->longest_side;
  }
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
  }
  build_vertex_terms();
}

// Islands the collapse keeps whole (docs/attributes.md, "Islands neither vanish nor split").
// Seams are strict, so no cluster joins two islands, but nothing else stopped a cluster from
// taking an island's last faces — a closed part without any feature line (an eyeball of
// flightgear_head_amelia, 112 faces, one island) or a lone n-gon decal whose boundary is one
// feature line (flightgear_cg57_cruiser_hd) collapsed whole — or from cutting it in two: a thin
// tube (cg57, 4 quads around) whose two middle rings each collapse to a point leaves two cones
// and drops the faces between, with no new boundary and no non-manifold vertex. Per-face layouts
// are exempt: they must lose islands to be reduced at all.
void Collapser::protect_islands() {
  if (mesh_.uv_sets.empty() || params_.min_kept_island_area < 0.0) return;
  const UvIslands islands = find_uv_islands(mesh_, conn_, 0);
  std::vector<Index> size(islands.num_islands, 0);
  Index with_uv = 0, alone = 0;
  for (Index f = 0; f < nf_; ++f)
    if (islands.face_island[f] != kInvalidIndex) ++size[islands.face_island[f]];
  for (Index f = 0; f < nf_; ++f)
    if (islands.face_island[f] != kInvalidIndex) {
      ++with_uv;
      alone += size[islands.face_island[f]] == 1;
    }
  if (double(alone) > params_.features.per_face_layout_fraction * double(with_uv)) return;
  const Index n = islands.num_islands;
  if (n == 0) return;
  face_island_ = islands.face_island;
  island_begin_.assign(n + 1, 0);
  for (Index f = 0; f < nf_; ++f)
    if (face_island_[f] != kInvalidIndex) ++island_begin_[face_island_[f] + 1];
  for (Index i = 0; i < n; ++i) island_begin_[i + 1] += island_begin_[i];
  island_faces_.resize(island_begin_[n]);
  std::vector<Index> fill(island_begin_.begin(), island_begin_.end() - 1);
  for (Index f = 0; f < nf_; ++f)
    if (face_island_[f] != kInvalidIndex) island_faces_[fill[face_island_[f]]++] = f;
  island_keep_.assign(n, 0);
  island_pieces_.assign(n, 0);
  for (Index i = 0; i < n; ++i) {
    double area = islands.area_3d[i];
    if (params_.face_island_area && params_.face_island_area->size() == nf_)
      for (Index k = island_begin_[i]; k < island_begin_[i + 1]; ++k)
        area = std::max(area, (*params_.face_island_area)[island_faces_[k]]);
    island_keep_[i] = area > 0.0 && area >= params_.min_kept_island_area;
    island_pieces_[i] = island_components(i, [&](Index c) { return mesh_.corner_vertex[c]; }, nullptr);
  }
  island_token_.assign(n, 0);
  root_component_.assign(nv_, kInvalidIndex);
  root_component_token_.assign(nv_, 0);
}

// Edge-connected components of island i's faces with corners mapped by vertex_of (input
// vertices, or output vertices = cluster roots over the surviving pieces). piece_component, when
// given, gets each surviving piece's component, in the order of island_faces_ and pieces.
template <class VertexOf>
Index Collapser::island_components(Index i, VertexOf&& vertex_of, std::vector<Index>* piece_component) {
  struct Side {
    Index a, b, piece;
    bool operator<(const Side& o) const { return a != o.a ? a < o.a : b != o.b ? b < o.b : piece < o.piece; }
  };
  std::vector<Side> sides;
  Index pieces = 0;
  const bool built = piece_component != nullptr;
  for (Index k = island_begin_[i]; k < island_begin_[i + 1]; ++k) {
    const Index f = island_faces_[k];
    if (!built) {  // the input face itself
      for (Index c = mesh_.face_begin(f); c < mesh_.face_end(f); ++c) {
        const Index a = vertex_of(c), b = vertex_of(mesh_.face_begin(f) + (c + 1 - mesh_.face_begin(f)) % mesh_.face_size(f));
        sides.push_back({std::min(a, b), std::max(a, b), pieces});
      }
      ++pieces;
      continue;
    }
    Index off = piece_base(f);
    for (Index p = 0; p < piece_count_[f]; ++p) {
      const Index len = piece_buf_[off];
      for (Index j = 0; j < len; ++j) {
        const Index a = vertex_of(piece_buf_[off + 1 + j]), b = vertex_of(piece_buf_[off + 1 + (j + 1) % len]);
        sides.push_back({std::min(a, b), std::max(a, b), pieces});
      }
      ++pieces;
      off += len + 1;
    }
  }
  std::sort(sides.begin(), sides.end());
  UnionFind uf(pieces);
  if (!built) {
    for (std::size_t k = 1; k < sides.size(); ++k)
      if (sides[k].a == sides[k - 1].a && sides[k].b == sides[k - 1].b) uf.unite(sides[k].piece, sides[k - 1].piece);
  } else {
    // find_uv_islands joins faces only across edges with exactly two faces, so an output side
    // joins two pieces only if no other output face lies on it. A collapse can fold an island
    // onto itself or onto a coincident sheet (flightgear_cg57_cruiser_hd at 0.6: one side with
    // three faces of a 24-quad island and two of a twin sheet), and the island is then cut in
    // two there although its UVs agree across the side. Such sides are kept for the blame.
    unjoined_sides_.clear();
    for (std::size_t k = 0; k < sides.size();) {
      std::size_t end = k + 1;
      while (end < sides.size() && sides[end].a == sides[k].a && sides[end].b == sides[k].b) ++end;
      if (end - k == 2 && pieces_on_side(sides[k].a, sides[k].b) == 2)
        uf.unite(sides[k].piece, sides[k + 1].piece);
      else if (end - k >= 2)
        for (std::size_t j = k; j < end; ++j) unjoined_sides_.push_back({sides[j].a, sides[j].b, sides[j].piece});
      k = end;
    }
  }
  Index components = 0;
  std::vector<Index> id(pieces, kInvalidIndex);
  if (built) piece_component->assign(pieces, kInvalidIndex);
  for (Index p = 0; p < pieces; ++p) {
    Index& c = id[uf.find(p)];
    if (c == kInvalidIndex) c = components++;
    if (built) (*piece_component)[p] = c;
  }
  return components;
}

// Output pieces of every input face, the island's or not, with a side between roots a and b:
// the sides next to a in its fan. Rebuilds fan_: called from check_islands, after every fan of
// the round is done.
Index Collapser::pieces_on_side(Index a, Index b) {
  gather_fan(a);
  Index count = 0;
  for (const auto& e : fan_) {
    const Index* cs = piece_buf_.data() + e.first;
    count += root_of_corner(cs[(e.pos + 1) % e.len]) == b;
    count += root_of_corner(cs[(e.pos + e.len - 1) % e.len]) == b;
  }
  return count;
}

// Per-vertex quadrics, after Knodt's simple_qem (see the file comment). Two deliberate changes:
//   * a face plane is weighted by the corner's share of the face *area*, split among corners by
//     interior angle (area θ_c / Σθ), instead of by the angle alone: §3.3.2 asks for area
//     weighting and the angle split keeps Knodt's per-corner distribution;
//   * edge planes carry |e| · h / 2π instead of |e| / h, so edge and face terms have the same
//     units (area) and, on a regular quad grid, the same ratio as in Knodt's code.
void Collapser::build_vertex_terms() {
  terms_ = build_vertex_quadrics(mesh_, conn_, face_n_, face_area_, h_, params_.placement).terms;
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
  for (Index m : ms) t.add_vertex(terms_[m], mesh_.positions[m]);
  if (features_on_) {
    // place_on_feature minimises the regularised quadric along the line.
    if (place_on_feature(r, regularized_quadric(t, h_, params_.placement))) {
      placed_round_[r] = round_;
      return;
    }
  }
  const ClusterPlacement pl = place_cluster(t, h_, params_.placement, [&](auto&& visit) {
    for (Index m : ms) visit(mesh_.positions[m]);
  });
  stats_.placements_pseudo_inverse += pl.pseudo_inverse;
  stats_.placements_volume_constrained += pl.volume_constrained;
  stats_.placements_fallback += pl.fallback;
  pos_[r] = pl.position;
  placed_round_[r] = round_;
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
bool Collapser::place_on_feature(Index r, const Quadric& q) {
  Index corners = 0, corner = kInvalidIndex;
  bool strict = false, any = false;
  // Vertices whose only feature is a hard edge follow their quadric unless place_on_hard_edges.
  auto counts = [&](Index m) {
    return feat_ptr_->on_feature(m) &&
           (params_.place_on_hard_edges || (feat_ptr_->vertex_bits[m] & ~std::uint32_t(kFeatureHardEdge)) != 0);
  };
  for (Index m : members(r)) {
    if (!counts(m)) continue;
    any = true;
    strict = strict || feat_ptr_->on_strict(m);
    if (feat_ptr_->vertex_corner[m]) {
      ++corners;
      corner = m;
    }
  }
  if (!any) return false;
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
    for (Index m : members(r)) {
      if (!feat_ptr_->vertex_corner[m]) continue;
      const double err = q(mesh_.positions[m]);
      if (err < best_err) {
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
        if (!feat_ptr_->is_feature(e) || (strict && !feat_ptr_->is_strict(e))) continue;
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

// A cluster may hold at most one strict feature corner, and its members on strict lines must be
// joined through collapsed strict feature edges: otherwise two seams (boundaries, material
// borders) would meet in one vertex, or one line would be pinched shut.
bool Collapser::features_valid(Index r) {
  const auto ms = members(r);
  Index strict_members = 0, strict_corners = 0;
  for (Index m : ms)
    if (feat_ptr_->on_strict(m)) {
      ++strict_members;
      strict_corners += feat_ptr_->vertex_corner[m];
    }
  if (strict_corners > 1) return false;
  if (strict_members <= 1) return true;
  const Index b = seg_begin_[r], e = seg_end_[r];
  auto local = [&](Index v) {
    return static_cast<Index>(std::lower_bound(member_list_.begin() + b, member_list_.begin() + e, v) -
                              (member_list_.begin() + b));
  };
  UnionFind uf(e - b);
  Index parts = strict_members;
  for (Index m : ms) {
    if (!feat_ptr_->on_strict(m)) continue;
    for (Index c : conn_.corners_at_vertex(m))
      for (Index ec : {c, conn_.corner_prev[c]}) {
        const Index edge = conn_.corner_edge[ec];
        if (!collapsed_[edge] || !feat_ptr_->is_strict(edge)) continue;
        const Index o = conn_.other_vertex(edge, m);
        if (o == m || root_[o] != r) continue;
        const Index lm = local(m), lo = local(o);
        if (uf.find(lm) == uf.find(lo)) continue;
        uf.unite(lm, lo);
        --parts;
      }
  }
  return parts == 1;
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
  auto emit = [&](const Index* cs, Index len) {
    if (len < 3) return;
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

// Face checks on every piece of a dirty face: degenerate, flipped, folded at a corner. The
// reference is the input face the piece comes from (its normal and its corners' convexity).
void Collapser::check_face(Index f) {
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

// Vertex checks around output vertex v: its edges (new non-manifold, new boundary), its fan (new
// non-manifold vertex), duplicate faces through it, and the Hausdorff bound of a new placement.
// "New" compares with the input edges between the two clusters (all of them manifold / all
// interior) and the members (none non-manifold).
void Collapser::check_vertex(Index v) {
  if (features_on_ && cluster_size(v) > 1 && !features_valid(v)) blame(v, CollapseRefusal::Feature);
  gather_fan(v);
  const Index nfan = static_cast<Index>(fan_.size());
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
  bool strict_member = false;
  for (Index m : members(v)) strict_member = strict_member || feat_ptr_->on_strict(m);
  if (!strict_member) return;
  const double tol = std::max(0.0, params_.feature_tolerance);
  constexpr std::uint8_t kKinds[4] = {kFeatureBoundary, kFeatureNonManifold, kFeatureUvSeam, kFeatureMaterialBorder};
  for (std::size_t i = 0; i < nbr_.size(); ++i) {
    const Index w = nbr_[i].first;
    if (i > 0 && nbr_[i - 1].first == w) continue;
    // Kinds of the input strict edges between the two clusters: the lines this edge continues.
    std::uint8_t kinds = 0;
    for (Index m : members(v))
      for (Index c : conn_.corners_at_vertex(m))
        for (Index ec : {c, conn_.corner_prev[c]}) {
          const Index e = conn_.corner_edge[ec];
          if (feat_ptr_->is_strict(e) && root_[conn_.other_vertex(e, m)] == w) kinds |= feat_ptr_->edge_bits[e];
        }
    if (!kinds) continue;
    const Vec3 &a = pos_[v], &b = pos_[w];
    const double bound = tol * (b - a).norm() + 1e-12 * diag_;
    bool ok = true;
    for (int k = 0; k < 4 && ok; ++k) {
      if (!(kinds & kKinds[k]) || reference_->by_kind[k].size() == 0) continue;
      for (double t : {0.25, 0.5, 0.75})
        ok = ok && reference_->by_kind[k].nearest(a + t * (b - a)).distance_sq <= bound * bound;
    }
    if (!ok) {
      blame(v, CollapseRefusal::Feature);
      blame(w, CollapseRefusal::Feature);
    }
  }
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
  for (Index f : dirty) check_face(f);
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
  if (!face_island_.empty()) check_islands(dirty);
}

// Islands of dirty faces (refusal `island`):
//   * vanished: an island of at least min_kept_island_area without any surviving face. The
//     clusters at the corners of its largest face are refused (split, then dissolved), until that
//     face survives; refusing every cluster on the island would undo far more than needed.
//   * split: its surviving pieces fall into more edge-connected components than its input faces
//     had (one). The clusters at the corners of the dropped faces between two components are
//     refused — the ring of a tube collapsed to a point on each side of a dropped band.
void Collapser::check_islands(const std::vector<Index>& dirty) {
  ++island_tok_;
  std::vector<Index> piece_component;
  for (Index f : dirty) {
    const Index i = face_island_[f];
    if (i == kInvalidIndex || island_token_[i] == island_tok_) continue;
    island_token_[i] = island_tok_;
    const Index* begin = island_faces_.data() + island_begin_[i];
    const Index* end = island_faces_.data() + island_begin_[i + 1];
    if (!std::any_of(begin, end, [&](Index g) { return piece_count_[g] > 0; })) {
      if (!island_keep_[i]) continue;
      const Index* largest = std::max_element(begin, end, [&](Index a, Index b) { return face_area_[a] < face_area_[b]; });
      for (Index c = mesh_.face_begin(*largest); c < mesh_.face_end(*largest); ++c)
        blame(root_of_corner(c), CollapseRefusal::Island);
      continue;
    }
    const Index components = island_components(i, [&](Index c) { return root_of_corner(c); }, &piece_component);
    if (components <= island_pieces_[i]) continue;
    // The component of every root on a surviving piece, then the dropped faces touching two.
    ++component_tok_;
    Index p = 0;
    for (const Index* g = begin; g != end; ++g) {
      Index off = piece_base(*g);
      for (Index q = 0; q < piece_count_[*g]; ++q, ++p) {
        const Index len = piece_buf_[off];
        for (Index j = 0; j < len; ++j) {
          const Index r = root_of_corner(piece_buf_[off + 1 + j]);
          if (root_component_token_[r] != component_tok_) {
            root_component_token_[r] = component_tok_;
            root_component_[r] = piece_component[p];
          }
        }
        off += len + 1;
      }
    }
    bool blamed_any = false;
    // A side with more than two faces that would join two components if it had only the
    // island's two: refuse the clusters at its ends, which made it (the island's own pieces
    // folded onto one side, or a coincident sheet collapsed onto it).
    for (std::size_t k = 0; k < unjoined_sides_.size();) {
      std::size_t side_end = k + 1;
      bool two = false;
      while (side_end < unjoined_sides_.size() && unjoined_sides_[side_end].a == unjoined_sides_[k].a &&
             unjoined_sides_[side_end].b == unjoined_sides_[k].b) {
        two = two || piece_component[unjoined_sides_[side_end].piece] != piece_component[unjoined_sides_[k].piece];
        ++side_end;
      }
      const Index a = unjoined_sides_[k].a, b = unjoined_sides_[k].b;
      if (two && (cluster_size(a) > 1 || cluster_size(b) > 1)) {
        blame(a, CollapseRefusal::Island);
        blame(b, CollapseRefusal::Island);
        blamed_any = true;
      }
      k = side_end;
    }
    for (const Index* g = begin; g != end; ++g) {
      if (piece_count_[*g] > 0) continue;
      Index first = kInvalidIndex;
      bool two = false;
      for (Index c = mesh_.face_begin(*g); c < mesh_.face_end(*g); ++c) {
        const Index r = root_of_corner(c);
        if (root_component_token_[r] != component_tok_) continue;
        if (first == kInvalidIndex) first = root_component_[r];
        else two = two || root_component_[r] != first;
      }
      if (!two) continue;
      blamed_any = true;
      for (Index c = mesh_.face_begin(*g); c < mesh_.face_end(*g); ++c) blame(root_of_corner(c), CollapseRefusal::Island);
    }
    if (!blamed_any)  // no dropped face between two pieces: refuse every cluster on a dropped face
      for (const Index* g = begin; g != end; ++g)
        if (piece_count_[*g] == 0)
          for (Index c = mesh_.face_begin(*g); c < mesh_.face_end(*g); ++c) blame(root_of_corner(c), CollapseRefusal::Island);
  }
}

// --- driver ----------------------------------------------------------------------------------------

void Collapser::run(const std::vector<std::uint8_t>& edge_kept, ClusterCollapseResult& out) {
  precompute();
  initial_clusters(edge_kept);

  pos_ = mesh_.positions;
  placed_round_.assign(nv_, kInvalidIndex);
  blame_reason_.assign(nv_, kNoReason);
  vert_token_.assign(nv_, 0);
  stack_pos_.assign(nv_, kInvalidIndex);
  face_dirty_token_.assign(nf_, 0);
  face_fan_token_.assign(nf_, 0);
  face_blame_.assign(nf_, kNoReason);
  piece_buf_.assign(2 * static_cast<std::size_t>(mesh_.num_corners()), 0);
  piece_count_.assign(nf_, 0);
  face_tri_eq_.assign(nf_, 0);
  face_pinched_.assign(nf_, 0);

  round_ = 0;
  for (Index v = 0; v < nv_; ++v)
    if (root_[v] == v && cluster_size(v) > 1) place(v);
  std::vector<Index> dirty, all_faces;
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
    check(dirty);
    if (blamed_.empty() && !face_island_.empty()) {
      // A round can split an island none of whose faces it touched: collapsing a coincident
      // sheet onto an island's edge makes that edge non-manifold (cg57 at 0.6). So before the
      // collapse is final, every island is checked once more.
      if (all_faces.empty()) {
        all_faces.resize(nf_);
        std::iota(all_faces.begin(), all_faces.end(), Index{0});
      }
      check_islands(all_faces);
    }
    if (blamed_.empty()) break;
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
    for (Index f : next_dirty_) {
      const std::int64_t before = face_tri_eq_[f];
      rebuild_face(f);
      stats_.refused_tri_equivalents[face_blame_[f]] += std::int64_t(face_tri_eq_[f]) - before;
      face_blame_[f] = kNoReason;
    }
    dirty.swap(next_dirty_);
  }
  assemble(edge_kept, out);
}

void Collapser::assemble(const std::vector<std::uint8_t>& edge_kept, ClusterCollapseResult& out) {
  PolyMesh& om = out.mesh;
  // Used output vertices, numbered in increasing root id.
  std::vector<Index> new_id(nv_, kInvalidIndex);
  for (Index f = 0; f < nf_; ++f) {
    Index off = piece_base(f);
    for (Index p = 0; p < piece_count_[f]; ++p) {
      const Index len = piece_buf_[off];
      for (Index i = 0; i < len; ++i) new_id[root_of_corner(piece_buf_[off + 1 + i])] = 0;
      off += len + 1;
    }
  }
  Index next = 0;
  for (Index v = 0; v < nv_; ++v)
    if (root_[v] == v && new_id[v] != kInvalidIndex) new_id[v] = next++;
  om.positions.resize(next);
  const bool colors = mesh_.vertex_colors.size() == nv_ && nv_ > 0;
  if (colors) om.vertex_colors.assign(next, Vec3::Zero());
  out.vertex_map.assign(nv_, kInvalidIndex);
  for (Index v = 0; v < nv_; ++v) {
    const Index r = root_[v];
    const Index id = new_id[r];
    if (id == kInvalidIndex) {
      ++stats_.vertices_removed_unused;
      continue;
    }
    out.vertex_map[v] = id;
    if (r == v) om.positions[id] = pos_[v];
    if (colors) om.vertex_colors[id] += mesh_.vertex_colors[v] / double(cluster_size(r));
  }

  // Faces, in input order, pieces in walk order; attributes per surviving corner: its own input
  // index, or the value projected / recomputed for its wedge when its vertex moved.
  const bool normals = mesh_.has_normals();
  const bool tag_o = !mesh_.face_object.empty(), tag_g = !mesh_.face_group.empty();
  const bool tag_m = !mesh_.face_material.empty(), tag_s = !mesh_.face_smoothing.empty();
  om.uv_sets.resize(mesh_.uv_sets.size());
  for (std::size_t k = 0; k < om.uv_sets.size(); ++k) {
    om.uv_sets[k].name = mesh_.uv_sets[k].name;
    om.uv_sets[k].values = mesh_.uv_sets[k].values;
  }
  om.normals = mesh_.normals;
  std::vector<std::vector<Index>> uv_override;
  std::vector<Index> normal_override;
  if (params_.project_attributes) project_attributes(om, uv_override, normal_override);
  auto uv_of = [&](std::size_t k, Index c) {
    const Index t = uv_override.empty() ? kInvalidIndex : uv_override[k][c];
    return t != kInvalidIndex ? t : mesh_.uv_sets[k].corner[c];
  };
  auto normal_of = [&](Index c) {
    const Index t = normal_override.empty() ? kInvalidIndex : normal_override[c];
    return t != kInvalidIndex ? t : mesh_.corner_normal[c];
  };
  om.object_names = mesh_.object_names;
  om.group_names = mesh_.group_names;
  om.material_names = mesh_.material_names;
  om.material_libraries = mesh_.material_libraries;
  om.face_offsets.assign(1, 0);
  om.corner_vertex.reserve(mesh_.num_corners());
  for (Index f = 0; f < nf_; ++f) {
    if (piece_count_[f] == 0) ++stats_.faces_dropped;
    if (face_pinched_[f]) ++stats_.faces_pinched;
    Index off = piece_base(f);
    for (Index p = 0; p < piece_count_[f]; ++p) {
      const Index len = piece_buf_[off];
      for (Index i = 0; i < len; ++i) {
        const Index c = piece_buf_[off + 1 + i];
        om.corner_vertex.push_back(new_id[root_of_corner(c)]);
        for (std::size_t k = 0; k < om.uv_sets.size(); ++k) om.uv_sets[k].corner.push_back(uv_of(k, c));
        if (normals) om.corner_normal.push_back(normal_of(c));
      }
      om.face_offsets.push_back(static_cast<Index>(om.corner_vertex.size()));
      out.face_source.push_back(f);
      if (tag_o) om.face_object.push_back(mesh_.face_object[f]);
      if (tag_g) om.face_group.push_back(mesh_.face_group[f]);
      if (tag_m) om.face_material.push_back(mesh_.face_material[f]);
      if (tag_s) om.face_smoothing.push_back(mesh_.face_smoothing[f]);
      if (len == 3) ++stats_.triangles_out;
      else if (len == 4) ++stats_.quads_out;
      else ++stats_.ngons_out;
      if (len == 3 && mesh_.face_size(f) == 4 && piece_count_[f] == 1) ++stats_.quads_to_triangles;
      stats_.tri_equivalent_out += tri_equivalent(len);
      off += len + 1;
    }
  }
  stats_.faces_in = nf_;
  stats_.faces_out = om.num_faces();

  out.edge_collapsed_final.assign(ne_, 0);
  for (Index e = 0; e < ne_; ++e) {
    const auto [a, b] = conn_.edge_vertices[e];
    if (root_[a] != root_[b] || a == b) continue;
    out.edge_collapsed_final[e] = 1;
    ++stats_.collapsed_edges_final;
    if (edge_kept[e] != 0) ++stats_.implied_collapsed_edges;
  }
  for (Index v = 0; v < nv_; ++v)
    if (root_[v] == v && cluster_size(v) > 1 && new_id[v] != kInvalidIndex) {
      ++stats_.clusters;
      stats_.clustered_vertices += cluster_size(v);
      stats_.largest_cluster = std::max(stats_.largest_cluster, cluster_size(v));
    }
  if (stats_.largest_cluster == 0 && next > 0) stats_.largest_cluster = 1;
}

// --- attributes per wedge (issue 7) ---------------------------------------------------------------
//
// A moved vertex gets new attribute values per *sector*: the input faces around its cluster
// (its star), joined across manifold edges whose two sides agree on the attribute. Each input
// corner at a member belongs to its face's sector, so corners of one wedge share one new value and
// a seam through the vertex keeps one value per side:
//
//        island A │ island B          sectors of the cluster {a, b} (a on the seam │):
//          ┌──────a──────┐            A-faces → UV of the projection into island A's faces,
//          │      ║      │            B-faces → UV of the projection into island B's faces;
//          └──────b──────┘            the vertex stays on the seam (place_on_feature), so both
//                                     projections land on the seam: no stretch across it.
//
// UVs: the closest point of the sector's input faces (fan triangles) to the new position, and the
// barycentric mix of that triangle's corner UVs (Hoppe 1999's "project into the same chart").
// Normals: the normalised sum of the area vectors of the output faces of the sector around the
// vertex — recomputed where smooth, and hard edges stay hard because they separate sectors.
void Collapser::project_attributes(PolyMesh& om, std::vector<std::vector<Index>>& uv_override,
                                   std::vector<Index>& normal_override) {
  const std::size_t sets = mesh_.uv_sets.size();
  const bool normals = mesh_.has_normals();
  if (sets == 0 && !normals) return;
  uv_override.assign(sets, std::vector<Index>(mesh_.num_corners(), kInvalidIndex));
  if (normals) normal_override.assign(mesh_.num_corners(), kInvalidIndex);

  // The corner of face(o) at vertex v, for a corner o whose edge has v as an endpoint.
  auto corner_at = [&](Index o, Index v) { return conn_.corner_vertex[o] == v ? o : conn_.corner_next[o]; };
  auto same_uv = [&](const UvSet& set, Index c, Index o) {
    const Index x = set.corner[c], y = set.corner[o];
    if (x == kInvalidIndex || y == kInvalidIndex) return x == y;
    return x == y || set.values[x] == set.values[y];
  };
  auto same_normal = [&](Index c, Index o) {
    const Index x = mesh_.corner_normal[c], y = mesh_.corner_normal[o];
    if (x == kInvalidIndex || y == kInvalidIndex) return x == y;
    return x == y || mesh_.normals[x] == mesh_.normals[y];
  };

  struct Nearest {
    double d2 = INFINITY;
    Index c0 = kInvalidIndex, c1 = kInvalidIndex, c2 = kInvalidIndex;  // input corners
    Vec3 w = Vec3::Zero();                                             // barycentric weights
  };
  std::vector<Index> star, star_slot(nf_, kInvalidIndex), sector(0);
  std::vector<Nearest> nearest;
  std::vector<Index> sector_value;
  std::vector<Vec3> sector_normal;
  for (Index r = 0; r < nv_; ++r) {
    if (root_[r] != r || cluster_size(r) < 2) continue;
    star.clear();
    for (Index m : members(r))
      for (Index c : conn_.corners_at_vertex(m)) {
        const Index f = conn_.corner_face[c];
        if (star_slot[f] != kInvalidIndex) continue;
        star_slot[f] = static_cast<Index>(star.size());
        star.push_back(f);
      }
    const Index ns = static_cast<Index>(star.size());
    const Vec3& x = pos_[r];

    // Closest point of each star face to the new position (independent of the attribute).
    nearest.assign(ns, Nearest{});
    for (Index i = 0; i < ns; ++i) {
      const Index f = star[i], b = mesh_.face_begin(f), k = mesh_.face_size(f);
      const Vec3& a = mesh_.positions[mesh_.corner_vertex[b]];
      for (Index j = 1; j + 1 < k; ++j) {
        const Vec3& p1 = mesh_.positions[mesh_.corner_vertex[b + j]];
        const Vec3& p2 = mesh_.positions[mesh_.corner_vertex[b + j + 1]];
        const TrianglePoint tp = closest_point_on_triangle(x, a, p1, p2);
        if (!(tp.distance_sq < nearest[i].d2)) continue;
        // Barycentric weights of the closest point (least squares; a sliver falls back to the
        // nearest corner).
        const Vec3 v0 = p1 - a, v1 = p2 - a, v2 = tp.point - a;
        const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
        const double d20 = v2.dot(v0), d21 = v2.dot(v1), den = d00 * d11 - d01 * d01;
        Vec3 w;
        if (den > 1e-12 * d00 * d11 && den > 0.0) {
          const double wv = (d11 * d20 - d01 * d21) / den, ww = (d00 * d21 - d01 * d20) / den;
          w = Vec3(1.0 - wv - ww, wv, ww);
        } else {
          const double da = v2.squaredNorm(), d1 = (tp.point - p1).squaredNorm(), d2 = (tp.point - p2).squaredNorm();
          w = da <= d1 && da <= d2 ? Vec3(1, 0, 0) : d1 <= d2 ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
        }
        nearest[i] = {tp.distance_sq, b, b + j, b + j + 1, w};
      }
    }
    // Does an output piece of star face i contain r? Only sectors with such a face need values.
    auto face_uses_root = [&](Index f) {
      Index off = piece_base(f);
      for (Index p = 0; p < piece_count_[f]; ++p) {
        const Index len = piece_buf_[off];
        for (Index i = 0; i < len; ++i)
          if (root_of_corner(piece_buf_[off + 1 + i]) == r) return true;
        off += len + 1;
      }
      return false;
    };

    // Sectors for one attribute, then one new value per used sector.
    auto label_sectors = [&](auto&& agree) {
      UnionFind uf(ns);
      for (Index i = 0; i < ns; ++i) {
        const Index f = star[i];
        for (Index c = mesh_.face_begin(f); c < mesh_.face_end(f); ++c) {
          const Index o = conn_.across(c);
          if (o == kInvalidIndex) continue;
          const Index j = star_slot[conn_.corner_face[o]];
          if (j == kInvalidIndex) continue;
          const Index a = conn_.corner_vertex[c], b = conn_.tip_vertex(c);
          if (agree(c, corner_at(o, a)) && agree(conn_.corner_next[c], corner_at(o, b))) uf.unite(i, j);
        }
      }
      sector.resize(ns);
      for (Index i = 0; i < ns; ++i) sector[i] = uf.find(i);
    };
    auto assign = [&](std::vector<Index>& override, auto&& value_for_sector) {
      sector_value.assign(ns, kInvalidIndex);
      for (Index i = 0; i < ns; ++i) {
        const Index s = sector[i];
        if (sector_value[s] == kInvalidIndex && face_uses_root(star[i])) sector_value[s] = value_for_sector(s);
      }
      for (Index m : members(r))
        for (Index c : conn_.corners_at_vertex(m)) override[c] = sector_value[sector[star_slot[conn_.corner_face[c]]]];
    };

    for (std::size_t k = 0; k < sets; ++k) {
      const UvSet& set = mesh_.uv_sets[k];
      label_sectors([&](Index c, Index o) { return same_uv(set, c, o); });
      assign(uv_override[k], [&](Index s) -> Index {
        const Nearest* best = nullptr;
        for (Index i = 0; i < ns; ++i) {
          if (sector[i] != s) continue;
          const Nearest& n = nearest[i];
          if (n.c0 == kInvalidIndex || set.corner[n.c0] == kInvalidIndex || set.corner[n.c1] == kInvalidIndex ||
              set.corner[n.c2] == kInvalidIndex)
            continue;
          if (!best || n.d2 < best->d2) best = &n;
        }
        if (!best) return kInvalidIndex;
        const Vec2 uv = best->w[0] * set.values[set.corner[best->c0]] + best->w[1] * set.values[set.corner[best->c1]] +
                        best->w[2] * set.values[set.corner[best->c2]];
        om.uv_sets[k].values.push_back(uv);
        ++stats_.uv_values_projected;
        return static_cast<Index>(om.uv_sets[k].values.size() - 1);
      });
    }
    if (normals) {
      label_sectors(same_normal);
      assign(normal_override, [&](Index s) -> Index {
        Vec3 sum = Vec3::Zero();
        for (Index i = 0; i < ns; ++i) {
          if (sector[i] != s) continue;
          Index off = piece_base(star[i]);
          for (Index p = 0; p < piece_count_[star[i]]; ++p) {
            const Index len = piece_buf_[off];
            const Index* cs = piece_buf_.data() + off + 1;
            off += len + 1;
            bool has_r = false;
            for (Index j = 0; j < len; ++j) has_r = has_r || root_of_corner(cs[j]) == r;
            if (has_r) sum += area_vector(len, [&](Index j) -> const Vec3& { return pos_[root_of_corner(cs[j])]; });
          }
        }
        const double n = sum.norm();
        if (!(n > 0.0) || !std::isfinite(n)) return kInvalidIndex;
        om.normals.push_back(sum / n);
        ++stats_.normals_recomputed;
        return static_cast<Index>(om.normals.size() - 1);
      });
    }
    for (Index f : star) star_slot[f] = kInvalidIndex;
  }
}

}  // namespace

SurfaceReference make_surface_reference(const PolyMesh& mesh) {
  SurfaceReference ref;
  TriangleSoup soup = fan_triangulate(mesh);
  ref.normal.resize(soup.triangles.size());
  for (std::size_t t = 0; t < soup.triangles.size(); ++t) {
    const auto& tri = soup.triangles[t];
    const Vec3 n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    const double len = n.norm();
    ref.normal[t] = len > 0.0 && std::isfinite(len) ? Vec3(n / len) : Vec3::Zero();
  }
  ref.bvh = TriangleBvh(soup.triangles);
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
      if (feat.is_strict(e) && (feat.edge_bits[e] & kKinds[k]))
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
