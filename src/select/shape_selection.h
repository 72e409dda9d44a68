// Shape-first edge selection (issue "Shape first"; beyond the paper's Eq. 9): which input edges
// to collapse so that the reduced mesh has about N triangle-equivalents and the least geometric
// error — the error of the mesh the collapse will actually produce, not a proxy of it.
//
// Decision units are the paper's: the opposing edges of a poly-chord segment collapse together
// (§3.2.2, Eq. 4), so a collapse removes a strip of quads and keeps the quad layout. The cost of
// a selection is
//
//     cost = Σ_clusters E(cluster)                       (geometric error)
//          + λ_shape Σ_quads A_f h² (ln aspect_f − ln aspect_f⁰)²   (quad shape)
//
// where the clusters are the union-find components of the collapsed edges (§3.3.2), E is the
// cluster quadric (geometry/cluster_quadric.h: the very quadrics and placement of
// post/cluster_collapse, Knodt's per-edge planes included) at its placed vertex, and the shape
// term compares each surviving quad's aspect ratio (placed corners) with its input face's. The
// reported figures divide by (input area × bbox diagonal²): an area-weighted mean squared
// distance in units of the diagonal squared.
//
// The search is a lazy greedy in error per triangle-equivalent removed, with exact incremental
// deltas: a move merges the clusters its edges join, and its delta is the change of those
// clusters' errors (and of the shapes of the quads around them). Where every remaining segment
// costs far more per triangle-equivalent than a single edge collapse would, single collapses that
// make triangles (as Single, Knodt 2025, does) compete too, handicapped by
// triangle_collapse_factor and capped at max_triangle_share of the reduction.
//
// Deterministic: no clock, ties broken by id; the first pricing of every candidate runs on
// `threads` threads, each candidate priced alone, so the result does not depend on them. The paper's Eq. 9 selection stays in
// select_edges() (`--objective paper`).
#pragma once

#include "geometry/cluster_quadric.h"
#include "select/selection.h"
#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "topology/analysis.h"

#include <cstdint>
#include <vector>

namespace quadlod {

struct ShapeSelectionParams {
  /// ϵ_N of Eq. 2: the selection never goes below (1 − epsilon_n)·N. The paper's value.
  double epsilon_n = 0.03;
  /// Eq. 4 on/off: false decides every edge on its own (the "w/o consistency" ablation).
  bool consistency = true;
  /// Edges with more than two faces are never collapsed (the collapse would join sheets).
  bool keep_nonmanifold_edges = true;
  /// Edges that must be kept, one entry per Connectivity edge (nonzero = keep); empty = none.
  /// Pinning an edge keeps its whole segment (Eq. 4), but not against single collapses of the
  /// segment's other edges.
  std::vector<std::uint8_t> keep_edges;
  /// The placement the collapse will use (ClusterCollapseParams::placement): the cost is priced
  /// at the same positions.
  QuadricPlacementParams placement;
  /// build_vertex_quadrics(mesh, conn, placement) of the same mesh, borrowed; nullptr: built here.
  const VertexQuadrics* vertex_quadrics = nullptr;
  /// λ_shape: weight of the quad-shape term (see above); 0 = geometric error alone.
  double lambda_shape = 0.0;
  /// Moves that would flip a face beyond this angle against its input face, or leave a kept face
  /// with less than zero_area_epsilon × diagonal² of area, are not taken: the collapse would
  /// refuse them (ClusterCollapseParams::flip_angle_deg, zero_area_epsilon; the same values).
  bool check_faces = true;
  double flip_angle_deg = 90.0;
  double zero_area_epsilon = 1e-12;
  /// A single edge collapse (it makes triangles of the quads beside it) competes with segment
  /// collapses at this multiple of its error per triangle-equivalent; 0 disables them.
  double triangle_collapse_factor = 3.0;
  /// Exchange rounds after the greedy (undo one collapsed move, take a cheaper one instead; see
  /// select_by_shape) and how many of the cheapest moves left each undone move is tried against.
  /// 0 rounds = the greedy alone.
  int swap_rounds = 0;
  int swap_candidates = 24;
  /// An exchange may not make a cluster whose mean squared plane distance exceeds the largest of
  /// the clusters it undoes (so it cannot trade a lower sum for a larger worst case).
  bool swap_keeps_peak = true;
  /// A segment collapse that leaves t triangles at its ends while removing q quads' worth of
  /// triangle-equivalents (2q) competes at (1 + triangle_penalty · t / q) times its cost per
  /// triangle-equivalent; 0 = no handicap.
  double triangle_penalty = 0.0;
  /// At most this share of the reduction (input − N triangle-equivalents) comes from single
  /// collapses.
  double max_triangle_share = 0.4;
  /// Threads of the first pricing of all candidates (the greedy itself is sequential); 0 = all
  /// cores. Speed only: the selection is the same for any value.
  int threads = 0;
  /// Below this many candidates the first pricing runs on one thread: a thread's start and its
  /// scratch (arrays per vertex and per face) are not worth it on a small mesh, whose whole
  /// pricing takes milliseconds. Not tuned (speed only; the selection is the same either way).
  std::size_t min_parallel_candidates = 20000;
  /// Chunks of equal work (edges) per thread in the first pricing, taken by the threads as they
  /// finish. 8: one chunk is then an eighth of a thread's share; measured on the 1M grid (speed
  /// only, the selection is the same for any value).
  std::size_t pricing_chunks_per_thread = 8;

