// Triangle-region clustering (paper §3.2.4, Eqs. 7–8).
//
// Triangles have no poly-chords, so their geometric constraints come from a QEM edge-collapse
// run on the edges that border triangles:
//   1. Regions: the edges that border a triangle, grouped into connected sets Γ_t by a
//      breadth-first search over shared vertices ("connected edges bordering triangular faces");
//      triangle patches that touch only at a vertex form one region, so that the collapse below,
//      which merges vertices, never joins clusters of two regions.
//   2. Every edge starts as its own cluster C_t(e) = {e}.
//   3. Greedy collapse in order of increasing cost Q(e) (standard face-based QEM, Garland &
//      Heckbert 1997): each vertex carries the sum of the plane quadrics (unit normal,
//      unweighted, so Q is a squared distance) of its incident faces — the triangles and also
//      the quads / n-gons that touch the region, so that the region's border sees the surrounding
//      surface; collapsing ⟨a, b⟩ merges the two endpoint classes into one vertex placed at the
//      point of segment [a, b] with the least summed error, and Q(e) is that error.
//      The collapse stops when the cheapest remaining cost exceeds
//      epsilon_tri = epsilon_tri_relative · bbox_diagonal² (the paper: "a threshold ϵ_tri
//      proportional to the squared bounding box diagonal"; default measured, docs/parameters.md).
//   4. A collapsed edge leaves Γ_t and its cluster joins the cluster of the remaining edge at the
//      merged vertex whose centre is nearest to the collapsed edge's centre. Edges that the merge
//      turns into loops (both ends in one vertex class: the parallel edges of a collapsed
//      triangle pair) are collapsed with it and join the same way. A collapse that would leave no
//      remaining edge at the merged vertex is rejected (counted), so every region keeps at least
//      one cluster.
//   5. Neighbour relation for Eqs. 7–8: two clusters are neighbours when an edge of one and an
//      edge of the other share a vertex (this includes two sides of one triangle, "adjacent
//      across a triangle").
//
// This is a clustering simulation on the edge graph, not a mesh decimation: no link condition,
// no fold-over checks, no topology update beyond the vertex classes.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <utility>
#include <vector>

namespace quadlod {

struct TriangleClusteringParams {
  /// ϵ_tri / bbox_diagonal²: collapses stop when the cheapest QEM cost exceeds
  /// epsilon_tri_relative · bbox_diagonal². At 0 only free collapses happen (flat patches,
  /// rulings of developable patches); a negative value disables collapsing, leaving every edge
  /// its own cluster. Default measured on the corpus: docs/parameters.md.
  double epsilon_tri_relative = 1e-5;
};

struct TriangleCluster {
  std::vector<Index> edges;  ///< mesh edges, sorted
  Index region = kInvalidIndex;
  /// The cluster's edge that was never collapsed (every other edge of the cluster was removed by
  /// a collapse and merged, directly or through others, into it).
  Index representative = kInvalidIndex;
};

struct TriangleClusteringStats {
  Index num_regions = 0;
  Index num_triangles = 0;
  Index num_region_edges = 0;      ///< |Γ_t| summed over regions, before clustering
  Index num_collapses = 0;         ///< edges removed by a chosen collapse
  Index num_loop_collapses = 0;    ///< parallel edges removed along with a collapse
  Index rejected_no_neighbour = 0; ///< collapses that would have left a vertex without edges
  Index largest_cluster = 0;
};

struct TriangleClusteringResult {
  std::vector<TriangleCluster> clusters;
  /// Neighbouring cluster pairs, both orders listed ((i, j) and (j, i)), sorted, no duplicates,
  /// no (i, i): Eq. 8 is written once per listed pair.
  std::vector<std::pair<Index, Index>> neighbours;
  /// For every mesh edge: its cluster, or kInvalidIndex when it borders no triangle.
  std::vector<Index> edge_cluster;
  /// For every mesh edge: its region, or kInvalidIndex.
  std::vector<Index> edge_region;
  double epsilon_tri = 0.0;  ///< the absolute threshold used (squared length units)
  TriangleClusteringStats stats;
};

/// Clusters the edges bordering triangles. Faces with exactly three corners are triangles;
/// n-gons are ignored (the paper's input has none). Cost O(E log E) for E region edges, plus the
/// neighbour lists.
TriangleClusteringResult cluster_triangle_regions(const PolyMesh& mesh, const Connectivity& conn,
                                                  const TriangleClusteringParams& params = {});

}  // namespace quadlod
