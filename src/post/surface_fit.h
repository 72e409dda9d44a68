// quadlod — the final fit of the output's vertices to the input surface (issue 24; docs/cluster_collapse.md,
// "Surface fit").
//
// The collapse places every cluster by its quadric (volume-constrained where it can, Lindstrom &
// Turk 1998): that minimises the vertex's distances to the input's planes, not the distance
// between the two surfaces, which is what Chamfer and Hausdorff measure and what a posed LOD
// carries into every frame (on the ram at 0.2 the per-frame Chamfer was 4.8 % above Single's
// while the bind-pose Chamfer tied). The fit moves each output vertex a few damped Gauss–Newton
// steps on the two-sided Chamfer energy between the output and the input:
//
//   E = Σ_{s on output} w_s d(s, M_in)² + Σ_{a on input} w_a d(a, M_out)²,
//
// fixed samples (4 barycentric points of every output fan triangle, 1 or 4 of every input one,
// weights = area share) whose residuals
// are spread onto the triangle's corners by their barycentric coordinates; each vertex moves by
// the weighted mean of its residuals (a lumped step, which does not overshoot when neighbours move together). Connectivity, UVs and
// every other attribute stay as they are; a step that would turn an incident face by more than
// `max_turn_deg`, shrink it below `min_area_ratio` of its area, or turn it away from the way it
// faced before the fit (a flip), or leave it facing away from the input surface by eval's rule
// (docs/metrics.md §6b), is undone for the face's vertices, and no vertex moves farther
// than `max_step_edge_fraction` of its shortest edge in one step.
#pragma once

#include "quadlod/mesh.h"

#include <cstdint>
#include <vector>

namespace quadlod {

struct SurfaceReference;  // post/cluster_collapse.h
struct FeatureReference;  // post/cluster_collapse.h
struct FeatureEdges;      // mesh/features.h
struct Connectivity;      // mesh/connectivity.h
struct VertexMirror;      // mesh/symmetry.h

/// The strict lines the fit keeps its vertices on (SurfaceFitParams::lines).
struct FitLines {
  /// Per output vertex: the kinds (FeatureBit) of the strict line it may slide along, 0 = none.
  std::vector<std::uint8_t> vertex_kinds;
  /// Per output vertex: 1 = a corner of the strict lines (a junction, an end, a change of kind),
  /// which does not move.
  std::vector<std::uint8_t> corners;
  /// Output edges on strict lines, with their kinds.
  struct Edge {
    Index v, w;
    std::uint8_t kinds;
  };
  std::vector<Edge> edges;
  /// The input's strict lines by kind (borrowed).
  const FeatureReference* reference = nullptr;
  /// ClusterCollapseParams::feature_tolerance: eval's seams_torn rule.
  double line_tolerance = 0.2;
};

struct SurfaceFitParams {
  /// Gauss–Newton steps (0 = no fit). Measured on the ram and the corpus at 0.4 (docs/benchmarks/fig10-2026-12-03.md).
  int iterations = 4;
  /// Samples per output fan triangle: 4 (its centroid and its midpoint sub-triangles') or 1 (the
  /// centroid).
  int output_points = 4;
  /// Weight of a peak vertex as a sample of E: a vertex farther from the input than every sample
  /// of its fan triangles weighs this times a third of their area (the face samples weigh their
  /// area). 0 = face samples only. It trades Chamfer for Hausdorff about one for one (corpus,
  /// 0.25: Hausdorff −1.4 to −4.3 %, Chamfer +2.0 to +4.5 %; docs/cluster_collapse.md), so it is
  /// off by default.
  double vertex_weight = 0.0;
  /// Fraction of the computed move that is made (damping; 1 = the full lumped step).
  double step = 1.0;
  /// A vertex moves at most this fraction of its shortest incident edge per step, so no face can
  /// degenerate in one step.
  double max_step_edge_fraction = 0.25;
  /// A sample whose closest point is farther than this multiple of its triangle's longest edge
  /// belongs to another part (an eye in its socket, a leg against the body) and is not used.
  double max_residual_edge_multiple = 1.0;
  /// A residual shorter than this fraction of its triangle's longest edge counts as zero (it
  /// still weighs in the vertex's mean): closest points carry rounding (1e-19 on a flat grid,
  /// where the fit otherwise moved 504 of a 250k-face LOD's vertices by that and wrote
  /// "2.1e-19" for 0), and a millionth of an edge is below float32's resolution of it.
  double min_residual_edge_fraction = 1e-6;
  /// An incident face may turn by at most this angle (degrees) in one step; against its normal
  /// before the fit it may turn by anything short of a flip (90°).
  double max_turn_deg = 30.0;
  /// The Hausdorff guard: a step may not leave a vertex farther from the input than it was
  /// before the fit, or than this fraction of the farthest point before the fit (the longest
  /// residual of the first step, either direction, or vertex distance), whichever is more. 1: no
  /// vertex ends farther from the input than the Hausdorff distance the fit started from.
  double max_vertex_distance_fraction = 1.0;
  /// An incident face keeps at least this fraction of its area before the step.
  double min_area_ratio = 0.5;
  /// The orientation guard (docs/metrics.md §6b, as the collapse applies it): a face that faced
  /// the input before the fit must still face it, with this slack (× the input's longest bbox
  /// side; ClusterCollapseParams::orientation_tolerance, half of eval's).
  double orientation_tolerance = 5e-4;
  /// Per output vertex, 1 = it does not move (the pipeline passes the corners of the strict
  /// feature lines: junctions, ends, a change of kind). nullptr or empty: every vertex may move.
  const std::vector<std::uint8_t>* fixed_vertices = nullptr;
  /// The strict feature lines of the output (issue 32: boundaries, non-manifold edges, UV seams,
  /// material borders, which eval holds to the input's: `seams_torn`, docs/metrics.md §6c). A
  /// vertex on one slides along it, never off it: its step is projected onto the input's lines
  /// of its kinds (`reference`), and a step after which an output line edge leaves the input line
  /// by more than `line_tolerance` of its length (sampled at ¼, ½, ¾, as eval samples it) is
  /// undone for the edge's vertices. nullptr: no line constraint.
  const FitLines* lines = nullptr;
  /// An output with a face of more corners than this is not fitted (a large n-gon's fan
  /// triangles are not its surface; the fit over a 50 000-corner fan took 75 s).
  Index max_face_corners = 32;
  int threads = 0;
  /// Evaluate E once more after the last step (energy_after). The pipeline does not: it is a
  /// whole evaluation, a fifth of the fit's queries, for a figure of the report.
  bool measure_after = true;
  /// make_surface_reference(input, threads), borrowed (the run's: its BVH is ~5 % of a 1M-face
  /// run); nullptr: built here.
  const SurfaceReference* surface = nullptr;

