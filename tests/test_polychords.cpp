// Poly-chord extraction (paper §3.1): hand-counted chords on generated and hand-built meshes,
// and the extraction invariants over every generated mesh and a corpus sample.
#include "topology/polychords.h"

#include "topology_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

using namespace quadlod;
using namespace quadlod::topo_test;

namespace {

PolyChordResult chords_of(const Fixture& f) { return extract_polychords(f.mesh, f.conn); }

// Multiset of (closed, length) over all chords.
std::map<std::pair<bool, Index>, Index> length_histogram(const PolyChordResult& r) {
  std::map<std::pair<bool, Index>, Index> h;
  for (const PolyChord& c : r.chords) ++h[{c.closed, c.size()}];
  return h;
}

}  // namespace

TEST(PolyChords, GridHasNPlusMOpenChords) {
  for (auto [n, m] : {std::pair<Index, Index>{5, 3}, {1, 1}, {7, 1}, {4, 4}}) {
    const Fixture f = make_fixture("grid", make_grid(n, m));
    const PolyChordResult r = chords_of(f);
    SCOPED_TRACE(testing::Message() << n << "x" << m);
    ASSERT_EQ(r.chords.size(), n + m);
    EXPECT_EQ(r.num_closed, 0u);
    EXPECT_EQ(r.num_self_crossing, 0u);
    std::map<std::pair<bool, Index>, Index> expected;
    expected[{false, n}] += m;  // m rows of n quads, n columns of m quads
    expected[{false, m}] += n;
    EXPECT_EQ(length_histogram(r), expected);
    EXPECT_EQ(r.stats.ends_at_boundary, 2 * (n + m));
    expect_polychord_invariants(f, r);
  }
}

TEST(PolyChords, GridRowChordKeepsItsSides) {
  // The chord along row j of a grid: side 0 loopy edges all on one horizontal line, side 1 on
  // the other, and the medial curve at height j + 1/2.
  const Fixture f = make_fixture("grid", make_grid(4, 3, 4.0, 3.0));
  const PolyChordResult r = chords_of(f);
  Index rows = 0;
  for (const PolyChord& ch : r.chords) {
    const std::vector<Vec3> medial = medial_curve(f.mesh, f.conn, ch);
    ASSERT_EQ(medial.size(), ch.opposing_edges.size());
    const bool is_row = std::abs(medial.front().y() - medial.back().y()) < 1e-12;
    if (!is_row) continue;
    ++rows;
    ASSERT_EQ(ch.size(), 4u);
    for (const Vec3& p : medial) EXPECT_NEAR(p.y(), medial.front().y(), 1e-12);
    EXPECT_NEAR(std::fmod(medial.front().y(), 1.0), 0.5, 1e-12);
    for (int side = 0; side < 2; ++side) {
      double y = -1;
      for (const auto& l : ch.loopy_edges) {
        const auto& v = f.conn.edge_vertices[l[side]];
        const double y0 = f.mesh.positions[v[0]].y(), y1 = f.mesh.positions[v[1]].y();
        EXPECT_EQ(y0, y1);
        if (y < 0) y = y0;
        EXPECT_EQ(y0, y) << "side " << side << " leaves its line";
      }
    }
  }
  EXPECT_EQ(rows, 3u);
}

TEST(PolyChords, TorusHasNPlusMClosedChords) {
  const Fixture f = make_fixture("torus", make_torus(8, 5));
  const PolyChordResult r = chords_of(f);
  ASSERT_EQ(r.chords.size(), 13u);
  EXPECT_EQ(r.num_closed, 13u);
  std::map<std::pair<bool, Index>, Index> expected{{{true, 8}, 5}, {{true, 5}, 8}};
  EXPECT_EQ(length_histogram(r), expected);
  for (const PolyChord& c : r.chords) EXPECT_EQ(c.opposing_edges.size(), c.quads.size());
  expect_polychord_invariants(f, r);
}

TEST(PolyChords, CylinderHasOpenAxialAndClosedRingChords) {
  // n = 7 around, m = 4 along: 7 open chords of 4 quads along the axis, 4 closed rings of 7.
  const Fixture f = make_fixture("cylinder", make_cylinder(7, 4));
  const PolyChordResult r = chords_of(f);
  ASSERT_EQ(r.chords.size(), 11u);
  EXPECT_EQ(r.num_closed, 4u);
  std::map<std::pair<bool, Index>, Index> expected{{{false, 4}, 7}, {{true, 7}, 4}};
  EXPECT_EQ(length_histogram(r), expected);
  EXPECT_EQ(r.stats.ends_at_boundary, 14u);
  expect_polychord_invariants(f, r);
}

