// Shared fixtures of the topology / clustering tests: hand-built meshes with hand-counted
// poly-chords, corpus loading, and the structural invariants every analysis result must satisfy.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"
#include "quadlod/mesh.h"
#include "topology/polychords.h"
#include "topology/segmentation.h"
#include "geometry/medial_clustering.h"
#include "geometry/triangle_clustering.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

namespace quadlod::topo_test {

/// A mesh with its connectivity, kept together so tests cannot mix them up.
struct Fixture {
  std::string name;
  PolyMesh mesh;
  Connectivity conn;
};

inline Fixture make_fixture(std::string name, PolyMesh mesh) {
  Fixture f{std::move(name), std::move(mesh), {}};
  f.conn = build_connectivity(f.mesh);
  return f;
}

/// Reads a corpus mesh; an empty optional-like result (mesh without faces) when the corpus is
/// missing, so callers can GTEST_SKIP.
inline bool load_corpus(const std::string& file, PolyMesh& mesh) {
#ifdef QUADLOD_CORPUS_DIR
  const std::filesystem::path path = std::filesystem::path(QUADLOD_CORPUS_DIR) / file;
  if (!std::filesystem::exists(path)) return false;
  ReadResult r = read_obj(path);
  if (!r.ok()) {
    ADD_FAILURE() << r.error;
    return false;
  }
  mesh = std::move(r.mesh);
  return true;
#else
  (void)file;
  (void)mesh;
  return false;
#endif
}

/// Small corpus meshes covering triangles, n-gons, non-manifold edges and duplicate faces.
inline const std::vector<std::string>& corpus_sample() {
  static const std::vector<std::string> files = {
      "blender_suzanne.obj",           // tris + quads, boundary
      "godot_squash_player_cage.obj",  // n-gons, closed
      "flightgear_head_amelia.obj",    // a non-manifold edge
      "opensubdiv_car_cage.obj",       // all quads, many components
      "tpsdemo_red_robot.obj",         // duplicate faces, 95 non-manifold edges
  };
  return files;
}

// --- hand-built meshes ---------------------------------------------------------------------------

/// A flat 3×3 grid plus a planar "bridge" strip of k quads that leaves the grid's east side at
/// row 1 and returns into its north side at column 1, so one chord runs west→east through the
/// centre quad X, around the bridge, and north→south through X again: a self-crossing chord.
///
///                         ╭───────────╮        bridge: k quads on the annulus sector of radii
///                        ╱  ╭───────╮  ╲       1..2 around the grid corner (3,3), angles
///   y=3  o────o──a_k──b_k  │       │   │      -90° … 180° (counter-clockwise, outside the grid)
///        │    │ ▼  │     ( (3,3)    )  │
///   y=2  o────o────o────a_0 ───────╯  ╱        a_0 = (3,2), b_0 = (3,1)
///        │    │ X  │ ──►  │ ─────────╯          a_k = (2,3), b_k = (1,3)
///   y=1  o────o────o────b_0
///        │    │ ▼  │    │                       the chord: (1,0) ▲ X ▲ (1,2) ▲ bridge ◄ (2,1)
///   y=0  o────o────o────o                       ◄ X ◄ (0,1)   (walked from the south end)
///       x=0  x=1  x=2  x=3
///
/// Chords (hand count): the self-crossing one (3 + k + 3 quads, open, 3 + k + 4 opposing edges);
/// rows 0 and 2 and columns 0 and 2 (3 quads each, open); each bridge quad across the strip
/// (1 quad, both ends on the boundary): 1 + 4 + k chords.
inline PolyMesh make_self_crossing(Index k = 9) {
  PolyMesh m;
  for (Index j = 0; j <= 3; ++j)
    for (Index i = 0; i <= 3; ++i) m.add_vertex(Vec3(i, j, 0));
  auto id = [](Index i, Index j) { return j * 4 + i; };
  for (Index j = 0; j < 3; ++j)
    for (Index i = 0; i < 3; ++i) m.add_face({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  std::vector<Index> a(k + 1), b(k + 1);
  a[0] = id(3, 2);
  b[0] = id(3, 1);
  a[k] = id(2, 3);
  b[k] = id(1, 3);
  const Vec3 centre(3, 3, 0);
  for (Index t = 1; t < k; ++t) {
    const double angle = (-90.0 + 270.0 * t / k) * std::numbers::pi / 180.0;
    const Vec3 dir(std::cos(angle), std::sin(angle), 0);
    a[t] = m.add_vertex(centre + dir);
    b[t] = m.add_vertex(centre + 2.0 * dir);
  }
  for (Index t = 0; t < k; ++t) m.add_face({a[t], b[t], b[t + 1], a[t + 1]});
  return m;
}

/// A valence-5 interior vertex O with five quads q_i = (O, H_2i, H_2i+1, H_2i+2) over a
/// ten-vertex rim (a decagon), a triangle glued on rim edge H1–H2 and a pentagon on rim edge
/// H5–H6 (both outside the rim):
///
///               H3 ─── H2 ─── H1 ── T      q0 = O H0 H1 H2   triangle (H2, H1, T)
///              ╱  q1   │   q0   ╲          q1 = O H2 H3 H4
///            H4 ────── O ─────── H0        q2 = O H4 H5 H6   pentagon (H6, H5, P0, P1, P2)
///              ╲  q2  ╱ ╲   q4  ╱          q3 = O H6 H7 H8
///      P… ── H5 ── H6  q3  H8 ─ H9         q4 = O H8 H9 H0
///                      H7
///
/// Every chord of a valence-k star crosses one spoke O–H_2i and two rim edges: it runs through
/// the two quads sharing that spoke. Hand count: 5 chords, 2 quads each, all open. The 10 chord
/// ends are the 10 rim edges: 8 on the boundary, 1 at the triangle, 1 at the pentagon.
inline PolyMesh make_star5_with_triangle_and_pentagon() {
  PolyMesh m;
  const Index o = m.add_vertex(Vec3(0, 0, 0));
  std::vector<Index> h(10);
  for (Index i = 0; i < 10; ++i) {
    const double a = 2.0 * std::numbers::pi * i / 10.0;
    const double r = i % 2 ? 1.2 : 1.0;
    h[i] = m.add_vertex(Vec3(r * std::cos(a), r * std::sin(a), 0));
  }
  for (Index i = 0; i < 5; ++i) m.add_face({o, h[2 * i], h[2 * i + 1], h[(2 * i + 2) % 10]});
  const Vec3 mid12 = 0.5 * (m.positions[h[1]] + m.positions[h[2]]);
  const Index t = m.add_vertex(1.6 * mid12);
  m.add_face({h[2], h[1], t});
  const Vec3 mid56 = 0.5 * (m.positions[h[5]] + m.positions[h[6]]);
  const Index p0 = m.add_vertex(1.5 * mid56 + Vec3(0, 0.3, 0));
  const Index p1 = m.add_vertex(1.9 * mid56);
  const Index p2 = m.add_vertex(1.5 * mid56 - Vec3(0, 0.3, 0));
  m.add_face({h[6], h[5], p0, p1, p2});
  return m;
}

/// Three quads sharing one edge (a "book" of three pages): the spine is non-manifold.
/// Hand count: each page has a chord across the spine (spine … outer edge, 1 quad, ending at the
/// non-manifold spine) and one along it (1 quad between two boundary edges): 6 chords; the spine
/// is the end edge of 3 chords.
inline PolyMesh make_book3() {
  PolyMesh m;
  const Index s0 = m.add_vertex(Vec3(0, 0, 0)), s1 = m.add_vertex(Vec3(0, 0, 1));
  for (int page = 0; page < 3; ++page) {
    const double a = 2.0 * std::numbers::pi * page / 3.0;
    const Vec3 d(std::cos(a), std::sin(a), 0);
    const Index p0 = m.add_vertex(d), p1 = m.add_vertex(d + Vec3(0, 0, 1));
    m.add_face({s0, p0, p1, s1});
  }
  return m;
}

/// An n×m grid (make_grid, unit cells) folded by `angle` about the line x = fold (0 < fold < n):
/// vertices with x > fold are rotated about that line, lifting the right part out of the plane.
inline PolyMesh make_folded_grid(Index n, Index m, Index fold, double angle) {
  PolyMesh mesh = make_grid(n, m, double(n), double(m));
  for (Vec3& p : mesh.positions) {
    const double t = p.x() - fold;
    if (t > 0) p = Vec3(fold + t * std::cos(angle), p.y(), t * std::sin(angle));
  }
  return mesh;
}

/// A flat width-1 strip that turns 90° in the plane through a mitred corner (two trapezoids):
///
///                   ┌───┐ y=3     quads, walking along the chord:
///                   │ c │           Q0 [0,1]×[0,1], Q1 [1,2]×[0,1],
///                   ├───┤ y=2       Qa (2,0)(4,0)(3,1)(2,1)  (trapezoid),
///                   │ b ╱           Qb (3,1)(4,0)(4,2)(3,2)  (trapezoid),
///   ┌───┬───┬─────┬─╱ │             Qc [3,4]×[2,3]
///   │Q0 │Q1 │ a  ╱    │ y=1
///   └───┴───┴───╱─────┘ y=0       the mitre edge (4,0)–(3,1) joins Qa and Qb: the chord turns
///  x=0     x=2  x=3  x=4          90° there without any dihedral angle.
///
/// Chords: the long one (5 quads) and one 1-quad chord across each quad: 6.
inline PolyMesh make_mitred_strip() {
  PolyMesh m;
  auto v = [&](double x, double y) { return m.add_vertex(Vec3(x, y, 0)); };
  const Index v00 = v(0, 0), v10 = v(1, 0), v20 = v(2, 0), v40 = v(4, 0);
  const Index v01 = v(0, 1), v11 = v(1, 1), v21 = v(2, 1), v31 = v(3, 1);
  const Index v32 = v(3, 2), v42 = v(4, 2), v33 = v(3, 3), v43 = v(4, 3);
  m.add_face({v00, v10, v11, v01});
  m.add_face({v10, v20, v21, v11});
  m.add_face({v20, v40, v31, v21});
  m.add_face({v31, v40, v42, v32});
  m.add_face({v32, v42, v43, v33});
  return m;
}

/// A closed band of n quads with a half twist (Möbius band): the chord along the band is closed
/// and its faces cannot be oriented consistently.
inline PolyMesh make_moebius(Index n = 12) {
  PolyMesh m;
  for (Index i = 0; i < n; ++i) {
    const double u = 2.0 * std::numbers::pi * i / n;
    for (int s = -1; s <= 1; s += 2) {
      const double w = 0.3 * s;
      const double r = 1.0 + w * std::cos(u / 2);
      m.add_vertex(Vec3(r * std::cos(u), r * std::sin(u), w * std::sin(u / 2)));
    }
  }
  // Vertex 2i is the "-" side, 2i+1 the "+" side; the last quad joins i = n-1 to i = 0 with the
  // sides swapped (the half twist).
  for (Index i = 0; i < n; ++i) {
    const Index a = 2 * i, b = 2 * i + 1;
    if (i + 1 < n) m.add_face({a, a + 2, b + 2, b});
    else m.add_face({a, 1, 0, b});
  }
  return m;
}

/// Splits every quad of `mesh` along its 0–2 diagonal (other faces are kept).
inline PolyMesh triangulate_quads(const PolyMesh& mesh) {
  PolyMesh out;
  out.positions = mesh.positions;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const auto v = mesh.face_vertices(f);
    if (v.size() == 4) {
      out.add_face({v[0], v[1], v[2]});
      out.add_face({v[0], v[2], v[3]});
    } else {
      out.add_face(v);
    }
  }
  return out;
}

/// The fixed set of generated meshes every invariant test runs over.
inline std::vector<Fixture> generated_fixtures() {
  std::vector<Fixture> f;
  f.push_back(make_fixture("grid_5x3", make_grid(5, 3)));
  f.push_back(make_fixture("grid_1x1", make_grid(1, 1)));
  f.push_back(make_fixture("torus_8x5", make_torus(8, 5)));
  f.push_back(make_fixture("cylinder_7x4", make_cylinder(7, 4)));
  f.push_back(make_fixture("cube_1", make_cube(1)));
  f.push_back(make_fixture("cube_3", make_cube(3)));
  f.push_back(make_fixture("vase_6x2", make_demo_vase(6, 2)));
  f.push_back(make_fixture("vase_48x40", make_demo_vase(48, 40)));
  f.push_back(make_fixture("self_crossing", make_self_crossing()));
  f.push_back(make_fixture("star5", make_star5_with_triangle_and_pentagon()));
  f.push_back(make_fixture("book3", make_book3()));
  f.push_back(make_fixture("folded_grid", make_folded_grid(6, 4, 3, std::numbers::pi / 2)));
  f.push_back(make_fixture("mitred_strip", make_mitred_strip()));
  f.push_back(make_fixture("moebius", make_moebius()));
  return f;
}

// --- invariants ---------------------------------------------------------------------------------

/// Structural invariants of extract_polychords (paper §3.1), including the one the rest of the
/// pipeline relies on: every edge of a quad is an opposing edge of exactly one chord (of one
/// chord per incident quad corner at a non-manifold edge).
inline void expect_polychord_invariants(const Fixture& f, const PolyChordResult& r) {
  SCOPED_TRACE(f.name);
  const Connectivity& conn = f.conn;
  std::vector<Index> occurrences(conn.num_edges, 0);
  std::vector<std::vector<Index>> chords_of_edge(conn.num_edges);
  std::size_t total_steps = 0;
  Index closed = 0, self_crossing = 0;
  for (Index id = 0; id < r.chords.size(); ++id) {
    const PolyChord& ch = r.chords[id];
    const Index m = ch.size();
    ASSERT_GT(m, 0u);
    ASSERT_EQ(ch.opposing_edges.size(), m + (ch.closed ? 0u : 1u));
    ASSERT_EQ(ch.loopy_edges.size(), m);
    ASSERT_EQ(ch.entry_corners.size(), m);
    EXPECT_EQ(ch.closed, ch.ends[0] == ChordEnd::None);
    EXPECT_EQ(ch.closed, ch.ends[1] == ChordEnd::None);
    total_steps += m;
    closed += ch.closed;
    for (Index e : ch.opposing_edges) {
      ++occurrences[e];
      chords_of_edge[e].push_back(id);
    }
    std::vector<Index> quads = ch.quads;
    std::sort(quads.begin(), quads.end());
    const bool twice = std::adjacent_find(quads.begin(), quads.end()) != quads.end();
    EXPECT_EQ(ch.self_crossing, twice);
    self_crossing += ch.self_crossing;
    for (Index i = 0; i < m; ++i) {
      const Index c = ch.entry_corners[i];
      ASSERT_EQ(conn.corner_face[c], ch.quads[i]);
      ASSERT_TRUE(conn.is_quad(ch.quads[i]));
      EXPECT_EQ(conn.corner_edge[c], ch.opposing_edges[i]);
      EXPECT_EQ(conn.corner_edge[conn.opposite_corner_in_quad(c)],
                ch.opposing_edges[(i + 1) % ch.opposing_edges.size()]);
      const Index n = conn.corner_edge[conn.corner_next[c]], p = conn.corner_edge[conn.corner_prev[c]];
      const auto& l = ch.loopy_edges[i];
      EXPECT_TRUE((l[0] == n && l[1] == p) || (l[0] == p && l[1] == n));
      EXPECT_EQ(r.corner_chord[c], id);
      // Side consistency: side-0 edges of consecutive quads meet at an endpoint of the shared
      // opposing edge (checked where no vertex repeats).
      if (i + 1 < m) {
        const auto& a = conn.edge_vertices[l[0]];
        const auto& b = conn.edge_vertices[ch.loopy_edges[i + 1][0]];
        const bool meet = a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
        EXPECT_TRUE(meet) << "chord " << id << " step " << i;
      }
    }
  }
  EXPECT_EQ(r.num_closed, closed);
  EXPECT_EQ(r.num_self_crossing, self_crossing);
  EXPECT_EQ(r.stats.num_open + r.stats.num_closed, r.chords.size());

  Index quads = 0;
  for (Index face = 0; face < conn.num_faces; ++face) quads += conn.is_quad(face);
  EXPECT_EQ(total_steps, 2u * quads) << "every quad direction on exactly one chord";

  for (Index c = 0; c < conn.corner_edge.size(); ++c) {
    if (!conn.is_quad(conn.corner_face[c])) {
      EXPECT_EQ(r.corner_chord[c], kInvalidIndex);
      continue;
    }
    EXPECT_EQ(r.corner_chord[c], r.corner_chord[conn.opposite_corner_in_quad(c)]);
  }
  for (Index e = 0; e < conn.num_edges; ++e) {
    Index quad_corners = 0;
    for (Index c : conn.corners_of_edge(e)) quad_corners += conn.is_quad(conn.corner_face[c]);
    if (quad_corners == 0) {
      EXPECT_EQ(occurrences[e], 0u) << "edge " << e;
      EXPECT_EQ(r.edge_chord[e], kInvalidIndex) << "edge " << e;
    } else if (!conn.is_nonmanifold_edge(e)) {
      ASSERT_EQ(occurrences[e], 1u) << "edge " << e << " must be an opposing edge of exactly one chord";
      EXPECT_EQ(r.edge_chord[e], chords_of_edge[e][0]);
    } else {
      EXPECT_EQ(occurrences[e], quad_corners) << "non-manifold edge " << e;
      const auto& list = chords_of_edge[e];
      EXPECT_NE(std::find(list.begin(), list.end(), r.edge_chord[e]), list.end());
    }
  }
}

/// Invariants of segment_polychords: the segments of each chord partition its opposing-edge
/// positions in walking order, every segment starts at position 0 or at a breakpoint,
/// edge_segment is consistent, and (self-intersection criterion on) the opposing edges of one
/// segment are pairwise vertex-disjoint.
inline void expect_segmentation_invariants(const Fixture& f, const PolyChordResult& chords,
                                           const SegmentationResult& seg, const SegmentationParams& params) {
  SCOPED_TRACE(f.name);
  ASSERT_EQ(seg.chord_segment_begin.size(), chords.chords.size() + 1);
  ASSERT_EQ(seg.chord_segment_begin.back(), seg.segments.size());
  std::vector<std::uint8_t> is_break;
  Index bp = 0;
  for (Index c = 0; c < chords.chords.size(); ++c) {
    const PolyChord& ch = chords.chords[c];
    const Index n = static_cast<Index>(ch.opposing_edges.size());
    is_break.assign(n, 0);
    for (; bp < seg.breakpoints.size() && seg.breakpoints[bp].chord == c; ++bp) {
      const Breakpoint& b = seg.breakpoints[bp];
      ASSERT_LT(b.position, n);
      EXPECT_EQ(b.edge, ch.opposing_edges[b.position]);
      EXPECT_NE(b.reasons, 0);
      is_break[b.position] = 1;
    }
    const Index begin = seg.chord_segment_begin[c], end = seg.chord_segment_begin[c + 1];
    ASSERT_GT(end, begin) << "chord " << c << " has no segment";
    if (!params.enable) {
      EXPECT_EQ(end - begin, 1u);
    }
    std::vector<Index> covered(n, 0);
    for (Index s = begin; s < end; ++s) {
      const Segment& g = seg.segments[s];
      EXPECT_EQ(g.chord, c);
      if (!ch.closed) {
        EXPECT_LE(g.first, g.last);
      }
      EXPECT_TRUE(g.first == 0 || is_break[g.first]) << "segment " << s << " starts at no breakpoint";
      // Positions first..last (cyclic) in order.
      Index i = g.first;
      for (std::size_t k = 0; k < g.opposing_edges.size(); ++k, i = (i + 1) % n) {
        EXPECT_EQ(g.opposing_edges[k], ch.opposing_edges[i]);
        ++covered[i];
        if (k > 0) {
          EXPECT_FALSE(is_break[i]) << "breakpoint inside segment " << s;
        }
      }
      EXPECT_EQ((i + n - 1) % n, g.last);
      if (params.enable && params.use_self_intersection) {
        std::vector<Index> verts;
        for (Index e : g.opposing_edges)
          for (Index v : f.conn.edge_vertices[e]) verts.push_back(v);
        std::sort(verts.begin(), verts.end());
        EXPECT_EQ(std::adjacent_find(verts.begin(), verts.end()), verts.end())
            << "segment " << s << " has two opposing edges sharing a vertex";
      }
    }
    for (Index i = 0; i < n; ++i) EXPECT_EQ(covered[i], 1u) << "chord " << c << " position " << i;
  }
  EXPECT_EQ(bp, seg.breakpoints.size());
  EXPECT_EQ(seg.stats.num_breakpoints, seg.breakpoints.size());
  ASSERT_EQ(seg.edge_segment.size(), f.conn.num_edges);
  for (Index e = 0; e < f.conn.num_edges; ++e) {
    if (chords.edge_chord[e] == kInvalidIndex) {
      EXPECT_EQ(seg.edge_segment[e], kInvalidIndex);
      continue;
    }
    ASSERT_NE(seg.edge_segment[e], kInvalidIndex) << "edge " << e;
    const Segment& g = seg.segments[seg.edge_segment[e]];
    EXPECT_EQ(g.chord, chords.edge_chord[e]);
    EXPECT_NE(std::find(g.opposing_edges.begin(), g.opposing_edges.end(), e), g.opposing_edges.end());
  }
}

/// Invariants of cluster_medial_curves: per chord, the clusters' quad ranges partition the chord
/// in order and their edges partition the chord's distinct loopy edges ("every loopy edge appears
/// in exactly one cluster of its chord").
inline void expect_medial_invariants(const Fixture& f, const PolyChordResult& chords,
                                     const MedialClusteringResult& r) {
  SCOPED_TRACE(f.name);
  ASSERT_EQ(r.chord_cluster_begin.size(), chords.chords.size() + 1);
  ASSERT_EQ(r.chord_cluster_begin.back(), r.clusters.size());
  const bool dropped = r.stats.empty_clusters_dropped > 0;
  for (Index c = 0; c < chords.chords.size(); ++c) {
    const PolyChord& ch = chords.chords[c];
    const Index m = ch.size();
    const Index begin = r.chord_cluster_begin[c], end = r.chord_cluster_begin[c + 1];
    ASSERT_GT(end, begin) << "chord " << c << " has no cluster";
    std::vector<Index> covered(m, 0);
    std::vector<Index> in_clusters;
    for (Index k = begin; k < end; ++k) {
      const EdgeCluster& cl = r.clusters[k];
      EXPECT_EQ(cl.chord, c);
      ASSERT_LT(cl.first, m);
      ASSERT_LT(cl.last, m);
      if (!ch.closed) {
        EXPECT_LE(cl.first, cl.last);
      }
      if (k > begin && !dropped) {
        EXPECT_EQ(cl.first, (r.clusters[k - 1].last + 1) % m) << "clusters in chord order";
      }
      std::vector<Index> allowed;
      for (Index i = cl.first;; i = (i + 1) % m) {
        ++covered[i];
        allowed.push_back(ch.loopy_edges[i][0]);
        allowed.push_back(ch.loopy_edges[i][1]);
        if (i == cl.last) break;
      }
      EXPECT_FALSE(cl.edges.empty());
      for (Index e : cl.edges) {
        EXPECT_NE(std::find(allowed.begin(), allowed.end(), e), allowed.end()) << "edge " << e;
        in_clusters.push_back(e);
      }
      if (cl.normal.squaredNorm() > 0) {
        EXPECT_NEAR(cl.normal.norm(), 1.0, 1e-9);
      }
    }
    for (Index i = 0; i < m; ++i) {
      if (dropped) {
        EXPECT_LE(covered[i], 1u);
      } else {
        EXPECT_EQ(covered[i], 1u) << "chord " << c << " quad position " << i;
      }
    }
    std::vector<Index> loopy;
    for (const auto& l : ch.loopy_edges) loopy.insert(loopy.end(), l.begin(), l.end());
    std::sort(loopy.begin(), loopy.end());
    loopy.erase(std::unique(loopy.begin(), loopy.end()), loopy.end());
    std::sort(in_clusters.begin(), in_clusters.end());
    EXPECT_EQ(std::adjacent_find(in_clusters.begin(), in_clusters.end()), in_clusters.end())
        << "chord " << c << ": a loopy edge in two clusters";
    if (!dropped) {
      EXPECT_EQ(in_clusters, loopy) << "chord " << c << ": clusters must cover its loopy edges";
    }
  }
}

/// Invariants of cluster_triangle_regions: clusters partition the edges that border triangles,
/// stay inside one region, and the neighbour list is exactly the symmetric "share a vertex"
/// relation.
inline void expect_triangle_invariants(const Fixture& f, const TriangleClusteringResult& r) {
  SCOPED_TRACE(f.name);
  const Connectivity& conn = f.conn;
  ASSERT_EQ(r.edge_cluster.size(), conn.num_edges);
  std::vector<Index> seen(conn.num_edges, 0);
  for (Index k = 0; k < r.clusters.size(); ++k) {
    const TriangleCluster& cl = r.clusters[k];
    ASSERT_FALSE(cl.edges.empty());
    EXPECT_TRUE(std::is_sorted(cl.edges.begin(), cl.edges.end()));
    EXPECT_TRUE(std::binary_search(cl.edges.begin(), cl.edges.end(), cl.representative));
    for (Index e : cl.edges) {
      ++seen[e];
      EXPECT_EQ(r.edge_cluster[e], k);
      EXPECT_EQ(r.edge_region[e], cl.region);
    }
  }
  for (Index e = 0; e < conn.num_edges; ++e) {
    bool borders_triangle = false;
    for (Index c : conn.corners_of_edge(e)) borders_triangle |= conn.face_degree[conn.corner_face[c]] == 3;
    EXPECT_EQ(seen[e], borders_triangle ? 1u : 0u) << "edge " << e;
    EXPECT_EQ(r.edge_cluster[e] != kInvalidIndex, borders_triangle) << "edge " << e;
  }
  // Neighbours: sorted, unique, irreflexive, symmetric, and equal to "share a vertex".
  EXPECT_TRUE(std::is_sorted(r.neighbours.begin(), r.neighbours.end()));
  EXPECT_EQ(std::adjacent_find(r.neighbours.begin(), r.neighbours.end()), r.neighbours.end());
  std::vector<std::pair<Index, Index>> expected;
  for (Index v = 0; v < conn.num_vertices; ++v) {
    std::vector<Index> here;
    for (Index c : conn.corners_at_vertex(v))
      for (Index e : {conn.corner_edge[c], conn.corner_edge[conn.corner_prev[c]]})
        if (r.edge_cluster[e] != kInvalidIndex) here.push_back(r.edge_cluster[e]);
    std::sort(here.begin(), here.end());
    here.erase(std::unique(here.begin(), here.end()), here.end());
    for (Index a : here)
      for (Index b : here)
        if (a != b) expected.emplace_back(a, b);
  }
  std::sort(expected.begin(), expected.end());
  expected.erase(std::unique(expected.begin(), expected.end()), expected.end());
  EXPECT_EQ(r.neighbours, expected);
  for (const auto& [a, b] : r.neighbours) {
    EXPECT_NE(a, b);
    EXPECT_TRUE(std::binary_search(r.neighbours.begin(), r.neighbours.end(), std::make_pair(b, a)));
  }
}

}  // namespace quadlod::topo_test
