// Dual-graph repair (§3.3.1) on hand-made selections with known super-faces.
#include "post/dual_repair.h"
#include "quadlod/generators.h"
#include "topology/polychords.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace quadlod;

namespace {

Index edge_between(const Connectivity& conn, Index a, Index b) {
  for (Index e = 0; e < conn.num_edges; ++e)
    if (conn.edge_vertices[e] == std::array<Index, 2>{std::min(a, b), std::max(a, b)}) return e;
  return kInvalidIndex;
}

Index max_valence(const Connectivity& conn, const std::vector<std::uint8_t>& kept) {
  const auto v = cluster_valences(conn, kept);
  return *std::max_element(v.begin(), v.end());
}

}  // namespace

TEST(DualRepair, SplitsARowOfThreeMergedVertices) {
  // 6×6 grid, vertices (i, j) → j*7 + i. Collapse (2,3)-(3,3) and (3,3)-(4,3): one cluster of
  // three interior vertices with 3 + 2 + 3 = 8 kept edges leaving it: a valence-8 super-face.
  const PolyMesh grid = make_grid(6, 6);
  const Connectivity conn = build_connectivity(grid);
  const PolyChordResult chords = extract_polychords(grid, conn);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  const Index e1 = edge_between(conn, 3 * 7 + 2, 3 * 7 + 3), e2 = edge_between(conn, 3 * 7 + 3, 3 * 7 + 4);
  kept[e1] = kept[e2] = 0;
  EXPECT_EQ(max_valence(conn, kept), 8u);

  const DualRepairResult r = repair_dual_graph(grid, conn, chords, kept);
  EXPECT_EQ(r.stats.super_faces_found, 1u);
  EXPECT_EQ(r.stats.super_faces_left, 0u);
  EXPECT_EQ(r.stats.splits, 1u);
  EXPECT_EQ(r.stats.restored_edges, 1u);
  EXPECT_EQ(r.stats.max_valence_before, 8u);
  EXPECT_EQ(r.stats.max_valence_after, 6u);
  // Exactly one of the two collapsed edges came back.
  EXPECT_EQ(int(r.edge_kept[e1]) + int(r.edge_kept[e2]), 1);
}

TEST(DualRepair, LeavesGoodSelectionsAlone) {
  const PolyMesh grid = make_grid(6, 6);
  const Connectivity conn = build_connectivity(grid);
  const PolyChordResult chords = extract_polychords(grid, conn);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  kept[edge_between(conn, 8, 9)] = 0;  // valence 6: fine
  const DualRepairResult r = repair_dual_graph(grid, conn, chords, kept);
  EXPECT_EQ(r.edge_kept, kept);
  EXPECT_EQ(r.stats.super_faces_found, 0u);
}

TEST(DualRepair, DisabledPassesThrough) {
  const PolyMesh grid = make_grid(6, 6);
  const Connectivity conn = build_connectivity(grid);
  const PolyChordResult chords = extract_polychords(grid, conn);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  kept[edge_between(conn, 23, 24)] = kept[edge_between(conn, 24, 25)] = 0;
  DualRepairParams params;
  params.enable = false;
  const DualRepairResult r = repair_dual_graph(grid, conn, chords, kept, params);
  EXPECT_EQ(r.edge_kept, kept);
  EXPECT_EQ(r.stats.max_valence_after, 8u);
}

TEST(DualRepair, LongChainIsSplitUntilNoSuperFaceRemains) {
  // Collapse a whole interior row of 5 edges: 6 vertices merge, 2·4 + 3 + 3 = 14... every split
  // must follow until all parts are at most 6.
  const PolyMesh grid = make_grid(8, 8);
  const Connectivity conn = build_connectivity(grid);
  const PolyChordResult chords = extract_polychords(grid, conn);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  for (Index i = 1; i < 7; ++i) kept[edge_between(conn, 4 * 9 + i, 4 * 9 + i + 1)] = 0;
  EXPECT_GT(max_valence(conn, kept), 6u);
  const DualRepairResult r = repair_dual_graph(grid, conn, chords, kept);
  EXPECT_EQ(r.stats.super_faces_left, 0u);
  EXPECT_LE(max_valence(conn, r.edge_kept), 6u);
  EXPECT_GE(r.stats.splits, 2u);
  // Repair only ever restores edges of the selection (erosion aside, which has nothing to do here).
  for (Index e = 0; e < conn.num_edges; ++e)
    if (kept[e]) {
      EXPECT_TRUE(r.edge_kept[e]);
    }
}

TEST(DualRepair, HighValenceInputVertexSetsItsClustersLimit) {
  // The demo vase's bottom pole has valence 12; collapsing one fan edge merges the pole with a
  // ring vertex: 11 other ring vertices + the ring vertex's upper neighbour = 12 distinct
  // neighbours (its two ring neighbours already are the pole's). The limit for that cluster is
  // the pole's own valence, so it is no super-face although 12 > 6.
  const PolyMesh vase = make_demo_vase(12, 4);
  const Connectivity conn = build_connectivity(vase);
  const PolyChordResult chords = extract_polychords(vase, conn);
  std::vector<std::uint8_t> kept(conn.num_edges, 1);
  const Index pole = vase.num_vertices() - 1;
  kept[edge_between(conn, 0, pole)] = 0;
  EXPECT_EQ(max_valence(conn, kept), 12u);
  const DualRepairResult r = repair_dual_graph(vase, conn, chords, kept);
  EXPECT_EQ(r.stats.super_faces_found, 0u);
  EXPECT_EQ(r.edge_kept, kept);
  // Also collapsing the ring vertex's upward edge (to vertex 12 of the next ring) adds 13, 23
  // and 24 as neighbours: 14 > 12, repaired back to at most the pole's 12.
  kept[edge_between(conn, 0, 12)] = 0;
  const Index before = max_valence(conn, kept);
  EXPECT_GT(before, 12u);
  const DualRepairResult r2 = repair_dual_graph(vase, conn, chords, kept);
  EXPECT_EQ(r2.stats.super_faces_found, 1u);
  EXPECT_EQ(r2.stats.super_faces_left, 0u);
  EXPECT_LE(r2.stats.max_valence_after, 12u);
  // And a selection that leaves the pole alone is not touched although 12 > 6.
  std::vector<std::uint8_t> all(conn.num_edges, 1);
  EXPECT_EQ(repair_dual_graph(vase, conn, chords, all).stats.super_faces_found, 0u);
}
