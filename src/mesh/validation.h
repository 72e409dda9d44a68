// Mesh statistics and validity checks (`quadlod info`, and the output checks of every stage that
// builds a mesh). Counts follow shared/corpus/stats.py where both define a quantity, so numbers
// can be compared with the corpus README.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace quadlod {

struct MeshStats {
  Index vertices = 0;          ///< all vertex records
  Index unused_vertices = 0;   ///< vertices no face uses
  Index faces = 0;
  Index triangles = 0;
  Index quads = 0;
  Index ngons = 0;             ///< faces with more than 4 corners
  std::uint64_t tri_equivalent = 0;  ///< quad = 2, k-gon = k - 2 (paper §3.1)
  Index max_face_degree = 0;
  std::map<Index, Index> faces_by_degree;  ///< degree → number of faces
  Index edges = 0;
  Index boundary_edges = 0;
  Index boundary_loops = 0;
  Index nonmanifold_edges = 0;     ///< edges with more than two incident faces
  Index nonmanifold_vertices = 0;  ///< see nonmanifold_vertices() in connectivity.h
  Index degenerate_faces = 0;      ///< repeated vertex index or zero area (either)
  Index repeated_index_faces = 0;  ///< faces that use one vertex twice
  Index zero_area_faces = 0;       ///< area <= zero_area_epsilon · bbox_diagonal²
  Index duplicate_faces = 0;       ///< faces whose vertex set equals an earlier face's
  Index zero_length_edges = 0;     ///< edges between two vertices <= zero_length_epsilon · bbox_diagonal apart
  Index components = 0;            ///< face components through shared edges
  Index nonfinite_vertices = 0;    ///< vertices with a NaN or infinite coordinate
  bool has_uvs = false;            ///< every corner has a UV in the first UV set
  Index uv_sets = 0;               ///< number of UV sets (texture coordinate layers)
  bool has_partial_uvs = false;    ///< some corners have a UV, some don't
  bool has_normals = false;
  Index materials = 0;
  Index groups = 0;
  BoundingBox bbox;
};

struct MeshStatsParams {
  /// A face is "zero area" when its area is at most this times the squared bbox diagonal.
  /// 1e-14 is ~100 ulps of a unit-scale area in double: exact collinear corners only.
  double zero_area_epsilon = 1e-14;
  /// An edge is "zero length" when its vertices are at most this times the bbox diagonal apart:
  /// the side of a square of zero_area_epsilon. Two distinct vertices on one point make a
  /// degenerate polygon side that no face-area test sees.
  double zero_length_epsilon = 1e-7;
};

MeshStats compute_stats(const PolyMesh& mesh, const Connectivity& conn,
                        const MeshStatsParams& params = {});

/// JSON object with the keys documented in README.md (`quadlod info --json`).
nlohmann::json to_json(const MeshStats& stats);

/// The `validity` object of `quadlod eval --json` (and of the Python module's evaluate()): the
/// output's counts, and the non-manifold edges it adds to the input's.
nlohmann::json validity_json(const MeshStats& output, const MeshStats& input);

/// Problems a pipeline stage cannot take as input. Empty when the mesh is acceptable.
/// Reports the first problem, naming the element: "vertex 17 has a non-finite coordinate".
std::string check_pipeline_input(const PolyMesh& mesh);

}  // namespace quadlod
