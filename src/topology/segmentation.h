// Poly-chord segmentation (paper §3.2.2, Fig. 5, Eq. 4).
//
// A chord P = {e_0, …, e_m} (its opposing edges) is cut at *breakpoints*: opposing edges where
//   * Dihedral:          the angle between the normals of the two chord quads on either side of
//                        e_i exceeds epsilon_theta;
//   * Bi-normal:         the bi-normal b = normalize(n_f × d) changes by more than epsilon_theta
//                        between those two quads (d = the chord's direction in the quad, see
//                        below);
//   * SelfIntersection:  an endpoint of e_i is an endpoint of an earlier opposing edge of P.
// The segments are the maximal runs between breakpoints. Eq. 4 then requires x_e = x_e' for all
// opposing edges e, e' of one segment (the ILP reads `Segment::opposing_edges`).
//
// Which side a breakpoint edge belongs to: a breakpoint edge STARTS a new segment.
//
//        segment s                          segment s+1
//   e_{i-2}   e_{i-1}  ┃ e_i   e_{i+1}          e_i is the breakpoint edge (crease, bi-normal
//     │   q   │   q    ┃  │  q  │                jump or self-contact); it is the first edge
//     │       │        ┃  │     │                of segment s+1.
//
// Why this side: with the self-intersection criterion on, it makes the opposing edges of every
// segment pairwise vertex-disjoint (each non-first edge of a segment touches no earlier edge of
// the chord, and the first edge is earlier than all others of its segment). Collapsing a segment
// (all x_e = 0) therefore merges disjoint vertex pairs, never a chain of three vertices, which is
// exactly the over-collapse at self-intersections that Fig. 4 warns about. tests check the
// property on the corpus. The geometric criteria are symmetric in e_i, so they follow the same
// rule for uniformity.
//
// Closed chords: the segment that contains the chord's first position may wrap around
// (first > last). When a closed chord has a self-intersection breakpoint, its position 0 is made
// a breakpoint too (reason ClosedStart): otherwise the wrapping segment would join the chord's
// tail to its head and could contain two edges sharing a vertex.
//
// Non-manifold edges may be the end edge of several chords (see polychords.h) and then belong to
// one segment per such chord; `edge_segment` names the one on `edge_chord[e]`, and Eq. 4 over
// all segments links them through the shared x_e.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "topology/polychords.h"

#include <cstdint>
#include <numbers>
#include <vector>

namespace quadlod {

struct SegmentationParams {
  /// ϵ_θ of §3.2.2, radians: the dihedral and bi-normal thresholds ("typically π/3").
  double epsilon_theta = std::numbers::pi / 3.0;
  /// false: one segment per chord (the paper's "w/o segmentation" ablation).
  bool enable = true;
  /// Individual criteria, for ablations and tests.
  bool use_dihedral = true;
  bool use_binormal = true;
  bool use_self_intersection = true;
  /// Threads for the chords' geometric tests (0 = every core); the segments do not depend on
  /// them. A mesh with fewer than min_parallel_edges edges is segmented on one thread.
  int threads = 1;
  std::size_t min_parallel_edges = 20000;
};

/// Breakpoint reasons, a bit set (one edge may have several).
enum BreakpointReason : std::uint8_t {
  kBreakDihedral = 1,
  kBreakBinormal = 2,
  kBreakSelfIntersection = 4,
  kBreakClosedStart = 8,  ///< position 0 of a self-touching closed chord (see file comment)
};

struct Breakpoint {
  Index chord = kInvalidIndex;
  Index position = kInvalidIndex;  ///< index into the chord's opposing_edges
  Index edge = kInvalidIndex;
  std::uint8_t reasons = 0;        ///< BreakpointReason bits
};

struct Segment {
  Index chord = kInvalidIndex;
  /// Range of opposing-edge positions in the chord, inclusive. For a closed chord the range may
  /// wrap (first > last means first..m-1 then 0..last); a closed chord without breakpoints is
  /// one segment 0..m-1.
  Index first = 0;
  Index last = 0;
  /// The opposing edges in walking order (what Eq. 4 ties together).
  std::vector<Index> opposing_edges;
};

struct SegmentationStats {
  Index num_breakpoints = 0;             ///< edges with at least one reason
  Index num_dihedral = 0;                ///< per reason (an edge may count for several)
  Index num_binormal = 0;
  Index num_self_intersection = 0;
  Index num_closed_start = 0;
  Index num_degenerate_skipped = 0;      ///< geometric tests skipped: zero normal or zero direction
  Index num_single_edge_segments = 0;
  Index longest_segment = 0;             ///< most opposing edges in one segment
};

struct SegmentationResult {
  std::vector<Segment> segments;
  /// Segments of chord c are [chord_segment_begin[c], chord_segment_begin[c+1]), in walking order.
  std::vector<Index> chord_segment_begin;
  /// For every mesh edge: the segment (on chord edge_chord[e]) containing it as an opposing edge,
  /// or kInvalidIndex for edges of no quad.
  std::vector<Index> edge_segment;
  std::vector<Breakpoint> breakpoints;  ///< in chord order, then position order
  SegmentationStats stats;
};

/// Cuts every chord of `chords` (from extract_polychords on the same mesh/connectivity) at its
/// breakpoints. Linear in the total chord length. Angles use unit face normals (Newell), made
/// sign-consistent along the chord (chord_quad_normals); the chord direction d in quad i is the
/// medial edge from the midpoint of e_i to the midpoint of e_{i+1}.
SegmentationResult segment_polychords(const PolyMesh& mesh, const Connectivity& conn,
                                      const PolyChordResult& chords,
                                      const SegmentationParams& params = {});

}  // namespace quadlod
