// quadlod — evaluation metrics of `quadlod eval INPUT OUTPUT` (paper §4.1 and beyond).
//
// The exact definitions, formulas and edge-case rules live in docs/metrics.md; this header is
// their contract. In short:
//   * both meshes are mapped by p ↦ s·(p − c), s = 1 / (longest side of the INPUT's bounding
//     box), c = the input bbox centre, so every distance below is in units of the input's
//     longest bbox side (paper §4.1: "normalized to a unit bounding box");
//   * distances are exact point-to-surface distances (BVH over the fan triangulation) measured
//     from area-weighted random surface samples (plus the mesh vertices, for Hausdorff only);
//   * QPR (Knodt 2025) with a documented rule for zero counts (`qpr_rule`);
//   * PCCD = Chamfer distance between the poly-chords' medial curves, sampled by arc length;
//   * flow deviation: angle between output quad edge directions and the closest input quad's;
//   * features (issue 7): torn UV seams / boundaries, UV islands, UV error, material borders and
//     feature-line deviation, from src/mesh/features.h on both meshes (docs/metrics.md §6c).
// Everything is deterministic for a fixed seed and independent of the thread count.
#pragma once

#include "quadlod/mesh.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>

namespace quadlod {

struct EvalParams {
  /// Surface samples per direction (N). 200000 gives a Chamfer standard error well below the
  /// paper's smallest reported values on the corpus meshes.
  std::uint64_t samples = 200000;
  /// Medial-curve samples per direction for PCCD (evenly spaced by arc length).
  std::uint64_t curve_samples = 100000;
  /// Seed of the sample generator (xoshiro256**; input stream 0, output stream 1).
  std::uint64_t seed = 1;
  /// Flow deviation only compares an output quad with an input quad whose planes are within
  /// this angle (unoriented normals); beyond it the sample does not count as covered.
  double flow_max_normal_angle_deg = 60.0;
  /// §6b: slack (normalised units, a fraction of the input's longest side) added to twice the
  /// distance of the nearest input surface before a face counts as flipped.
  double flip_tolerance = 1e-3;
  /// §6c: an output seam / boundary edge is *torn* when one of its sample points (at ¼, ½, ¾) is
  /// farther than feature_tolerance × (the edge's own length) from every input edge of the same
  /// kind. A chord of an input feature line whose endpoints lie on it deviates from it by at most
  /// tan(θ/4)/2 of its length (θ = the turn it cuts off), so 0.2 tolerates the chord error of
  /// cutting a turn of up to 43.6° — just under FeatureParams::corner_angle_deg (45°), beyond
  /// which a vertex is a feature corner and cutting it moves the feature.
  double feature_tolerance = 0.2;
  /// Hausdorff by branch and bound (src/eval/hausdorff_bound.h) when > 0: the largest distance
  /// found and a proven upper bound at most this far above it (normalised units), from every
  /// point of both surfaces instead of the random samples (no seed dependence). 0 (default): the
  /// maximum over the samples and the vertices, a lower bound. `eval --animation` uses 1e-5.
  double hausdorff_tolerance = 0.0;
  /// Worker threads for the distance queries; 0 = std::thread::hardware_concurrency().
  /// Results do not depend on it.
  unsigned threads = 0;
};

/// Face counts of one mesh as QPR sees them (tris = 3 corners, quads = 4, n-gons = 5+).
struct FaceCounts {
  std::uint64_t faces = 0;
  std::uint64_t tris = 0;
  std::uint64_t quads = 0;
  std::uint64_t ngons = 0;
  std::uint64_t tri_equivalent = 0;  ///< quad = 2, k-gon = k − 2 (paper §3.1)
};

struct EvalResult {
  /// Empty on success; otherwise why no metric could be computed (then all metrics are NaN/0).
  std::string error;
  bool ok() const { return error.empty(); }

  // --- normalisation ---------------------------------------------------------------------------
  double scale = 0.0;       ///< s = 1 / longest side of the input bbox (original units → metric units)
  double area_in = 0.0;     ///< surface area of the input after scaling
  double area_out = 0.0;    ///< surface area of the output after scaling