TEST(PolyChords, CubeHas3kClosedChords) {
  for (Index k : {1u, 2u, 3u, 5u}) {
    const Fixture f = make_fixture("cube", make_cube(k));
    const PolyChordResult r = chords_of(f);
    SCOPED_TRACE(k);
    ASSERT_EQ(r.chords.size(), 3 * k);
    EXPECT_EQ(r.num_closed, 3 * k);
    for (const PolyChord& c : r.chords) EXPECT_EQ(c.size(), 4 * k);  // a ring round four sides
    expect_polychord_invariants(f, r);
  }
}

TEST(PolyChords, VaseChordsEndAtTheTriangleFanAndTheLid) {
  // make_demo_vase(6, 2): 6 quads around × 2 rings, a 6-triangle fan round the bottom pole and a
  // hexagonal lid. Every column is an open chord of 2 quads from a fan triangle to the lid; each
  // ring is a closed chord of 6 quads. 6 + 2 = 8 chords.
  const Fixture f = make_fixture("vase", make_demo_vase(6, 2));
  const PolyChordResult r = chords_of(f);
  ASSERT_EQ(r.chords.size(), 8u);
  std::map<std::pair<bool, Index>, Index> expected{{{false, 2}, 6}, {{true, 6}, 2}};
  EXPECT_EQ(length_histogram(r), expected);
  EXPECT_EQ(r.stats.ends_at_triangle, 6u);
  EXPECT_EQ(r.stats.ends_at_polygon, 6u);
  EXPECT_EQ(r.stats.ends_at_boundary, 0u);
  for (const PolyChord& c : r.chords) {
    if (c.closed) continue;
    const std::array<ChordEnd, 2> ends = c.ends;
    EXPECT_TRUE((ends[0] == ChordEnd::Triangle && ends[1] == ChordEnd::Polygon) ||
                (ends[0] == ChordEnd::Polygon && ends[1] == ChordEnd::Triangle));
  }
  // Only the 6 fan spokes (pole to ring 0) touch no quad.
  Index chordless = 0;
  for (Index e = 0; e < f.conn.num_edges; ++e) chordless += r.edge_chord[e] == kInvalidIndex;
  EXPECT_EQ(chordless, 6u);
  expect_polychord_invariants(f, r);
}

TEST(PolyChords, ValenceFiveStarWithTriangleAndPentagon) {
  // Hand count in make_star5_with_triangle_and_pentagon(): 5 chords of 2 quads, all open; the
  // triangle and the pentagon each end one chord; 6 edges (2 of the triangle, 4 of the
  // pentagon) touch no quad.
  const Fixture f = make_fixture("star5", make_star5_with_triangle_and_pentagon());
  const PolyChordResult r = chords_of(f);
  ASSERT_EQ(r.chords.size(), 5u);
  for (const PolyChord& c : r.chords) {
    EXPECT_FALSE(c.closed);
    EXPECT_EQ(c.size(), 2u);
    EXPECT_EQ(c.opposing_edges.size(), 3u);
    EXPECT_NE(c.quads[0], c.quads[1]);
  }
  EXPECT_EQ(r.stats.ends_at_boundary, 8u);
  EXPECT_EQ(r.stats.ends_at_triangle, 1u);
  EXPECT_EQ(r.stats.ends_at_polygon, 1u);
  EXPECT_EQ(r.stats.num_quad_edges, 15u);  // 5 spokes + 10 rim edges
  Index chordless = 0;
  for (Index e = 0; e < f.conn.num_edges; ++e) chordless += r.edge_chord[e] == kInvalidIndex;
  EXPECT_EQ(chordless, 6u);
  // Each spoke is the middle opposing edge of its chord.
  for (const PolyChord& c : r.chords) {
    const auto& v = f.conn.edge_vertices[c.opposing_edges[1]];
    EXPECT_TRUE(v[0] == 0 || v[1] == 0) << "the middle edge is a spoke at O";
  }
  expect_polychord_invariants(f, r);
}

TEST(PolyChords, SelfCrossingChordPassesThroughTheCentreQuadTwice) {
  // make_self_crossing(9): see the sketch in topology_test_util.h. Hand count: the self-crossing
  // chord (3 + 9 + 3 = 15 quads, 16 opposing edges), rows 0 and 2, columns 0 and 2 (3 quads
  // each), 9 one-quad chords across the bridge: 14 chords.
  const Fixture f = make_fixture("self_crossing", make_self_crossing(9));
  const PolyChordResult r = chords_of(f);
  ASSERT_EQ(r.chords.size(), 14u);
  EXPECT_EQ(r.num_self_crossing, 1u);
  std::map<std::pair<bool, Index>, Index> expected{{{false, 15}, 1}, {{false, 3}, 4}, {{false, 1}, 9}};
  EXPECT_EQ(length_histogram(r), expected);
  const auto it = std::find_if(r.chords.begin(), r.chords.end(), [](const PolyChord& c) { return c.self_crossing; });
  ASSERT_NE(it, r.chords.end());
  const PolyChord& ch = *it;
  EXPECT_FALSE(ch.closed);
  EXPECT_EQ(ch.opposing_edges.size(), 16u);
  // Walked from the south end (face 1 is grid cell (1,0)): (1,0), X, (1,2), bridge quads 8…0,
  // (2,1), X, (0,1). Grid cell (i,j) is face 3j + i, bridge quad t is face 9 + t.
  std::vector<Index> quads{1, 4, 7};
  for (Index t = 9; t-- > 0;) quads.push_back(9 + t);
  quads.insert(quads.end(), {5, 4, 3});
  EXPECT_EQ(ch.quads, quads);
  // X's two passes use its two different directions.
  EXPECT_NE(ch.entry_corners[1], ch.entry_corners[13]);
  EXPECT_NE(ch.entry_corners[1], f.conn.opposite_corner_in_quad(ch.entry_corners[13]));
  expect_polychord_invariants(f, r);
}

