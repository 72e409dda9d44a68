// Poly-chords (paper §3.1; Daniels et al. 2008): maximal chains of quads linked through opposite
// edges. In the dual, a chord is the polyline through the quads' centroids; in the primal, the
// edges it crosses are its *opposing edges* and the edges along its two sides are *loopy edges*
// (they form the edge loops of Fig. 3).
//
//      loopy side 1:   o────────o────────o────────o
//                      │        │        │        │
//      opposing edges: e0  q0   e1  q1   e2  q2   e3      (open chord: m quads, m+1 edges)
//                      │        │        │        │
//      loopy side 0:   o────────o────────o────────o
//
// A chord is *open* when it ends at both ends on an edge that is not shared with another quad
// across a manifold edge (boundary, triangle, n-gon, non-manifold edge); *closed* when it returns
// to its first edge (m quads, m opposing edges). It *crosses itself* when it passes through one
// quad twice, once through each pair of that quad's opposite edges.
//
// Every quad has two "directions" (its two pairs of opposite edges); every direction lies on
// exactly one chord. Hence every quad corner belongs to exactly one chord (`corner_chord`), and
// every edge of a quad is an opposing edge of exactly one chord — except a non-manifold edge
// (more than two faces), at which every incident quad's chord ends: such an edge is an opposing
// edge (the end edge) of one chord per incident quad corner. `edge_chord` then names the chord of
// the lowest incident quad corner and `num_shared_end_edges` counts these edges.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace quadlod {

/// Why an open chord stops at one of its ends (the face across the end edge, seen from the
/// last quad). A closed chord has no ends (`None`).
enum class ChordEnd : std::uint8_t {
  None,         ///< closed chord
  Boundary,     ///< the end edge has one face
  Triangle,     ///< the end edge is shared with a triangle
  Polygon,      ///< the end edge is shared with an n-gon (n > 4)
  NonManifold,  ///< the end edge has more than two faces
};

struct PolyChord {
  /// Quads in walking order; a self-crossing chord lists a quad twice.
  std::vector<Index> quads;
  /// Edges crossed, in order: opposing_edges[i] and opposing_edges[i+1] are the two opposite
  /// sides of quads[i] (indices modulo the size for a closed chord).
  /// Open chord: quads.size() + 1 entries. Closed chord: quads.size() entries.
  std::vector<Index> opposing_edges;
  /// The two loopy edges of each quad step: loopy_edges[i] = {side 0, side 1} of quads[i], the
  /// quad's edges that join opposing_edges[i] to opposing_edges[i+1]. Sides are consistent along
  /// the chord (side 0 is always on the same side of the walking direction), also across
  /// inconsistently oriented neighbours. On a non-orientable closed chord (a Möbius band) the
  /// sides swap where the walk closes.
  std::vector<std::array<Index, 2>> loopy_edges;
  /// The corner of quads[i] whose edge is opposing_edges[i] (the corner the walk enters through).
  std::vector<Index> entry_corners;
  bool closed = false;
  bool self_crossing = false;
  /// Why the walk stops before opposing_edges.front() / after opposing_edges.back() (open chords).
  std::array<ChordEnd, 2> ends{ChordEnd::None, ChordEnd::None};

  Index size() const { return static_cast<Index>(quads.size()); }
};

struct PolyChordParams {
  // No parameters yet: extraction is purely topological. Kept for the one-stage-one-Params rule.
};

struct PolyChordStats {
  Index num_open = 0;
  Index num_closed = 0;
  Index num_self_crossing = 0;  ///< chords that pass through some quad twice
  Index longest = 0;            ///< most quads in one chord
  /// Open chord ends by kind (two per open chord).
  Index ends_at_boundary = 0;
  Index ends_at_triangle = 0;
  Index ends_at_polygon = 0;
  Index ends_at_nonmanifold = 0;
  Index num_quad_edges = 0;        ///< edges with at least one quad corner
  Index num_shared_end_edges = 0;  ///< non-manifold edges that are an opposing edge of > 1 chord entry
};

struct PolyChordResult {
  std::vector<PolyChord> chords;
  /// For every edge: the chord for which it is an opposing edge, or kInvalidIndex when the edge
  /// touches no quad. Invariant: every edge of a quad is an opposing edge of exactly one chord
  /// (non-manifold edges: see the file comment).
  std::vector<Index> edge_chord;
  /// For every corner: the chord that crosses the corner's edge through the corner's face, or
  /// kInvalidIndex when the face is not a quad. The two directions of quad f are the chords of
  /// its corners 0 and 1 (corners 2 and 3 repeat them).
  std::vector<Index> corner_chord;
  Index num_closed = 0;
  Index num_self_crossing = 0;
  PolyChordStats stats;
};

/// Extracts all poly-chords in time linear in the number of corners. Deterministic: chords are
/// numbered in the order of their lowest (face, corner) visit; an open chord starts at the end
/// reached by walking backwards from that corner, a closed chord starts at that corner.
/// Faces of any degree are accepted; only quads (4 corners) carry chords.
PolyChordResult extract_polychords(const PolyMesh& mesh, const Connectivity& conn,
                                   const PolyChordParams& params = {});

/// The medial curve of a chord (§3.2.3, Fig. 6; also PCCD §4.1): the midpoints of its opposing
/// edges in order (for a closed chord the first point is not repeated; callers close the curve).
std::vector<Vec3> medial_curve(const PolyMesh& mesh, const Connectivity& conn, const PolyChord& chord);

/// Unit normals of the chord's quads (zero for a zero-area quad), signs made consistent along the
/// walk: where the chord crosses an inconsistently oriented edge (both corners of the edge start
/// at the same vertex) every following normal is negated, so neighbouring normals can be
/// compared (§3.2.2 dihedral and bi-normal criteria, §3.2.3 cluster normals). For a closed chord,
/// `wrap_flip` (optional) receives whether the step quads[m-1] → quads[0] flips orientation (a
/// non-orientable band); the normals themselves are relative to quads[0].
std::vector<Vec3> chord_quad_normals(const PolyMesh& mesh, const Connectivity& conn,
                                     const PolyChord& chord, bool* wrap_flip = nullptr);

const char* to_string(ChordEnd end);

}  // namespace quadlod
