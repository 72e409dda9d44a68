// Cluster collapse (paper §3.3.2, "QEM-based Simplification"): turns the solver's one bit per
// input edge (kept / collapsed) into the reduced mesh.
//
//   1. Vertices joined by collapsed edges form clusters (union-find). Each cluster becomes one
//      vertex, placed at the minimiser of the members' accumulated quadrics: area-weighted face
//      planes plus the per-edge planes and weights of Knodt 2025 (dihedral-angle weights, heavy
//      boundary / non-manifold edges), a small pull toward the cluster centroid (Trettner &
//      Kobbelt 2020 style regulariser) and, optionally, Lindstrom–Turk volume preservation.
//      docs/cluster_collapse.md says what was taken from Knodt's code and what is ours.
//   2. Every input face maps its corners through the clusters: runs of corners in one cluster
//      become one corner, faces with fewer than 3 distinct corners disappear, a face that meets a
//      cluster at two non-adjacent corners ("pinched") is cut there into simple loops. Quads that
//      keep four distinct corners stay quads: nothing is ever triangulated.
//   3. Guarantees, checked on the neighbourhood of every cluster: no new non-manifold edge or
//      vertex, no new boundary edge, no degenerate (zero-area or repeated-index) face, no new
//      duplicate face, no face flipped against the input face it comes from nor facing away from
//      the nearest input surface (the rule `quadlod eval` counts flipped faces by), no polygon
//      folded over at a corner that was convex, and (optional) a bounded one-sided Hausdorff
//      distance.
//      A cluster that breaks one is *refused*: it is split in two along its longest collapsed
//      edges (or dissolved entirely after `max_bisect_rounds`), its refused edges become kept,
//      and the check runs again on the faces that changed, until nothing is violated.
//      Every refusal is counted by reason together with the triangle-equivalents it kept.
//   4. Feature lines (issue 7, src/mesh/features.h; docs/attributes.md): a cluster that touches a
//      feature line is placed *on* it — at its feature corner if it has one (the best of its
//      corners on a per-face UV layout), else at the minimiser of its quadric along the feature
//      segments around it — and a cluster that would join two strict feature lines (boundaries,
//      UV seams, material borders) or two strict corners, or zip a boundary shut, is refused. The selection already avoids such clusters (feature_pinned_edges); this is the
//      guarantee behind it.
//   5. Attributes per wedge: the UVs of a moved vertex are re-projected into the chart each of its
//      corners came from (the input faces around the cluster joined across non-seam edges: one
//      "sector" per wedge), normals are recomputed from the output faces of each sector (hard
//      edges separate sectors, so they stay hard), vertex colours are averaged.
//
// Cost: linear in the mesh per round; rounds after the first only revisit the faces around
// refused clusters.
#pragma once

#include "geometry/bvh.h"
#include "geometry/cluster_quadric.h"
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "quadlod/mesh.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace quadlod {

/// The strict feature lines of the original input, one segment set per kind: boundary,
/// non-manifold, UV seam, material border. A multi-pass reduction measures feature_tolerance
/// against these in every pass, so the deviations of successive passes do not add up.
struct FeatureReference {
  std::array<SegmentBvh, 4> by_kind;
};
/// The strict edges of `mesh` (features from find_feature_edges on `conn`), and all its UV seams (those of
/// a per-face layout are not strict, but eval holds them to the input's too), sorted by kind.
FeatureReference make_feature_reference(const PolyMesh& mesh, const Connectivity& conn, const FeatureEdges& feat);

/// The original input surface, fan-triangulated as `quadlod eval` triangulates it, with each
/// triangle's unit normal: the reference of the orientation guarantee (docs/metrics.md §6b). A
/// multi-pass reduction checks every pass against the original input, so an output face is
/// never accepted facing away from the surface `eval` compares it with.
struct VertexMirror;  // mesh/symmetry.h

struct SurfaceReference {
  TriangleBvh bvh;
  std::vector<Vec3> normal;  ///< unit normal of each triangle of bvh (zero for zero area)
  double longest_side = 1.0;  ///< of the input's bounding box (eval's unit of length)
};
/// `threads` (0 = every core) changes only the speed.
SurfaceReference make_surface_reference(const PolyMesh& mesh, int threads = 1);

