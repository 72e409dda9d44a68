// Mirror symmetry of a mesh about one of its three bbox-centred axis planes (issue 34,
// docs/symmetry.md): detection, the vertex → mirror vertex map, and the edge map built on it.
//
//        plane x = c (the bbox centre on x)
//              │
//     a ●──────┼──────● a'      a' = partner[a]: the vertex at reflect(a) within the tolerance
//       │      │      │         p  = partner[p]: a vertex within the tolerance of the plane is
//     b ●──────● p ───● b'           its own mirror ("on the plane")
//              │                e = (a, b) → (a', b'); (a, a') and (p, …) edges can be their own
//
// A vertex with no partner within the tolerance is *unmatched* (partner kInvalidIndex): the
// reduction decides around it without a mirror, so a few modelling slips (a vertex nudged on one
// side) do not turn symmetry off for the whole mesh.
#pragma once

#include "quadlod/mesh.h"

#include <cstdint>
#include <string>
#include <vector>

namespace quadlod {

struct Connectivity;

/// One of the three axis planes: axis 0, 1, 2 = x, y, z (the plane's normal); -1 = none.
struct MirrorPlane {
  int axis = -1;
  double centre = 0.0;  ///< the plane is {p : p[axis] = centre}
  bool valid() const { return axis >= 0 && axis < 3; }
  /// The mirror image of p (exact for centre 0: a negation).
  Vec3 reflect(const Vec3& p) const {
    Vec3 q = p;
    q[axis] = centre == 0.0 ? -p[axis] : 2.0 * centre - p[axis];
    return q;
  }
};

/// "x", "y", "z" or "none".
const char* axis_name(int axis);

/// Per vertex, its mirror vertex (itself on the plane; kInvalidIndex unmatched), with counts.
struct VertexMirror {
  MirrorPlane plane;
  std::vector<Index> partner;
  Index pairs = 0;      ///< vertices with a partner other than themselves (each pair counted twice)
  Index on_plane = 0;   ///< vertices that are their own mirror
  Index unmatched = 0;  ///< vertices with no partner
  /// (pairs + on_plane) / vertices; 1 for a mesh without vertices.
  double matched_fraction() const {
    const Index n = pairs + on_plane + unmatched;
    return n ? double(pairs + on_plane) / double(n) : 1.0;
  }
  bool empty() const { return partner.empty(); }
};

/// Pairs each vertex with the nearest vertex to its mirror image within `tolerance` (absolute
/// units), each vertex used once (vertices in id order; ties by the smaller id), so duplicate
/// positions pair with duplicates. A vertex within `tolerance` of the plane whose nearest free
/// candidate is itself is on the plane. Linear in the vertices (a hash grid of cell `tolerance`).
VertexMirror match_mirror_vertices(const std::vector<Vec3>& positions, const MirrorPlane& plane, double tolerance);

struct SymmetryDetectParams {
  /// A vertex's mirror partner must lie within this fraction of the bbox diagonal of its
  /// reflected position. 1e-4: the bar (eval's `symmetry` metric uses the same);
  /// meshes built by a mirror modifier are exact to float rounding (~1e-7), hand-placed
  /// "symmetric" vertices of artist meshes are often 1e-5 to 1e-4 off.
  double tolerance = 1e-4;
  /// A plane is a mirror plane when at least this fraction of the vertices is matched (paired or
  /// on the plane). The rest reduce without a mirror (see above).
  double min_matched_fraction = 0.99;
};

struct SymmetryDetection {
  VertexMirror mirror;        ///< of the chosen plane (empty when none)
  double best_fraction = 0.0; ///< matched fraction of the best plane tried (also when none passed)
  int best_axis = -1;         ///< that plane's axis
  double tolerance = 0.0;     ///< absolute (tolerance × diagonal)
  bool symmetric() const { return mirror.plane.valid(); }
};

/// Tries the bbox-centred planes of `axis` (0–2) or, with axis -1, of all three, and keeps the one
/// with the most matched vertices if it reaches min_matched_fraction (ties: fewer vertices on the
/// plane, then x, y, z). An axis along which the mesh is flat (extent within the tolerance) is
/// never a mirror plane: every vertex would be its own mirror.
SymmetryDetection detect_symmetry(const PolyMesh& mesh, int axis, const SymmetryDetectParams& params = {});

/// Per Connectivity edge: the edge between the partners of its endpoints (itself for an edge
/// that is its own mirror); kInvalidIndex when an endpoint is unmatched or the mirrored vertex
/// pair is no edge.
std::vector<Index> mirror_edges(const Connectivity& conn, const VertexMirror& mirror);

/// Makes a set of per-edge flags symmetric: flag[e] |= flag[mirror[e]] (the union).
void symmetrize_flags_union(std::vector<std::uint8_t>& flags, const std::vector<Index>& edge_mirror);

/// Writes exact mirror positions: for every pair (v, w = partner[v]) the one with the smaller id
/// keeps its position and the other gets its reflection; an on-plane vertex gets
/// p[axis] = centre exactly. Vertices flagged in `fixed` (protect weight 1, issue 34) never
/// move: a pair with one fixed member takes that one as the source, a pair of two fixed members
/// and a fixed on-plane vertex stay as they are. Returns the largest distance a vertex moved.
double symmetrize_positions(std::vector<Vec3>& positions, const VertexMirror& mirror,
                            const std::vector<std::uint8_t>* fixed = nullptr);

/// Fraction of the vertices of `positions` whose reflection about `plane` has a vertex within
/// `tolerance` (nearest-neighbour, partners may repeat): eval's `symmetry` metric.
double mirrored_vertex_fraction(const std::vector<Vec3>& positions, const MirrorPlane& plane, double tolerance);

}  // namespace quadlod