  // --- symmetry (issue 34; docs/symmetry.md) ---------------------------------------------------
  /// The output's mirror pairs (borrowed; partner per output vertex, positions already exact
  /// mirrors); nullptr: none. Each step then moves a pair by the mean of its own step and the
  /// reflection of its partner's (a vertex on the plane only within it), a pair with a fixed
  /// vertex stays, and any guard that undoes one vertex's move undoes its partner's too, so the
  /// output stays exactly mirrored.
  const VertexMirror* mirror = nullptr;
};

struct SurfaceFitResult {
  double energy_before = 0.0;  ///< E at the start (input units², area-weighted means summed)
  double energy_after = 0.0;   ///< E at the end, with the same samples (measure_after; else 0)
  double energy_last_step = 0.0;  ///< E at the start of the last step taken
  int steps = 0;               ///< steps taken (fewer than asked once a step moves nothing)
  Index moved_vertices = 0;    ///< vertices whose position changed
  Index refused_moves = 0;     ///< vertex moves undone by any guard (summed over steps)
  Index refused_far = 0;       ///< of those, by the Hausdorff guard (max_vertex_distance_fraction)
  Index refused_line = 0;      ///< of those, because a line edge would leave its input line
  double start_reach = 0.0;    ///< the farthest point before the fit, as the guard measures it
};

/// The strict lines of `output` (features from find_feature_edges on `conn`) and its UV seams, as
/// the fit keeps them: a vertex on exactly two such edges of the same kinds slides along them; any
/// other vertex on one is a corner. `reference`: the input's lines (borrowed).
FitLines fit_lines(const PolyMesh& output, const Connectivity& conn, const FeatureEdges& features,
                   const FeatureReference& reference);

/// Fits output.positions to the surface of `input` (both pass check_layout(); faces of any
/// degree, fan-triangulated). Deterministic for any thread count.
SurfaceFitResult fit_to_surface(const PolyMesh& input, PolyMesh& output, const SurfaceFitParams& params = {});

}  // namespace quadlod