struct ClusterCollapseParams {
  // --- placement: the cluster quadric (geometry/cluster_quadric.h) -------------------------
  QuadricPlacementParams placement;
  /// build_vertex_quadrics(mesh, conn, placement) of the mesh being collapsed, borrowed (must
  /// outlive the call); nullptr: built here. simplify() builds them once per pass for the shape
  /// selection and every collapse round of that pass.
  const VertexQuadrics* vertex_quadrics = nullptr;
  /// Threads of the face checks of a round (each dirty face checked alone; the refusals are
  /// replayed in face order, so the output does not depend on the count) and of the attribute
  /// projection (clusters in chunks, their new values appended in chunk order) and of the
  /// per-face and per-edge set-up; 0 = all cores. A round with fewer than min_parallel_faces
  /// dirty faces (a mesh with fewer vertices, for the projection; fewer faces or edges, for the
  /// set-up) runs on one thread.
  int threads = 0;
  std::size_t min_parallel_faces = 20000;

  /// Clusters on hard edges (dihedral >= FeatureParams::hard_angle_deg, or smoothing groups) but
  /// on no other feature are placed on the hard line or at its corner (issue 7's rule) when true;
  /// when false they follow their quadric, whose edge planes weigh sharp edges like boundaries
  /// (QuadricPlacementParams::feature_edge_weight). false by measurement (issue 19,
  /// docs/shape_objective.md: on 12 corpus meshes at 0.4 the pinned placement cost
  /// 11 % more Chamfer than Single's against 4 % less without it). Hard edges still separate the
  /// normal sectors of the output either way.
  bool place_on_hard_edges = false;

  // --- guarantees -----------------------------------------------------------------------------
  /// An output face whose normal is more than this many degrees away from the normal of the
  /// input face it comes from is "flipped" (90 = any reversal of orientation). In (0, 180].
  double flip_angle_deg = 90.0;
  /// Also refuse an output face that faces away from the input *surface* near it — the rule
  /// `quadlod eval` counts `flipped_faces` by (docs/metrics.md §6b): the nearest input triangle
  /// whose normal agrees with the face's (dot >= 0) must lie within twice the distance of the
  /// nearest input triangle, plus orientation_tolerance × the input's longest bbox side, from
  /// the face centroid. The check above compares with the face's own input face only, which
  /// passes faces that slide over a fold onto a sheet facing the other way.
  bool check_surface_orientation = true;
  /// Half of EvalParams::flip_tolerance (1e-3), so an accepted face passes eval's count with a
  /// margin for the rounding of eval's normalised copy.
  double orientation_tolerance = 5e-4;
  /// Surface the orientation check uses (borrowed; must outlive the call). nullptr: the mesh
  /// being collapsed. simplify() passes the original input's in every pass.
  const SurfaceReference* surface_reference = nullptr;
  /// Also refuse when a corner of an output polygon (>= 4 corners) turns reflex while the input
  /// corner was convex: the polygon folds over (bow-tie quads; concave quads, which fold when
  /// split along the wrong diagonal). Reflex = the interior angle, measured against the input
  /// face's normal, exceeds 180° + corner_fold_tolerance_deg (so nearly straight corners pass).
  bool check_corner_folds = true;
  double corner_fold_tolerance_deg = 5.0;
  /// An output face whose area is at most this times the squared bbox diagonal is degenerate
  /// (100× the threshold of MeshStats, so outputs pass compute_stats()).
  double zero_area_epsilon = 1e-12;
  /// An output side at most this times the bbox diagonal long is degenerate, when its two input
  /// corners were farther apart: two clusters placed on one point (or a cluster on an unmoved
  /// neighbour). Default: the side of a square of zero_area_epsilon. makehuman_teeth_base at 0.2
  /// had up to 4 such edges per output, on and off feature lines, and one on a seam counted as
  /// torn (eval cannot place a zero-length edge on the input seam).
  double zero_length_epsilon = 1e-6;
  /// Bound on the one-sided distance, relative to the input bbox diagonal, from a placed cluster
  /// vertex and from the midpoints of its new edges to unmoved neighbours, to the input faces
  /// around the cluster. <= 0: no bound.
  double max_hausdorff = 0.0;

