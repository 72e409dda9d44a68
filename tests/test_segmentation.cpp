// Poly-chord segmentation (paper §3.2.2): breakpoints from each of the three criteria on meshes
// built to trigger exactly one of them, the side a breakpoint edge goes to, the ablation switch,
// and the segmentation invariants on generated and corpus meshes.
#include "topology/segmentation.h"

#include "topology_test_util.h"

#include <gtest/gtest.h>

#include <numbers>

using namespace quadlod;
using namespace quadlod::topo_test;

namespace {

struct SegRun {
  PolyChordResult chords;
  SegmentationResult seg;
};

SegRun run(const Fixture& f, const SegmentationParams& params = {}) {
  SegRun r;
  r.chords = extract_polychords(f.mesh, f.conn);
  r.seg = segment_polychords(f.mesh, f.conn, r.chords, params);
  expect_segmentation_invariants(f, r.chords, r.seg, params);
  return r;
}

constexpr double kDeg = std::numbers::pi / 180.0;

}  // namespace

TEST(Segmentation, FlatGridHasNoBreakpoints) {
  const Fixture f = make_fixture("grid", make_grid(6, 4));
  const SegRun r = run(f);
  EXPECT_TRUE(r.seg.breakpoints.empty());
  ASSERT_EQ(r.seg.segments.size(), r.chords.chords.size());
  for (const Segment& s : r.seg.segments) {
    EXPECT_EQ(s.first, 0u);
    EXPECT_EQ(s.opposing_edges, r.chords.chords[s.chord].opposing_edges);
  }
}

TEST(Segmentation, FoldAt90DegreesBreaksEveryChordCrossingTheFold) {
  // 6×4 unit grid folded by 90° about x = 3. The 4 chords along x cross the fold; their opposing
  // edge at x = 3 (position 3) has a 90° dihedral angle. The fold turns the normal about the
  // bi-normal axis, so the bi-normal does not change. 4 breakpoints, 6 + 2·4 = 14 segments.
  const Fixture f = make_fixture("fold", make_folded_grid(6, 4, 3, 90 * kDeg));
  const SegRun r = run(f);
  ASSERT_EQ(r.seg.breakpoints.size(), 4u);
  EXPECT_EQ(r.seg.stats.num_dihedral, 4u);
  EXPECT_EQ(r.seg.stats.num_binormal, 0u);
  EXPECT_EQ(r.seg.stats.num_self_intersection, 0u);
  EXPECT_EQ(r.seg.segments.size(), 14u);
  for (const Breakpoint& b : r.seg.breakpoints) {
    EXPECT_EQ(b.reasons, kBreakDihedral);
    EXPECT_EQ(b.position, 3u);
    for (Index v : f.conn.edge_vertices[b.edge]) {
      EXPECT_NEAR(f.mesh.positions[v].x(), 3.0, 1e-12);
      EXPECT_NEAR(f.mesh.positions[v].z(), 0.0, 1e-12);
    }
    // The breakpoint edge starts the second segment of its chord: {e0 e1 e2} | {e3 … e6}.
    const Index s0 = r.seg.chord_segment_begin[b.chord];
    ASSERT_EQ(r.seg.chord_segment_begin[b.chord + 1] - s0, 2u);
    EXPECT_EQ(r.seg.segments[s0].first, 0u);
    EXPECT_EQ(r.seg.segments[s0].last, 2u);
    EXPECT_EQ(r.seg.segments[s0 + 1].first, 3u);
    EXPECT_EQ(r.seg.segments[s0 + 1].last, 6u);
    EXPECT_EQ(r.seg.segments[s0 + 1].opposing_edges.front(), b.edge);
    EXPECT_EQ(r.seg.edge_segment[b.edge], s0 + 1);
  }
}

TEST(Segmentation, DihedralThresholdIsStrictAndUsesEpsilonTheta) {
  // Fold angle below / above ϵ_θ = 60°.
  EXPECT_EQ(run(make_fixture("fold45", make_folded_grid(6, 4, 3, 45 * kDeg))).seg.breakpoints.size(), 0u);
  EXPECT_EQ(run(make_fixture("fold70", make_folded_grid(6, 4, 3, 70 * kDeg))).seg.breakpoints.size(), 4u);
  SegmentationParams loose;
  loose.epsilon_theta = 80 * kDeg;
  EXPECT_EQ(run(make_fixture("fold70", make_folded_grid(6, 4, 3, 70 * kDeg)), loose).seg.breakpoints.size(), 0u);
  SegmentationParams no_dihedral;
  no_dihedral.use_dihedral = false;
  EXPECT_EQ(run(make_fixture("fold90", make_folded_grid(6, 4, 3, 90 * kDeg)), no_dihedral).seg.breakpoints.size(), 0u);
}

