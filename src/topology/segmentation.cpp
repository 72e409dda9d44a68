// Poly-chord segmentation at breakpoints (paper §3.2.2, Fig. 5; Eq. 4 consumes the segments).
// See segmentation.h for the criteria and for which segment a breakpoint edge joins.
//
// Geometry per chord step, with signed normals n_i (chord_quad_normals) and medial points p_i
// (midpoints of the opposing edges):
//
//        e_{i-1}        e_i         e_{i+1}
//          │  quads[i-1] │  quads[i]  │
//          │ n_{i-1}     │ n_i        │        d_i = p_{i+1} - p_i   (walking direction in quad i)
//          p_{i-1} ────► p_i ───────► p_{i+1}  b_i = normalize(n_i × d_i)  (bi-normal)
//          │             │            │
//   dihedral(e_i)  = ∠(n_{i-1}, n_i)
//   bi-normal(e_i) = ∠(b_{i-1}, b_i)
//
// Both are defined only where e_i lies between two chord quads: positions 1..m-1 of an open
// chord, every position of a closed one (position 0 compares quads[m-1] with quads[0], with the
// wrap's orientation flip applied on a Möbius band). The end edges of an open chord can only be
// self-intersection breakpoints.
#include "topology/segmentation.h"

#include "util/parallel.h"

#include <cmath>