  // --- features and attributes (issue 7) -------------------------------------------------------
  /// Keep merged vertices on feature lines and refuse clusters that join two strict lines or two
  /// strict corners (point 4 above). false: the paper's plain quadric placement.
  bool respect_features = true;
  FeatureParams features;
  /// Re-project UVs and recompute normals of moved vertices per wedge (point 5 above). false:
  /// every surviving corner keeps its own input UV / normal index (UVs then stretch).
  bool project_attributes = true;
  /// An output edge continuing a strict feature line (boundary, UV seam, material border) may
  /// leave the input line by at most this fraction of its own length (sampled at ¼, ½, ¾): the
  /// tolerance `quadlod eval` uses for `seams_torn` (docs/metrics.md §6c). 0.2 forgives a chord
  /// over a turn of up to 43.6°, just under FeatureParams::corner_angle_deg.
  double feature_tolerance = 0.2;
  /// A cluster on a strict UV seam or material border (not a boundary, no corner among its
  /// members) is placed by its quadric, whose planes weigh those lines
  /// (QuadricPlacementParams::texture_line_edges), not on the input polyline; feature_tolerance
  /// holds the output line to the input one. A placement within this fraction of the mean length
  /// of the line's edges around the cluster goes onto the line: what is left there is the
  /// regulariser's pull, and on the line each side's UVs meet exactly. Not tuned: a flat seam
  /// column's leftover was 0.7 % of an edge.
  double texture_line_snap = 0.05;
  /// Lines feature_tolerance is measured against (borrowed; must outlive the call). nullptr: the
  /// strict lines of the mesh being collapsed.
  const FeatureReference* feature_reference = nullptr;
  /// The features of the mesh being collapsed, when the caller has them already (borrowed; must
  /// match `features` and `conn`). nullptr: computed here.
  const FeatureEdges* feature_edges = nullptr;
  /// With respect_features: a UV island (set 0) never falls apart into two pieces and, with at
  /// least this 3D area, never loses its last face — the clusters that would do so are refused
  /// (`island`). simplify() passes
  /// the area of one output face (input area / target tri-equivalents), so only islands too small
  /// for one output face may vanish (issue 7). < 0: islands are not checked at all. Per-face layouts
  /// (FeatureParams::per_face_layout_fraction) are never protected.
  double min_kept_island_area = 0.0;
  /// The lines around a UV island (set 0) whose area is below this may merge through it: its
  /// strict vertices may join a cluster through its interior edges, and the island may vanish
  /// even above min_kept_island_area (issue 32, docs/attributes.md). simplify() keeps it 0 until
  /// a pass stalls on the lines (`--seams auto`; always with `--seams strict`), then sets it to one
  /// output face and raises it ×4 per further stall. Every output line still stays within
  /// feature_tolerance of an input line.
  double crossing_island_area = 0.0;
  /// With respect_features: a part (a connected component: faces joined through shared
  /// vertices) whose area is at least this keeps a face, and a loop of open boundary never
  /// collapses to a point (a hole closed, or a part's outline gone) unless this is positive.
  /// 0 (default): no part vanishes and no hole closes; a part too small for one output face still
  /// loses as much as the other rules allow. simplify() raises it with crossing_island_area when a
  /// pass stalls (SeamPolicy::Auto): a part vanishing costs Hausdorff its whole extent
  /// (flightgear_cessna337 at 0.4: a 120-face part 0.017 long, 12× the Hausdorff of the rest).
  double max_vanishing_part_area = 0.0;
  /// Per face of the mesh being collapsed: the 3D area of the island it comes from in the
  /// original input (borrowed; nullptr: the island's own area here). A multi-pass reduction
  /// shrinks islands (a curved part loses area as it is simplified), so an island worth two
  /// output faces in the input could fall below the bound in a late pass and vanish there.
  const std::vector<double>* face_island_area = nullptr;