TEST(Segmentation, MitredTurnGivesOneBinormalBreakpoint) {
  // make_mitred_strip(): a flat strip whose chord turns 90° in the plane at the mitre edge
  // (position 3 of the 5-quad chord walked from Q0, position 2 walked from Qc; the extraction
  // walks it from Qc: its first unvisited corner is Q0's corner 1, and the backward walk from
  // there runs to the Qc end). Normals agree everywhere (no dihedral breakpoint); the
  // bi-normal turns from +y to -x.
  const Fixture f = make_fixture("mitre", make_mitred_strip());
  const SegRun r = run(f);
  ASSERT_EQ(r.seg.breakpoints.size(), 1u);
  const Breakpoint& b = r.seg.breakpoints[0];
  EXPECT_EQ(b.reasons, kBreakBinormal);
  const PolyChord& chord = r.chords.chords[b.chord];
  EXPECT_EQ(chord.size(), 5u);
  EXPECT_EQ(b.position, chord.quads.front() == 0 ? 3u : 2u);
  EXPECT_EQ(chord.quads.front(), 4u);
  const auto& v = f.conn.edge_vertices[b.edge];
  const Vec3 a = f.mesh.positions[v[0]], c = f.mesh.positions[v[1]];
  EXPECT_NEAR((a - c).norm(), std::sqrt(2.0), 1e-12) << "the mitre edge (4,0)-(3,1)";
  EXPECT_EQ(r.seg.segments.size(), 7u);  // 5 one-quad chords + the long one cut in two
}

TEST(Segmentation, TwistedStripGivesBinormalBreakpoints) {
  // A straight strip of 6 quads along x whose rungs (the opposing edges) are rotated about the
  // x axis by 0°, 0°, 0°, 0°, 150°, 150°, 150°. Quad 3 is twisted hard: its (Newell) normal is
  // ~75° from both neighbours', and so is its bi-normal (n × x): both criteria fire at the two
  // rungs of quad 3 (positions 3 and 4 counted from x = 0; the chord is walked from x = 6, so
  // positions 2 and 3), nowhere else.
  PolyMesh m;
  const double angles[7] = {0, 0, 0, 0, 150, 150, 150};
  for (int i = 0; i < 7; ++i) {
    const double a = angles[i] * kDeg;
    const Vec3 d(0, std::cos(a), std::sin(a));
    m.add_vertex(Vec3(i, 0, 0) - 0.5 * d);
    m.add_vertex(Vec3(i, 0, 0) + 0.5 * d);
  }
  for (Index i = 0; i < 6; ++i) m.add_face({2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1});
  const Fixture f = make_fixture("twist", std::move(m));
  const SegRun r = run(f);
  ASSERT_EQ(r.seg.breakpoints.size(), 2u);
  EXPECT_EQ(r.seg.stats.num_binormal, 2u);
  const PolyChord& chord = r.chords.chords[r.seg.breakpoints[0].chord];
  EXPECT_EQ(chord.quads.front(), 5u);
  EXPECT_EQ(r.seg.breakpoints[0].position, 2u);
  EXPECT_EQ(r.seg.breakpoints[1].position, 3u);
  for (const Breakpoint& b : r.seg.breakpoints) EXPECT_EQ(b.reasons, kBreakBinormal | kBreakDihedral);
}