  // --- symmetry (issue 34; docs/symmetry.md) ---------------------------------------------------
  /// Per Connectivity edge, its mirror edge (mesh/symmetry.h: mirror_edges; itself on the plane,
  /// kInvalidIndex: none), borrowed; nullptr: no symmetry. Every move then collapses its edges and
  /// their mirror images together — a segment with its mirror segment, a single edge with its
  /// mirror edge — priced as one move, and a move whose mirror image holds a pinned edge is not
  /// taken. keep_edges should be symmetric (simplify() makes it so).
  const std::vector<Index>* edge_mirror = nullptr;
};

struct ShapeSelectionStats {
  double cost = 0.0;            ///< the selection's cost, normalised (see above)
  double greedy_cost = 0.0;     ///< the greedy's, before the exchanges
  double error = 0.0;           ///< its geometric part
  double shape = 0.0;           ///< its quad-shape part
  Index segment_collapses = 0;  ///< group (segment) collapses taken
  Index single_collapses = 0;   ///< single edge collapses taken
  std::uint64_t reduced_by_segments = 0;  ///< triangle-equivalents removed by segment collapses
  std::uint64_t reduced_by_singles = 0;   ///< … by single collapses
  std::int64_t evaluations = 0;           ///< move evaluations (the greedy's work)
  Index overshooting_moves = 0;           ///< moves dropped: they would leave Eq. 2's band below
  Index swaps_tried = 0, swaps_taken = 0;  ///< exchanges tried and taken
  Index invalid_moves = 0;                ///< moves dropped: a face around them would flip or vanish
};

struct ShapeSelectionResult {
  /// edge_kept, counts and note as select_edges() fills them (strategy "shape-greedy").
  SelectionResult selection;
  ShapeSelectionStats stats;
};

/// Selects the edges to collapse for a reduction to `target` triangle-equivalents by the shape
/// cost. `analysis` must come from analyze() on the same mesh and connectivity.
ShapeSelectionResult select_by_shape(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                     std::uint64_t target, const ShapeSelectionParams& params = {});

/// The shape cost (normalised, as ShapeSelectionStats::cost) of any selection, computed from
/// scratch: for tests and for comparing selections made by other objectives.
ShapeSelectionStats shape_cost(const PolyMesh& mesh, const Connectivity& conn,
                               const std::vector<std::uint8_t>& edge_kept, const ShapeSelectionParams& params = {});

}  // namespace quadlod