  // --- protected regions (issue 34; docs/protect.md) -----------------------------------------
  /// Per vertex of the mesh being collapsed (borrowed; nullptr or empty: none): 1 = protected
  /// (weight 1). A cluster with one protected member lands exactly on it (a half-edge collapse:
  /// the protected vertex absorbs its unprotected neighbours); a cluster with two, or with one and
  /// a strict feature corner elsewhere, is refused (`protected`), so an edge between two protected
  /// vertices never collapses and no protected vertex moves.
  const std::vector<std::uint8_t>* protected_vertices = nullptr;

  // --- refinement -----------------------------------------------------------------------------
  /// Refused clusters are bisected (longest collapsed edges cut first) during this many rounds;
  /// from then on a refused cluster is dissolved entirely. 0: always dissolve.
  Index max_bisect_rounds = 8;

  // --- symmetry (issue 34; docs/symmetry.md) ---------------------------------------------------
  /// The mirror map of the mesh being collapsed (borrowed; nullptr: no symmetry). A cluster whose
  /// mirror image is a cluster (every member's partner in one cluster of the same size) is placed
  /// as the reflection of that cluster's placement, and a cluster that is its own mirror is placed
  /// exactly on the plane; which side's placement is reflected: the one placed in the later round
  /// (a re-placement wins), else the one placed on a feature line, else the smaller root. Refusals
  /// are not mirrored here: simplify() intersects the collapsed edges with their mirrors and runs
  /// the collapse again until they are symmetric.
  const VertexMirror* mirror = nullptr;
};

/// Why a cluster was refused, in priority order (a cluster with several problems is counted
/// once, under the first).
enum class CollapseRefusal : std::uint8_t {
  NonManifoldEdge,    ///< an output edge with > 2 faces whose input edges all had <= 2
  NonManifoldVertex,  ///< an output vertex whose fan splits, no member was non-manifold
  NewBoundary,        ///< an output edge with 1 face whose input edges all had >= 2
  DuplicateFace,      ///< two output faces on the same vertex set (not input duplicates)
  DegenerateFace,     ///< an output face with zero area, or a side the collapse shrank to zero length
  Flip,               ///< an output face turned more than flip_angle_deg from its input face
  FoldedCorner,       ///< a convex polygon corner became reflex
  Orientation,        ///< an output face faces away from the nearest input surface (§6b rule)
  Hausdorff,          ///< the placed vertex left the max_hausdorff band around the input
  Feature,            ///< the cluster joins two strict feature lines or two strict corners, or
                      ///< an output edge leaves the strict line it continues (feature_tolerance),
                      ///< or an output edge with two faces covers an input boundary edge (a
                      ///< boundary zipped shut)
  Island,             ///< a UV island would fall apart into two pieces, or, with at least
                      ///< min_kept_island_area, lose its last face
  Part,               ///< a part (connected component) of at least max_vanishing_part_area
                      ///< would lose its last face
  Protected,          ///< issue 34: the cluster holds two protected vertices (weight 1), or one
                      ///< and a strict feature corner, which would have to move
};
inline constexpr std::size_t kNumCollapseRefusals = 13;
const char* to_string(CollapseRefusal reason);

enum class ClusterCollapseStatus : std::uint8_t {
  Ok,
  InvalidInput,  ///< connectivity or edge_kept does not match the mesh (see `error`)
};

