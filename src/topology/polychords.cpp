// Poly-chord extraction (paper §3.1, Fig. 3; Daniels et al. 2008, "Quadrilateral mesh
// simplification").
//
// The walk works on corners. A quad has two *directions*, {c0, c2} and {c1, c3}; entering the
// quad through corner c's edge, the walk leaves through the opposite corner's edge and steps to
// the corner across that edge:
//
//            side 1 = edge(p)
//         p ◄────────────── c          ──►  walking direction
//         │                 ▲
//   exit  │   quad q        │  entry          entry corner c, its edge = opposing edge e_i
//  edge(o)│                 │ edge(c)         exit  corner o = next(next(c)), edge(o) = e_{i+1}
//         ▼                 │                 loopy edges: edge(n) and edge(p)
//         o ──────────────► n
//            side 0 = edge(n)
//
//   next entry = across(o), when edge(o) is a manifold edge whose other face is a quad;
//   otherwise the chord ends at edge(o) (boundary / triangle / n-gon / non-manifold edge).
//
// Each direction is a node with two ports (its two corners) and `across` pairs ports one to one,
// so directions form disjoint paths and cycles: walking backwards from any unvisited corner
// either reaches an end (open chord) or returns to the start (closed chord); walking forwards
// from there visits every direction of the chord once. Each corner is visited a constant number
// of times: linear time.
//
// Side bookkeeping: `side` says whether side 0 is edge(next(entry)) (side == 0) or
// edge(prev(entry)) (side == 1). Across a consistently oriented edge the neighbour traverses the
// shared edge the other way and the parity is kept; across an inconsistently oriented edge
// (both corners start at the same vertex) it flips.
#include "topology/polychords.h"