namespace quadlod {

namespace {

// Angle between two vectors in [0, π]; negative when either is zero (test undefined).
double angle_between(const Vec3& a, const Vec3& b) {
  if (a.isZero(0.0) || b.isZero(0.0)) return -1.0;
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

struct ChordSegmenter {
  const PolyMesh& mesh;
  const Connectivity& conn;
  const SegmentationParams& params;
  SegmentationResult& out;
  std::vector<Index> vertex_stamp;  // chord id + 1 of the last chord that visited the vertex

  std::vector<std::uint8_t> reasons;  // per position of the current chord

  // `geometric_reasons`: what geometric(chord) found for this chord (computed beforehand, on
  // any thread).
  void run(Index chord_id, const PolyChord& chord, std::vector<std::uint8_t>&& geometric_reasons) {
    const Index m = chord.size();
    const Index num_edges = static_cast<Index>(chord.opposing_edges.size());
    reasons = std::move(geometric_reasons);
    reasons.resize(num_edges, 0);
    if (params.enable && m > 0 && params.use_self_intersection) self_intersection(chord_id, chord);

    // Breakpoint positions; position 0 of an open chord is its start anyway.
    std::vector<Index> starts;
    bool self_touch = false;
    for (Index i = 0; i < num_edges; ++i) {
      if (!reasons[i]) continue;
      self_touch |= (reasons[i] & kBreakSelfIntersection) != 0;
      if (i > 0 || chord.closed) starts.push_back(i);
    }
    if (chord.closed && self_touch && reasons[0] == 0) {
      reasons[0] = kBreakClosedStart;
      starts.insert(starts.begin(), 0);
    }
    for (Index i = 0; i < num_edges; ++i) {
      if (!reasons[i] || (i == 0 && !chord.closed)) continue;
      out.breakpoints.push_back({chord_id, i, chord.opposing_edges[i], reasons[i]});
      SegmentationStats& s = out.stats;
      ++s.num_breakpoints;
      s.num_dihedral += (reasons[i] & kBreakDihedral) != 0;
      s.num_binormal += (reasons[i] & kBreakBinormal) != 0;
      s.num_self_intersection += (reasons[i] & kBreakSelfIntersection) != 0;
      s.num_closed_start += (reasons[i] & kBreakClosedStart) != 0;
    }

    if (!chord.closed || starts.empty()) {
      if (starts.empty() || starts.front() != 0) starts.insert(starts.begin(), 0);
      for (std::size_t j = 0; j < starts.size(); ++j) {
        const Index last = j + 1 < starts.size() ? starts[j + 1] - 1 : num_edges - 1;
        emit(chord_id, chord, starts[j], last);
      }
    } else {
      // Closed with breakpoints: segments run from one breakpoint to the next, the last one
      // wrapping round to the first.
      for (std::size_t j = 0; j < starts.size(); ++j) {
        const Index last = j + 1 < starts.size() ? starts[j + 1] - 1
                                                 : (starts.front() + num_edges - 1) % num_edges;
        emit(chord_id, chord, starts[j], last);
      }
    }
  }

  // The dihedral and bi-normal breakpoints of one chord into `reasons` (one per opposing edge);
  // reads the mesh only, so chords run on any thread. Returns the tests skipped as degenerate.
  static Index geometric(const PolyMesh& mesh, const Connectivity& conn, const SegmentationParams& params,
                         const PolyChord& chord, std::vector<std::uint8_t>& reasons) {
    Index skipped = 0;
    const Index m = chord.size();
    bool wrap_flip = false;
    const std::vector<Vec3> normals = chord_quad_normals(mesh, conn, chord, &wrap_flip);
    const std::vector<Vec3> points = medial_curve(mesh, conn, chord);
    std::vector<Vec3> binormals(m);
    for (Index i = 0; i < m; ++i) {
      const Vec3 d = points[(i + 1) % points.size()] - points[i];
      const Vec3 b = normals[i].cross(d);
      const double len = b.norm();
      binormals[i] = len > 0.0 ? Vec3(b / len) : Vec3::Zero();
    }
    const double eps = params.epsilon_theta;
    const Index first = chord.closed ? 0 : 1;
    for (Index i = first; i < m; ++i) {
      const Index prev = i == 0 ? m - 1 : i - 1;
      const double s = (i == 0 && wrap_flip) ? -1.0 : 1.0;
      if (params.use_dihedral) {
        const double a = angle_between(normals[prev], s * normals[i]);
        if (a < 0.0) ++skipped;
        else if (a > eps) reasons[i] |= kBreakDihedral;
      }
      if (params.use_binormal) {
        const double a = angle_between(binormals[prev], s * binormals[i]);
        if (a < 0.0) ++skipped;
        else if (a > eps) reasons[i] |= kBreakBinormal;
      }
    }
    return skipped;
  }

  void self_intersection(Index chord_id, const PolyChord& chord) {
    const Index stamp = chord_id + 1;
    for (Index i = 0; i < chord.opposing_edges.size(); ++i) {
      const auto& v = conn.edge_vertices[chord.opposing_edges[i]];
      if (i > 0 && (vertex_stamp[v[0]] == stamp || vertex_stamp[v[1]] == stamp))
        reasons[i] |= kBreakSelfIntersection;
      vertex_stamp[v[0]] = stamp;
      vertex_stamp[v[1]] = stamp;
    }
  }

  void emit(Index chord_id, const PolyChord& chord, Index first, Index last) {
    const Index n = static_cast<Index>(chord.opposing_edges.size());
    Segment seg;
    seg.chord = chord_id;
    seg.first = first;
    seg.last = last;
    for (Index i = first;; i = (i + 1) % n) {
      seg.opposing_edges.push_back(chord.opposing_edges[i]);
      if (i == last) break;
    }
    const Index id = static_cast<Index>(out.segments.size());
    for (Index e : seg.opposing_edges)
      if (out.edge_segment[e] == kInvalidIndex && chord_id == edge_chord_of(e)) out.edge_segment[e] = id;
    const Index size = static_cast<Index>(seg.opposing_edges.size());
    out.stats.num_single_edge_segments += size == 1;
    out.stats.longest_segment = std::max(out.stats.longest_segment, size);
    out.segments.push_back(std::move(seg));
  }

  const std::vector<Index>* edge_chord = nullptr;
  Index edge_chord_of(Index e) const { return (*edge_chord)[e]; }
};

}  // namespace

SegmentationResult segment_polychords(const PolyMesh& mesh, const Connectivity& conn,
                                      const PolyChordResult& chords, const SegmentationParams& params) {
  SegmentationResult out;
  out.edge_segment.assign(conn.num_edges, kInvalidIndex);
  out.chord_segment_begin.reserve(chords.chords.size() + 1);
  // The geometric tests (the cost: normals, medial points and angles of every chord position)
  // on all threads, each chord alone; the segments are then cut chord by chord in order.
  const std::size_t nc = chords.chords.size();
  std::vector<std::vector<std::uint8_t>> geometric(nc);
  std::vector<Index> skipped(nc, 0);
  const bool test_geometry = params.enable && (params.use_dihedral || params.use_binormal);
  if (test_geometry)
    parallel_chunks(nc, params.threads, conn.num_edges < params.min_parallel_edges ? nc + 1 : 0,
                    [&](std::size_t begin, std::size_t end, std::size_t) {
                      for (std::size_t c = begin; c < end; ++c) {
                        const PolyChord& chord = chords.chords[c];
                        geometric[c].assign(chord.opposing_edges.size(), 0);
                        if (chord.size() > 0)
                          skipped[c] = ChordSegmenter::geometric(mesh, conn, params, chord, geometric[c]);
                      }
                    });
  ChordSegmenter seg{mesh, conn, params, out, std::vector<Index>(conn.num_vertices, 0), {}};
  seg.edge_chord = &chords.edge_chord;
  for (Index c = 0; c < nc; ++c) {
    out.chord_segment_begin.push_back(static_cast<Index>(out.segments.size()));
    out.stats.num_degenerate_skipped += skipped[c];
    seg.run(c, chords.chords[c], std::move(geometric[c]));
  }
  out.chord_segment_begin.push_back(static_cast<Index>(out.segments.size()));
  return out;
}

}  // namespace quadlod
