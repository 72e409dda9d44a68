// Dual-graph repair of an edge selection (paper §3.3.1, Fig. 7).
//
// The ILP decides edges without seeing the dual graph M*. Its dual vertices are the input faces,
// its dual edges the input edges, its dual faces the input vertices. Collapsed edges merge dual
// faces: every cluster of input vertices joined by collapsed edges becomes one *super-face* f*,
// bounded by the kept edges that leave the cluster, i.e. one output vertex of that valence.
//
//      kept edges ═══, collapsed ───            super-face of cluster {a,b,c}:
//                                                8 boundary (kept) edges → a valence-8 vertex
//           ║   ║   ║
//        ═══a───b───c═══                          split along the dual path crossing b─c:
//           ║       ║                             {a,b} (5) and {c} (4): no super-face left
//
// A super-face with more than `max_valence` boundary edges is repaired:
//   1. erosion: a face of the super-face with exactly one kept edge (a dangling dual vertex) has
//      that edge collapsed too;
//   2. split: from the boundary face of highest valence (most kept edges), shortest paths through
//      the super-face's interior dual edges (its collapsed edges) reach the other boundary faces;
//      a step that leaves the poly-chord of the previous step costs `loop_change_penalty` extra,
//      so paths follow an edge loop. The path whose split gives the smallest larger half wins;
//      its collapsed edges become kept, which cuts the cluster in two.
// Both halves go back into the queue until no super-face remains, or none can be split (a cluster
// whose interior has no manifold edge, or whose every split leaves a half just as bad).
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "topology/polychords.h"

#include <cstdint>
#include <vector>

namespace quadlod {

struct DualRepairParams {
  /// Super-faces with more boundary edges than this are split (the paper's 6). A cluster that
  /// contains an input vertex of higher valence only has to get down to that vertex's valence.
  Index max_valence = 6;
  /// Extra path cost of a step that crosses an edge of a different poly-chord than the step
  /// before ("a high penalty when an edge does not follow the same edge loop").
  double loop_change_penalty = 10.0;
  /// Erode dangling dual vertices before splitting (step 1).
  bool erode = true;
  bool enable = true;  ///< false: the "w/o dual" ablation, the selection passes through unchanged
};

struct DualRepairStats {
  Index super_faces_found = 0;   ///< clusters above the limit before repair
  Index super_faces_left = 0;    ///< clusters still above the limit after repair
  Index splits = 0;
  Index eroded_edges = 0;        ///< kept edges collapsed by erosion
  Index restored_edges = 0;      ///< collapsed edges made kept by splits
  Index unsplittable = 0;        ///< super-faces for which no valid split exists
  Index max_valence_before = 0;
  Index max_valence_after = 0;
};

struct DualRepairResult {
  std::vector<std::uint8_t> edge_kept;  ///< the repaired selection, one entry per edge
  DualRepairStats stats;
  double seconds = 0.0;
};

/// Repairs `edge_kept` (one entry per Connectivity edge, 1 = kept). `chords` gives each edge's
/// poly-chord for the loop-following path cost (extract_polychords on the same mesh).
DualRepairResult repair_dual_graph(const PolyMesh& mesh, const Connectivity& conn,
                                   const PolyChordResult& chords,
                                   const std::vector<std::uint8_t>& edge_kept,
                                   const DualRepairParams& params = {});

/// Valence of every vertex cluster a selection produces: the number of distinct other clusters
/// its kept edges lead to (the valence of the merged output vertex; kept edges that join the
/// same two clusters become one output edge). Indexed by vertex (a cluster shares the value).
std::vector<Index> cluster_valences(const Connectivity& conn, const std::vector<std::uint8_t>& edge_kept);

}  // namespace quadlod