namespace quadlod {

namespace {

// Next entry corner after leaving a quad through corner `exit`, or kInvalidIndex at a chord end.
Index step_across(const Connectivity& conn, Index exit) {
  const Index a = conn.across(exit);
  if (a == kInvalidIndex || !conn.is_quad(conn.corner_face[a])) return kInvalidIndex;
  return a;
}

ChordEnd classify_end(const Connectivity& conn, Index corner) {
  const Index e = conn.corner_edge[corner];
  const Index count = conn.edge_face_count(e);
  if (count == 1) return ChordEnd::Boundary;
  if (count > 2) return ChordEnd::NonManifold;
  const Index degree = conn.face_degree[conn.corner_face[conn.across(corner)]];
  // A quad across a manifold edge never ends a chord; degree 4 here would mean the walk was cut
  // defensively (see below), which the tests show never happens.
  return degree == 3 ? ChordEnd::Triangle : ChordEnd::Polygon;
}

void count_end(PolyChordStats& stats, ChordEnd end) {
  switch (end) {
    case ChordEnd::Boundary: ++stats.ends_at_boundary; break;
    case ChordEnd::Triangle: ++stats.ends_at_triangle; break;
    case ChordEnd::Polygon: ++stats.ends_at_polygon; break;
    case ChordEnd::NonManifold: ++stats.ends_at_nonmanifold; break;
    case ChordEnd::None: break;
  }
}

}  // namespace

const char* to_string(ChordEnd end) {
  switch (end) {
    case ChordEnd::None: return "none";
    case ChordEnd::Boundary: return "boundary";
    case ChordEnd::Triangle: return "triangle";
    case ChordEnd::Polygon: return "polygon";
    case ChordEnd::NonManifold: return "non-manifold";
  }
  return "?";
}

PolyChordResult extract_polychords(const PolyMesh& mesh, const Connectivity& conn,
                                   const PolyChordParams&) {
  PolyChordResult out;
  const Index nc = static_cast<Index>(conn.corner_vertex.size());
  out.corner_chord.assign(nc, kInvalidIndex);
  out.edge_chord.assign(conn.num_edges, kInvalidIndex);
  std::vector<Index>& corner_chord = out.corner_chord;

  for (Index f = 0; f < conn.num_faces; ++f) {
    if (!conn.is_quad(f)) continue;
    for (Index k = 0; k < 2; ++k) {
      const Index c = mesh.face_begin(f) + k;
      if (corner_chord[c] != kInvalidIndex) continue;

      // 1. Walk backwards to the chord's start (or all the way round).
      Index start = c;
      bool closed = false;
      for (Index guard = 0; guard <= nc; ++guard) {
        const Index a = step_across(conn, start);  // exit corner of the previous quad
        if (a == kInvalidIndex) break;
        const Index prev_entry = conn.opposite_corner_in_quad(a);
        if (prev_entry == c) {
          closed = true;
          start = c;
          break;
        }
        // Unreachable by the port argument above; kept so corrupt input cannot loop forever.
        if (corner_chord[prev_entry] != kInvalidIndex) break;
        start = prev_entry;
      }

      // 2. Walk forwards, recording quads, opposing and loopy edges.
      const Index id = static_cast<Index>(out.chords.size());
      PolyChord chord;
      chord.closed = closed;
      if (!closed) chord.ends[0] = classify_end(conn, start);
      Index entry = start;
      Index side = 0;
      for (;;) {
        const Index exit = conn.opposite_corner_in_quad(entry);
        corner_chord[entry] = id;
        corner_chord[exit] = id;
        const Index n = conn.corner_next[entry], p = conn.corner_prev[entry];
        chord.quads.push_back(conn.corner_face[entry]);
        chord.entry_corners.push_back(entry);
        chord.opposing_edges.push_back(conn.corner_edge[entry]);
        chord.loopy_edges.push_back(side == 0
                                        ? std::array<Index, 2>{conn.corner_edge[n], conn.corner_edge[p]}
                                        : std::array<Index, 2>{conn.corner_edge[p], conn.corner_edge[n]});
        const Index next = step_across(conn, exit);
        if (closed && next == start) break;
        if (next == kInvalidIndex || corner_chord[next] != kInvalidIndex) {
          // Open end (the second condition is the defensive cut of step 1's guard).
          chord.opposing_edges.push_back(conn.corner_edge[exit]);
          chord.ends[1] = classify_end(conn, exit);
          break;
        }
        if (conn.corner_vertex[next] == conn.corner_vertex[exit]) side ^= 1;
        entry = next;
      }

      PolyChordStats& s = out.stats;
      if (closed) {
        ++s.num_closed;
      } else {
        ++s.num_open;
        count_end(s, chord.ends[0]);
        count_end(s, chord.ends[1]);
      }
      s.longest = std::max(s.longest, chord.size());
      out.chords.push_back(std::move(chord));
    }
  }

  // A chord crosses itself where both directions of one quad lie on it.
  for (Index f = 0; f < conn.num_faces; ++f) {
    if (!conn.is_quad(f)) continue;
    const Index c0 = mesh.face_begin(f);
    if (corner_chord[c0] == corner_chord[c0 + 1]) out.chords[corner_chord[c0]].self_crossing = true;
  }
  for (const PolyChord& chord : out.chords) out.stats.num_self_crossing += chord.self_crossing;

  // edge_chord: the chord of the lowest quad corner on the edge. On a manifold edge every quad
  // corner of the edge is on the same chord; a non-manifold edge may end several chords.
  for (Index c = 0; c < nc; ++c) {
    if (corner_chord[c] == kInvalidIndex) continue;
    Index& slot = out.edge_chord[conn.corner_edge[c]];
    if (slot == kInvalidIndex) {
      slot = corner_chord[c];
      ++out.stats.num_quad_edges;
    }
  }
  for (Index e = 0; e < conn.num_edges; ++e) {
    if (!conn.is_nonmanifold_edge(e)) continue;
    Index quad_corners = 0;
    for (Index c : conn.corners_of_edge(e)) quad_corners += corner_chord[c] != kInvalidIndex;
    if (quad_corners > 1) ++out.stats.num_shared_end_edges;
  }
  out.num_closed = out.stats.num_closed;
  out.num_self_crossing = out.stats.num_self_crossing;
  return out;
}

std::vector<Vec3> medial_curve(const PolyMesh& mesh, const Connectivity& conn, const PolyChord& chord) {
  std::vector<Vec3> points;
  points.reserve(chord.opposing_edges.size());
  for (Index e : chord.opposing_edges) {
    const auto& v = conn.edge_vertices[e];
    points.push_back(0.5 * (mesh.positions[v[0]] + mesh.positions[v[1]]));
  }
  return points;
}

std::vector<Vec3> chord_quad_normals(const PolyMesh& mesh, const Connectivity& conn,
                                     const PolyChord& chord, bool* wrap_flip) {
  const Index m = chord.size();
  std::vector<Vec3> normals(m);
  double sign = 1.0;
  // Orientation flips between a quad left through `exit` and the next quad entered at `entry`.
  auto flips = [&](Index exit, Index entry) {
    return conn.corner_vertex[entry] == conn.corner_vertex[exit];
  };
  for (Index i = 0; i < m; ++i) {
    if (i > 0 && flips(conn.opposite_corner_in_quad(chord.entry_corners[i - 1]), chord.entry_corners[i]))
      sign = -sign;
    normals[i] = sign * face_normal(mesh, chord.quads[i]);
  }
  if (wrap_flip) {
    *wrap_flip = false;
    if (chord.closed && m > 0)
      *wrap_flip = (sign < 0.0) !=
                   flips(conn.opposite_corner_in_quad(chord.entry_corners[m - 1]), chord.entry_corners[0]);
  }
  return normals;
}

}  // namespace quadlod