TEST(PolyChords, NonManifoldSpineEndsThreeChords) {
  // make_book3(): three quads on one spine. 6 chords of 1 quad; the spine is the end edge of the
  // three chords that cross the pages.
  const Fixture f = make_fixture("book3", make_book3());
  const PolyChordResult r = chords_of(f);
  ASSERT_EQ(r.chords.size(), 6u);
  EXPECT_EQ(r.stats.ends_at_nonmanifold, 3u);
  EXPECT_EQ(r.stats.ends_at_boundary, 9u);
  EXPECT_EQ(r.stats.num_shared_end_edges, 1u);
  expect_polychord_invariants(f, r);
}

TEST(PolyChords, MoebiusBandIsOneClosedChordAlongAndOneAcrossPerQuad) {
  const Fixture f = make_fixture("moebius", make_moebius(12));
  const PolyChordResult r = chords_of(f);
  ASSERT_EQ(r.chords.size(), 13u);
  EXPECT_EQ(r.num_closed, 1u);
  bool wrap_flip = false;
  for (const PolyChord& c : r.chords) {
    if (!c.closed) {
      EXPECT_EQ(c.size(), 1u);
      continue;
    }
    EXPECT_EQ(c.size(), 12u);
    const std::vector<Vec3> normals = chord_quad_normals(f.mesh, f.conn, c, &wrap_flip);
    // Consecutive signed normals agree (a smooth band) although the faces cannot be oriented.
    for (Index i = 0; i + 1 < c.size(); ++i) EXPECT_GT(normals[i].dot(normals[i + 1]), 0.5);
  }
  EXPECT_TRUE(wrap_flip);
  expect_polychord_invariants(f, r);
}

TEST(PolyChords, InvariantsOnEveryGeneratedMesh) {
  for (const Fixture& f : generated_fixtures()) expect_polychord_invariants(f, chords_of(f));
}

TEST(PolyChords, DeterministicAndOrderedByFirstCorner) {
  const Fixture f = make_fixture("vase", make_demo_vase(12, 7));
  const PolyChordResult a = chords_of(f), b = chords_of(f);
  ASSERT_EQ(a.chords.size(), b.chords.size());
  for (Index i = 0; i < a.chords.size(); ++i) {
    EXPECT_EQ(a.chords[i].quads, b.chords[i].quads);
    EXPECT_EQ(a.chords[i].opposing_edges, b.chords[i].opposing_edges);
  }
  EXPECT_EQ(a.edge_chord, b.edge_chord);
}

TEST(PolyChords, InvariantsOnCorpusSample) {
  Index loaded = 0;
  for (const std::string& file : corpus_sample()) {
    PolyMesh mesh;
    if (!load_corpus(file, mesh)) continue;
    ++loaded;
    const Fixture f = make_fixture(file, std::move(mesh));
    const PolyChordResult r = chords_of(f);
    expect_polychord_invariants(f, r);
    EXPECT_GT(r.chords.size(), 0u);
  }
  if (loaded == 0) GTEST_SKIP() << "corpus not found";
}

TEST(PolyChords, CorpusSuzanneCounts) {
  // blender_suzanne.obj (Blender's built-in monkey): counts recorded from this implementation
  // and cross-checked against the invariants above; a change here means the extraction changed.
  PolyMesh mesh;
  if (!load_corpus("blender_suzanne.obj", mesh)) GTEST_SKIP() << "corpus not found";
  const Fixture f = make_fixture("suzanne", std::move(mesh));
  const PolyChordResult r = chords_of(f);
  EXPECT_EQ(r.chords.size(), 77u);
  EXPECT_EQ(r.num_closed, 25u);
  EXPECT_EQ(r.num_self_crossing, 2u);
  EXPECT_EQ(r.stats.ends_at_boundary + r.stats.ends_at_triangle, 2 * r.stats.num_open);
}
