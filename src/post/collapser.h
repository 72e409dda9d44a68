// Internal to src/post/: the class behind collapse_clusters() (cluster_collapse.h), the cluster
// collapse of the paper's §3.3.2. Nothing outside src/post/ includes this header. The methods
// are defined by concern:
//   cluster_collapse.cpp   setup (vertex quadrics, initial clusters), placement, splitting a
//                          refused cluster, rebuilding a face, the driver run(), and the public
//                          functions of cluster_collapse.h
//   collapse_checks.cpp    the guarantees: face checks (degenerate, flip, orientation, folded
//                          corner), vertex checks (non-manifold, boundary, duplicates, features),
//                          feature edges, the Hausdorff bound
//   collapse_islands.cpp   UV islands that neither vanish nor split
//   collapse_output.cpp    the output mesh (assemble) and the attributes per wedge
#pragma once

#include "geometry/cluster_quadric.h"
#include "geometry/quadric.h"
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "post/cluster_collapse.h"
#include "quadlod/mesh.h"

#include <cstdint>
#include <span>
#include <utility>
#include <array>
#include <vector>

namespace quadlod::collapse_detail {

// blame_reason_ / face_blame_ of a root / face no refusal blamed.
inline constexpr std::uint8_t kNoReason = 0xFF;

// Area vector (Newell, shifted to the first corner against cancellation far from the origin).
template <typename PositionOf>
Vec3 area_vector(Index k, PositionOf&& at) {
  const Vec3 o = at(0);
  Vec3 sum = Vec3::Zero();
  for (Index i = 1; i + 1 < k; ++i) sum += (at(i) - o).cross(at(i + 1) - o);
  return 0.5 * sum;
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
  void mark_crossing_side(Index r);
  std::vector<Index> snap_edges_;  // place_on_feature → place: the texture line around a cluster
  // Per root: placed by its quadric although on a texture line (placed_free_); to be placed on
  // the line (on_line_) after its line edges failed the tolerance, in the next round (replace_).
  std::vector<std::uint8_t> placed_free_, on_line_;
  std::vector<Index> replace_, replace_round_;
  bool place_on_line_again(Index r);
  std::vector<std::uint8_t> side_;  // mark_crossing_side: per vertex, 1 = may anchor the placement
  std::vector<Index> side_stack_;
  bool features_valid(Index r);
  bool protection_valid(Index r) const;  // issue 34: at most one protected member, no other strict corner
  std::span<const std::uint8_t> protected_;  // params_.protected_vertices, or empty
  bool edge_in_crossable_island(Index e) const;
  void check_feature_edges(Index v);
  std::vector<std::pair<Index, std::uint8_t>> line_edges_;  // check_feature_edges: {w, kinds}
  void split(Index r, CollapseRefusal why, bool dissolve);
  // --- symmetry (issue 34; docs/symmetry.md) ------------------------------------------------------
  // Mirror placements: the roots placed in this round (placed_now_) get the reflection of their
  // mirror cluster's position, or give theirs (see cluster_collapse.cpp); clusters overwritten
  // that were not placed this round have their faces appended to `dirty` (with dirty_token_).
  Index mirror_root(Index r) const;
  bool holds_protected(Index root) const;  // a member has protect weight 1 (issue 34)
  void mirror_placements(std::vector<Index>* dirty);
  std::vector<Index> placed_now_;
  std::vector<std::uint8_t> placed_on_feature_;

  // --- faces -----------------------------------------------------------------------------------
  Index piece_base(Index f) const { return 2 * mesh_.face_begin(f); }
  void rebuild_face(Index f);

  // --- checks ----------------------------------------------------------------------------------
  void check(const std::vector<Index>& dirty);
  // A refusal a face check found, replayed through blame() in the order of the dirty faces.
  struct FaceBlame {
    Index root;
    CollapseRefusal why;
  };
  void check_face(Index f, std::vector<FaceBlame>& found) const;
  void check_vertex(Index v);
  void check_hausdorff(Index v);
  template <class PositionOf>
  bool faces_input_surface(Index len, PositionOf&& at, const Vec3& av) const;
  void gather_fan(Index v);
  void gather_fan_indexed(Index v);
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
  VertexQuadrics own_quadrics_;
  const std::vector<VertexTerms>* terms_ = nullptr;  // params_.vertex_quadrics' or own_quadrics_'s
  std::vector<std::int8_t> input_nm_;  // input vertex non-manifold: 1 / 0, −1 not computed yet
  bool features_on_ = false;
  // UV islands (set 0) the collapse must neither cut in pieces nor, from
  // params_.min_kept_island_area up, remove whole (issue 7); empty when off.
  std::vector<Index> face_island_;  // per input face: its island, or kInvalidIndex
  std::vector<Index> island_begin_, island_faces_;  // faces of island i: [begin[i], begin[i+1])
  std::vector<std::uint8_t> island_keep_;   // 1: must keep a face (area >= min_kept_island_area)
  // 1: its lines may merge through it (area below crossing_island_area or min_kept_island_area)
  std::vector<std::uint8_t> island_crossable_;
  std::vector<Index> island_token_;
  Index island_tok_ = 0;
  std::vector<Index> root_component_, root_component_token_;  // per root, during check_islands
  std::vector<Index> pinch_roots_;  // check_islands: roots that pieces of two components share
  // Output sides that two or more pieces of the island being checked lie on, but that do not
  // join them because more than two output faces lie there (find_uv_islands joins faces only
  // across edges with exactly two): {a, b, piece} per piece on such a side.
  struct IslandSide {
    Index a, b, piece;
  };
  std::vector<IslandSide> unjoined_sides_;
  // Scratch of island_components: the sides, and their bucket sort by first root.
  std::vector<IslandSide> sides_, sides_sorted_;
  std::vector<Index> side_bucket_;
  Index fan_root_ = kInvalidIndex;  // root whose fan_ pieces_on_side gathered last
  Index component_tok_ = 0;
  void sort_sides();
  void protect_islands();
  // Parts (connected components) that must keep a face (max_vanishing_part_area): per face its
  // part, the faces of part i in [part_begin_[i], part_begin_[i + 1]), and whether it must.
  std::vector<Index> face_part_, part_begin_, part_faces_;
  std::vector<std::uint8_t> part_keep_;
  std::vector<Index> part_token_;
  Index part_tok_ = 0;
  void protect_parts();
  void check_parts(const std::vector<Index>& faces);
  std::vector<Index> all_faces_;
  const std::vector<Index>& all_faces_list();
  // skip_checked: leave out the islands the last call checked (nothing changed since).
  void check_islands(const std::vector<Index>& dirty, bool skip_checked = false);
  Index island_components(Index i, std::vector<Index>& piece_component);
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
  // Only for meshes with a face above kIndexedFanDegree corners (empty otherwise: no memory for
  // quad meshes): where each input corner sits in piece_buf_, the offset of its piece's len slot
  // and its place in the piece, or kInvalidIndex when the corner is in no piece (see
  // gather_fan_indexed).
  static constexpr Index kIndexedFanDegree = 32;
  std::vector<Index> corner_piece_, corner_piece_pos_;
  std::vector<std::array<Index, 3>> fan_keys_;  // gather_fan scratch: (face rank, piece offset, position)
  std::vector<Index> face_fan_rank_;
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

}  // namespace quadlod::collapse_detail
