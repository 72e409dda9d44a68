// The analysis stage: everything the ILP (§3.2) needs to know about the input before it decides
// which edges to keep — poly-chords (§3.1), their segments (§3.2.2), the loopy-edge clusters of
// the medial curves (§3.2.3) and the triangle-region clusters (§3.2.4).
//
//   PolyMesh + Connectivity ─► extract_polychords ─► segment_polychords      (Eq. 4)
//                                               └──► cluster_medial_curves   (Eqs. 5–6)
//                            ─► cluster_triangle_regions                     (Eqs. 7–8)
//
// `write_analysis_export` writes the result as coloured edge geometry for inspection in MeshLab
// or Blender (see its comment for the files).
#pragma once

#include "geometry/medial_clustering.h"
#include "geometry/triangle_clustering.h"
#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "topology/polychords.h"
#include "topology/segmentation.h"

#include <filesystem>
#include <string>

namespace quadlod {

struct AnalysisParams {
  PolyChordParams polychords;
  SegmentationParams segmentation;
  MedialClusteringParams medial;
  TriangleClusteringParams triangles;
  /// Compute the geometric clusters of §3.2.3–§3.2.4 (medial curves and triangle regions). Only
  /// the paper's objective (Eqs. 6–8) reads them; the shape objective skips them (they were
  /// 60–75 % of the analysis time on makehuman_base_body).
  bool clusters = true;
};

struct AnalysisTimings {
  double polychords_ms = 0.0;
  double segmentation_ms = 0.0;
  double medial_ms = 0.0;
  double triangles_ms = 0.0;
  double total_ms = 0.0;
};

struct AnalysisResult {
  PolyChordResult polychords;
  SegmentationResult segmentation;
  MedialClusteringResult medial;
  TriangleClusteringResult triangles;
  AnalysisTimings timings;  ///< wall-clock milliseconds per stage
};

/// Runs the four analysis stages in order (single-threaded). `conn` must be
/// build_connectivity(mesh).
AnalysisResult analyze(const PolyMesh& mesh, const Connectivity& conn, const AnalysisParams& params = {});

/// One line for logs and benchmarks:
/// "analysis: 5476 faces, 1930 chords, 5120 segments, 8000 quad clusters, 300 tri clusters in 84.1 ms"
std::string analysis_summary(const PolyMesh& mesh, const AnalysisResult& result);

/// Writes the analysis as coloured edge geometry into `dir` (created if missing):
///   mesh.ply, mesh.obj           the input mesh (faces), as context;
///   chords.ply / chords.obj      opposing edges, one colour / OBJ group `chord_N` per chord;
///   segments.ply / .obj          opposing edges, per segment (`segment_N`);
///   quad_clusters.ply / .obj     loopy edges, per medial cluster (`cluster_N`);
///   triangle_clusters.ply / .obj triangle-region edges, per cluster (`tricluster_N`).
/// PLY files hold every mesh vertex and an `edge` element (vertex1 vertex2 red green blue);
/// colours come from a hash of the id, so neighbouring ids look different. An edge listed by two
/// chords / clusters appears twice. Files are written atomically. Returns an empty string on
/// success, else one line naming the file that failed.
std::string write_analysis_export(const PolyMesh& mesh, const Connectivity& conn,
                                  const AnalysisResult& result, const std::filesystem::path& dir);

}  // namespace quadlod
