// Medial-curve clustering of loopy edges (paper §3.2.3, Fig. 6, Eqs. 5–6).
//
// For every poly-chord (the whole, unsegmented chord), the medial curve Γ = ⟨e_1 … e_m⟩ joins
// the midpoints of consecutive opposing edges: one medial edge per quad of the chord. The cluster
// C(e_i) of medial edge e_i starts as the two loopy edges of that quad (its two sides parallel to
// e_i). Γ is then simplified by greedy QEM edge collapse in order of increasing cost; collapsing
// e_i merges C(e_i) into the cluster of the neighbouring medial edge whose centre is nearer. The
// surviving clusters are what Eq. 6 asks the ILP to keep at least one edge of.
//
// One refinement of the paper's merge rule: when the normal criteria below forbid merging into
// the nearer neighbour but allow the farther one, the cluster joins the farther one (counted in
// `merged_into_farther`). With the literal rule a flat run that ends at a crease stays split in
// two, only because the cluster across the crease is the nearer one for the run's end edges
// (on a k×k cube every side of a ring would keep two clusters instead of one).
//
// Cost (a priority only, as in the paper): every curve vertex carries the sum of the Eq. 5
// quadrics (geometry/quadric.h, `edge_quadric`, w_n = edge length, w_f) of the original medial
// edges incident to it, with each edge's quad normal; collapsing ⟨a, b⟩ merges the two vertex
// quadrics and places the merged vertex at the point of segment [a, b] with the least error (at a
// or b for the first / last edge of an open curve, so its ends stay on the chord's end edges).
// The cost is that least error. The cluster normal n_f of a merged cluster is the average of its
// quads' unit normals (signs made consistent along the chord); it drives the stopping criteria.
//
// Stopping criteria. The paper names three and leaves the thresholds to its supplement; here each
// rejects one candidate collapse (the candidate stays, the next cheapest is tried; it is tried
// again when a neighbour changes) and is counted in the stats:
//   * spatial deviation: an original medial point would lie farther than
//     max_spatial_deviation · bbox_diagonal from the simplified medial edge that spans it;
//   * normal deviation: the angle between the two merging clusters' normals exceeds
//     max_normal_deviation;
//   * normal variation: some quad normal of the merged cluster deviates from the merged cluster
//     normal by more than max_normal_variation.
// Defaults were chosen by measurement on the corpus: docs/parameters.md, "Medial-curve
// clustering".
//
// Loopy edges that occur twice along one chord (a chord running alongside itself, e.g. the turns
// of a spiral) belong to the cluster of their first occurrence, so the clusters of one chord
// partition its distinct loopy edges. An edge is a loopy edge of at most two chords (one per side)
// and so lies in at most two clusters overall.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "topology/polychords.h"

#include <cstddef>
#include <numbers>
#include <vector>

namespace quadlod {

struct MedialClusteringParams {
  /// w_f of Eq. 5 (weight of the in-plane plane; w_n is the medial edge length).
  double w_f = 0.01;
  /// Spatial deviation limit, as a fraction of the bounding-box diagonal.
  double max_spatial_deviation = 0.01;
  /// Limit on the angle between the normals of two clusters that merge, radians.
  double max_normal_deviation = 20.0 * std::numbers::pi / 180.0;
  /// Limit on the angle between any quad normal of a cluster and the cluster normal, radians.
  double max_normal_variation = 30.0 * std::numbers::pi / 180.0;
};

struct EdgeCluster {
  std::vector<Index> edges;  ///< loopy edges, in walking order (side 0 before side 1 per quad)
  Index chord = kInvalidIndex;
  /// Quad positions of the chord covered by the cluster, inclusive; may wrap on a closed chord
  /// (first > last).
  Index first = 0;
  Index last = 0;
  Vec3 normal = Vec3::Zero();  ///< average of the quads' unit normals, normalised (n_f)
};

struct MedialClusteringStats {
  Index num_medial_edges = 0;             ///< = total chord length (one per quad step)
  Index num_collapses = 0;
  Index rejected_spatial_deviation = 0;   ///< per stopping criterion (first failing one counted)
  Index rejected_normal_deviation = 0;
  Index rejected_normal_variation = 0;
  Index merged_into_farther = 0;          ///< nearer neighbour forbidden, farther one taken
  Index duplicate_loopy_edges = 0;        ///< loopy edges seen again along the same chord
  Index empty_clusters_dropped = 0;       ///< clusters whose every edge was a duplicate
  Index largest_cluster = 0;              ///< most quads (medial edges) merged into one cluster
  /// Criterion checks that the O(1) bounds could not decide (a scan of the spanned points /
  /// the clusters' quads ran); a cost indicator only.
  std::size_t exact_spatial_checks = 0;
  std::size_t exact_normal_checks = 0;
};

struct MedialClusteringResult {
  std::vector<EdgeCluster> clusters;
  /// Clusters of chord c are [chord_cluster_begin[c], chord_cluster_begin[c+1]), along the chord.
  std::vector<Index> chord_cluster_begin;
  double bbox_diagonal = 0.0;  ///< the length the spatial threshold is relative to
  MedialClusteringStats stats;
};

/// Clusters the loopy edges of every chord. `chords` must come from extract_polychords on the
/// same mesh and connectivity. Each chord yields at least one cluster (a closed chord keeps at
/// least two medial edges). Cost per chord is O(m log m) plus the criterion checks, which touch
/// the quads of the two merging clusters.
MedialClusteringResult cluster_medial_curves(const PolyMesh& mesh, const Connectivity& conn,
                                             const PolyChordResult& chords,
                                             const MedialClusteringParams& params = {});

}  // namespace quadlod