  // --- geometric distances (normalised units) ----------------------------------------------------
  double chamfer = 0.0;              ///< ½(mean_in_to_out + mean_out_to_in), plain distances
  double chamfer_sq = 0.0;           ///< ½(mean of d² in→out + mean of d² out→in)
  double mean_in_to_out = 0.0;       ///< mean over input samples of d(a, M_out)
  double mean_out_to_in = 0.0;       ///< mean over output samples of d(b, M_in)
  double hausdorff = 0.0;            ///< max(hausdorff_in_to_out, hausdorff_out_to_in)
  double hausdorff_in_to_out = 0.0;  ///< max over input samples and input vertices
  double hausdorff_out_to_in = 0.0;  ///< max over output samples and output vertices
  /// With EvalParams::hausdorff_tolerance > 0: hausdorff* above are the branch-and-bound values
  /// (attained distances), hausdorff_upper the proven bound on the true Hausdorff (≥ hausdorff,
  /// within the tolerance when hausdorff_converged).
  bool hausdorff_bounded = false;
  bool hausdorff_converged = false;
  double hausdorff_upper = 0.0;
  std::uint64_t hausdorff_queries = 0;  ///< nearest-point queries of the bound, both directions
  /// Where the bounded Hausdorff is attained, in the caller's units (not normalised), and on
  /// which surface: true = a point of the output (out → in), false = of the input.
  Vec3 hausdorff_point = Vec3::Zero();
  bool hausdorff_point_on_output = false;

  // --- quad preservation ---------------------------------------------------------------------------
  double qpr = 0.0;                 ///< Quad Preservation Ratio (Knodt 2025), see qpr_rule
  std::string qpr_rule;             ///< which case of docs/metrics.md §4 produced qpr
  double quad_fraction_in = 0.0;    ///< quads / faces of the input
  double quad_fraction_out = 0.0;   ///< quads / faces of the output
  FaceCounts counts_in;
  FaceCounts counts_out;

  // --- poly-chord Chamfer distance (PCCD, paper §4.1) -----------------------------------------
  double pccd = 0.0;            ///< ½(pccd_in_to_out + pccd_out_to_in) when defined
  bool pccd_defined = false;    ///< false when either mesh has no poly-chord (then see metrics.md §5)
  double pccd_in_to_out = 0.0;  ///< mean distance from input curve samples to the output curves
  double pccd_out_to_in = 0.0;
  std::uint64_t chords_in = 0;
  std::uint64_t chords_out = 0;
  double curve_length_in = 0.0;   ///< total medial-curve length (normalised units)
  double curve_length_out = 0.0;

  // --- flow deviation (beyond the paper) ---------------------------------------------------------
  double flow_deviation_deg = 0.0;      ///< mean over covered output samples; NaN when none
  double flow_deviation_p90_deg = 0.0;  ///< 90th percentile (nearest rank); NaN when none
  double flow_coverage = 0.0;           ///< covered output samples / all output samples

  // --- orientation (beyond the paper; validity) ---------------------------------------------------
  /// Output faces that face away from the input surface they lie on: the nearest input surface
  /// with the face's orientation (normals within 90°) is more than twice as far from the face's
  /// centroid as the nearest input surface, plus EvalParams::flip_tolerance (docs/metrics.md §6b).
  /// Faces that are unchanged input faces (same corner positions in the same order) are not
  /// replacements and are counted in flipped_faces_kept instead.
  std::uint64_t flipped_faces = 0;
  /// Unchanged input faces the same rule flags: the input itself is like that there (e.g. a
  /// folded quad whose fan triangles face away from its Newell normal). Input against itself:
  /// flipped_faces = 0 and flipped_faces_kept = the input's own count.
  std::uint64_t flipped_faces_kept = 0;