struct ClusterCollapseStats {
  Index collapsed_edges_in = 0;     ///< edges the selection marked collapsed
  Index collapsed_edges_final = 0;  ///< edges whose endpoints ended in one output vertex
  Index implied_collapsed_edges = 0;  ///< of those, edges the selection marked kept
  Index clusters = 0;               ///< output vertices made of > 1 input vertex
  Index clustered_vertices = 0;     ///< input vertices in those clusters
  Index largest_cluster = 0;        ///< most input vertices in one output vertex
  Index faces_in = 0;
  Index faces_out = 0;
  Index quads_out = 0;
  Index triangles_out = 0;
  Index ngons_out = 0;
  std::uint64_t tri_equivalent_in = 0;
  std::uint64_t tri_equivalent_out = 0;
  /// What the selection asked for: tri-equivalents after applying every collapse unchecked.
  std::uint64_t tri_equivalent_wanted = 0;
  Index faces_dropped = 0;         ///< input faces left with < 3 distinct corners (removed)
  Index faces_pinched = 0;         ///< input faces cut at a repeated vertex into simple loops
  Index quads_to_triangles = 0;    ///< input quads that became one triangle
  Index vertices_removed_unused = 0;  ///< input vertices no output face uses (besides merging)
  // Placement.
  Index placements_volume_constrained = 0;  ///< clusters placed under the volume constraint
  Index placements_pseudo_inverse = 0;      ///< ill-conditioned systems solved by eigen cutoff
  Index placements_fallback = 0;            ///< minimiser untrusted: best of centroid/members
  Index placements_at_feature_corner = 0;   ///< clusters placed at a feature corner: their one, or
                                            ///< the best of several per-face-layout seam corners
  Index placements_on_feature_line = 0;     ///< clusters placed on the feature segments around them
  Index placements_at_protected = 0;        ///< clusters placed on their protected member (issue 34)
  /// Output vertices that merge strict lines through an island they may cross (issue 32:
  /// crossing_island_area): clusters whose strict members are not all joined by collapsed
  /// strict edges. Each is one crossing of a line.
  Index line_crossings = 0;
  // Attributes.
  Index uv_values_projected = 0;    ///< new UV values (wedges of moved vertices, all sets)
  Index normals_recomputed = 0;     ///< new normal values (wedges of moved vertices), projected or recomputed
  // Refinement.
  Index rounds = 0;                ///< check rounds run (1 when nothing was refused)
  Index clusters_bisected = 0;
  Index clusters_dissolved = 0;
  Index edges_restored = 0;        ///< collapsed edges turned back to kept by refusals
  /// Refusals by reason (each split or dissolve of one cluster counts once).
  std::array<Index, kNumCollapseRefusals> refused{};
  /// Tri-equivalents those refusals kept that the selection wanted removed (sums to
  /// tri_equivalent_out - tri_equivalent_wanted).
  std::array<std::int64_t, kNumCollapseRefusals> refused_tri_equivalents{};

  Index refusals(CollapseRefusal r) const { return refused[static_cast<std::size_t>(r)]; }
  Index total_refusals() const;
};

struct ClusterCollapseResult {
  ClusterCollapseStatus status = ClusterCollapseStatus::Ok;
  std::string error;  ///< why the input was rejected (status InvalidInput)
  /// The reduced mesh: positions of untouched vertices unchanged, uv/normal pools and name
  /// tables copied whole (new values for moved wedges appended), each surviving corner of an
  /// unmoved vertex keeps its own uv/normal index, faces keep their tags and the order of the
  /// input faces they come from. Vertex ids are compacted in the order
  /// of the smallest input vertex of each output vertex.
  PolyMesh mesh;
  /// Input vertex → output vertex, or kInvalidIndex for input vertices no output face uses.
  std::vector<Index> vertex_map;
  /// One per input (Connectivity) edge: 1 when its endpoints ended in the same output vertex
  /// (collapsed), 0 when the edge survives. Note the inversion w.r.t. the `edge_kept` input.
  std::vector<std::uint8_t> edge_collapsed_final;
  /// Output face → the input face it comes from (a pinched input face gives several output
  /// faces, a dropped one none). The provenance behind simplify's exact UV island accounting.
  std::vector<Index> face_source;
  ClusterCollapseStats stats;
  double seconds = 0.0;
};

/// Collapses the clusters of `edge_kept` (one entry per `conn` edge: nonzero = kept,
/// 0 = collapsed) and returns the reduced mesh with the guarantees listed at the top of this file.
/// Preconditions: `conn` was built from `mesh`. A size mismatch gives status InvalidInput and a
/// copy of the input mesh (identity vertex_map, nothing collapsed).
/// Faces the collapse does not touch are passed through; degenerate input faces are not repaired
/// (only repeated corners are normalised: runs merged, pinched faces cut into loops).
ClusterCollapseResult collapse_clusters(const PolyMesh& mesh, const Connectivity& conn,
                                        const std::vector<std::uint8_t>& edge_kept,
                                        const ClusterCollapseParams& params = {});

/// The stats as a JSON object (for `--report`).
nlohmann::json to_json(const ClusterCollapseStats& stats);

}  // namespace quadlod