TEST(Segmentation, SelfCrossingChordBreaksWhereItReentersVisitedVertices) {
  // make_self_crossing(9), walked from the south: positions 0..2 climb column 1 through X,
  // 3..12 go round the bridge, 13 = (2,1)-(2,2) and 14 = (1,1)-(1,2) are X's second pass: both
  // touch vertices of positions 1 and 2 (X's first pass). 15 = (0,1)-(0,2) touches nothing seen.
  // The mesh is flat and the bridge turns by 30° per quad: no geometric breakpoints.
  // Segments of that chord: [0..12], [13], [14..15].
  const Fixture f = make_fixture("self_crossing", make_self_crossing(9));
  const SegRun r = run(f);
  ASSERT_EQ(r.seg.breakpoints.size(), 2u);
  EXPECT_EQ(r.seg.stats.num_self_intersection, 2u);
  EXPECT_EQ(r.seg.stats.num_dihedral + r.seg.stats.num_binormal, 0u);
  const Index chord = r.seg.breakpoints[0].chord;
  EXPECT_TRUE(r.chords.chords[chord].self_crossing);
  EXPECT_EQ(r.seg.breakpoints[0].position, 13u);
  EXPECT_EQ(r.seg.breakpoints[1].position, 14u);
  const Index s0 = r.seg.chord_segment_begin[chord];
  ASSERT_EQ(r.seg.chord_segment_begin[chord + 1] - s0, 3u);
  EXPECT_EQ(r.seg.segments[s0].last, 12u);
  EXPECT_EQ(r.seg.segments[s0 + 1].first, 13u);
  EXPECT_EQ(r.seg.segments[s0 + 1].last, 13u);
  EXPECT_EQ(r.seg.segments[s0 + 2].first, 14u);
  EXPECT_EQ(r.seg.segments[s0 + 2].last, 15u);
  EXPECT_EQ(r.seg.stats.num_single_edge_segments, 1u);  // {e13}; every other chord has >= 2 edges
}

TEST(Segmentation, CubeRingsBreakAtEveryCrease) {
  // k×k cube: each of the 3k rings (closed, 4k quads) crosses 4 creases of 90°. The fold is
  // about the opposing edge, so only the dihedral criterion fires: 4 breakpoints per ring and
  // 4 segments of k edges each (one per side; the one through the chord's start may wrap).
  for (Index k : {1u, 2u, 3u}) {
    const Fixture f = make_fixture("cube", make_cube(k));
    const SegRun r = run(f);
    SCOPED_TRACE(k);
    EXPECT_EQ(r.seg.stats.num_dihedral, 12 * k);
    EXPECT_EQ(r.seg.stats.num_binormal, 0u);
    EXPECT_EQ(r.seg.stats.num_self_intersection, 0u);
    ASSERT_EQ(r.seg.segments.size(), 12 * k);
    for (const Segment& s : r.seg.segments) {
      EXPECT_EQ(s.opposing_edges.size(), k);
      // A segment starts at a crease and covers the side after it: its edges after the first
      // are interior to one side, so their midpoints share one coordinate at ±1/2.
      const Vec3 first_mid = 0.5 * (f.mesh.positions[f.conn.edge_vertices[s.opposing_edges[0]][0]] +
                                    f.mesh.positions[f.conn.edge_vertices[s.opposing_edges[0]][1]]);
      EXPECT_NEAR(first_mid.cwiseAbs().maxCoeff(), 0.5, 1e-12);
      Index on_crease = 0;
      for (int axis = 0; axis < 3; ++axis) on_crease += std::abs(std::abs(first_mid[axis]) - 0.5) < 1e-12;
      EXPECT_EQ(on_crease, 2u) << "the first edge of a segment is a crease edge";
    }
  }
}

TEST(Segmentation, SmoothClosedChordsHaveNoBreakpoints) {
  // Torus 24×12: neighbouring quads turn by 15° / 30°; the Möbius band: its closed chord crosses
  // an inconsistently oriented edge where it closes, which must not read as a 180° fold.
  EXPECT_EQ(run(make_fixture("torus", make_torus(24, 12))).seg.breakpoints.size(), 0u);
  const SegRun moebius = run(make_fixture("moebius", make_moebius(12)));
  EXPECT_EQ(moebius.seg.stats.num_dihedral, 0u);
  EXPECT_EQ(moebius.seg.stats.num_binormal, 0u);
}

TEST(Segmentation, DisabledGivesOneSegmentPerChord) {
  SegmentationParams off;
  off.enable = false;
  for (const Fixture& f : generated_fixtures()) {
    const SegRun r = run(f, off);
    EXPECT_EQ(r.seg.segments.size(), r.chords.chords.size()) << f.name;
    EXPECT_TRUE(r.seg.breakpoints.empty()) << f.name;
  }
}

TEST(Segmentation, InvariantsOnEveryGeneratedMesh) {
  for (const Fixture& f : generated_fixtures()) run(f);
}

TEST(Segmentation, InvariantsOnCorpusSample) {
  Index loaded = 0;
  for (const std::string& file : corpus_sample()) {
    PolyMesh mesh;
    if (!load_corpus(file, mesh)) continue;
    ++loaded;
    const SegRun r = run(make_fixture(file, std::move(mesh)));
    EXPECT_GE(r.seg.segments.size(), r.chords.chords.size());
  }
  if (loaded == 0) GTEST_SKIP() << "corpus not found";
}