  // --- features, UVs, materials (issue 7; docs/metrics.md §6c) ------------------------------------
  /// UV islands of UV set 0 with non-zero 3D area (0 when the mesh has no UVs).
  std::uint64_t uv_islands_in = 0;
  std::uint64_t uv_islands_out = 0;
  /// Island correspondence (both meshes with UVs; else 0): every output fan triangle of positive
  /// area votes at its centroid for the input island it lies in (closest input point; the
  /// UV-nearest of the islands nearly as close). Vanished: input islands with area that no output
  /// triangle votes for (reduced away: allowed). Merged: output islands voting for two or more
  /// input islands (two charts joined, or a face spanning a seam: never allowed). Split: input
  /// islands two or more output islands vote for. Without merges,
  /// uv_islands_out = uv_islands_in − vanished + (extra pieces of split islands).
  std::uint64_t uv_islands_vanished = 0;
  std::uint64_t uv_islands_merged = 0;
  std::uint64_t uv_islands_split = 0;
  /// Output edges that are UV seams (any set) or open boundaries in the output and are not within
  /// feature_tolerance of an input edge of the same kind (see EvalParams::feature_tolerance).
  std::uint64_t seams_torn = 0;
  std::uint64_t seam_edges_in = 0, seam_edges_out = 0;          ///< UV seam edges (any set)
  std::uint64_t boundary_edges_in = 0, boundary_edges_out = 0;  ///< open boundary edges
  /// UV distance between an output sample's UV and the UV at its closest input point in the
  /// corresponding island, over that input island's UV bbox diagonal. NaN when either mesh has no
  /// UVs or no sample could be measured.
  double uv_error_mean = 0.0;
  double uv_error_max = 0.0;
  std::uint64_t uv_samples = 0;  ///< output samples that entered uv_error
  /// UV stretch of each mesh's first UV set (issue 32): Sander et al. 2001's L2 stretch of the
  /// map from UV to surface per fan triangle, times √(UV area / surface area) so that 1 is a map
  /// without distortion at any uniform scale and more is stretch or shear; its area-weighted
  /// median and 90th percentile over the surface (their mean is ruled by slivers of UV).
  /// Triangles without UVs or with no UV area are left out (uv_stretch_skipped_out counts the
  /// output's). NaN without UVs.
  double uv_stretch_median_in = 0.0, uv_stretch_median_out = 0.0;
  double uv_stretch_p90_in = 0.0, uv_stretch_p90_out = 0.0;
  std::uint64_t uv_stretch_skipped_out = 0;
  /// Distance (normalised units) from the sample points of output material-border edges to the
  /// nearest input border between the same two materials (by name): max and length-weighted mean.
  /// NaN when the output has no material border.
  double material_border_error = 0.0;
  double material_border_error_mean = 0.0;
  std::uint64_t material_border_edges_out = 0;
  /// Output samples whose face material (by name) differs from the input face's at the closest
  /// input point, over all output samples. NaN when neither mesh has per-face materials.
  double material_mismatch_fraction = 0.0;
  /// Distance from the sample points of all output feature edges (any kind, FeatureParams
  /// defaults) to the nearest input feature edge (any kind): max and length-weighted mean.
  /// NaN when the output has no feature edge.
  double feature_deviation_max = 0.0;
  double feature_deviation_mean = 0.0;
  std::uint64_t feature_edges_in = 0, feature_edges_out = 0;

  // --- provenance -----------------------------------------------------------------------------------
  std::uint64_t seed = 0;
  std::uint64_t samples_in = 0;          ///< surface samples drawn on the input
  std::uint64_t samples_out = 0;
  std::uint64_t vertex_samples_in = 0;   ///< input vertices used by a face (Hausdorff only)
  std::uint64_t vertex_samples_out = 0;
  std::uint64_t curve_samples_in = 0;
  std::uint64_t curve_samples_out = 0;
  std::uint64_t flow_samples = 0;        ///< covered output samples
  unsigned threads = 0;                  ///< worker threads used
  double seconds = 0.0;                  ///< wall time of evaluate()
  double seconds_distance = 0.0;         ///< sampling + BVH + surface distance queries
  double seconds_pccd = 0.0;             ///< chords + curve sampling + curve distances
  double seconds_features = 0.0;         ///< §6c: features, islands, UV and border queries
};

/// Computes every metric of `output` against `input` (docs/metrics.md). Preconditions: both
/// meshes pass PolyMesh::check_layout(); on a violation, a non-finite coordinate, an input with a
/// zero-size bounding box, or a mesh with zero surface area, returns a result whose `error` says
/// which (no exception). Deterministic for fixed params.seed; independent of params.threads.
EvalResult evaluate(const PolyMesh& input, const PolyMesh& output, const EvalParams& params = {});

/// QPR from face counts alone (docs/metrics.md §4); `rule` receives the case name.
double quad_preservation_ratio(const FaceCounts& in, const FaceCounts& out, std::string* rule = nullptr);

/// Face counts of a mesh (tris, quads, n-gons, triangle equivalents).
FaceCounts count_faces(const PolyMesh& mesh);

/// The result as a JSON object; NaN and ±inf become null. Keys are the field names above
/// (counts flattened as quads_in, tris_out, …).
nlohmann::json to_json(const EvalResult& result);

}  // namespace quadlod
