// Feature edges and UV islands (issue 7): the lines a reduction must not tear, merge or move away.
//
// An input edge is a *feature edge* when one of these holds (several may):
//   * open boundary — used by exactly one face;
//   * non-manifold — used by more than two faces;
//   * UV seam — in some UV set, the two faces' corners at either endpoint carry different UV
//     values (compared by value, so duplicate pool entries with equal values are not a seam), or
//     one side has a UV and the other has none;
//   * normal seam — the per-corner normals differ across the edge in the same sense;
//   * material border — the two faces have different `face_material`;
//   * hard edge — dihedral angle >= hard_angle_deg, or (when smoothing groups are present) the
//     faces lie in different smoothing groups; smoothing off (group 0, flat shading) counts as a
//     group of its own, so flat | smooth is hard and flat | flat only by its dihedral angle.
// Only manifold interior edges can be seams, borders or hard edges; boundary and non-manifold
// edges carry their own bit.
//
// *Strict* features (boundary, non-manifold, UV seam, material border) separate things that
// must stay separate: two strict feature points may only merge when they are neighbours along one
// strict line, otherwise a seam would tear (one island's UVs meeting another's off their common
// seam), a hole would be pinched shut, a thin open part would vanish, or two materials would meet
// along a border the input does not have. Exception: the seams of a per-face UV layout (most faces
// alone in their island) are not strict: such a mesh must lose islands to be reduced at all.
// Hard edges and normal seams are *placement* features: a merged vertex that touches one such
// line stays on it, but two such lines may merge (a bevel between two creases may collapse at a
// coarse LOD). The measurements behind this split are in docs/attributes.md.
//
// Feature *lines* are maximal chains of feature edges between feature corners. A vertex is a
// feature corner when its number of incident feature edges is not 2 (an endpoint or a junction),
// or when its two feature edges have different bits (a seam turning into a boundary), or when
// they meet at a turn sharper than corner_angle_deg (a corner of a hard-surface outline).
// A closed feature loop without any corner is one line; its smallest vertex counts as a corner so
// that every line has an endpoint to anchor to.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace quadlod {

enum FeatureBit : std::uint8_t {
  kFeatureBoundary = 1u << 0,
  kFeatureNonManifold = 1u << 1,
  kFeatureUvSeam = 1u << 2,
  kFeatureNormalSeam = 1u << 3,
  kFeatureMaterialBorder = 1u << 4,
  kFeatureHardEdge = 1u << 5,
};
/// Features that must never be merged with a different feature line (see above).
inline constexpr std::uint8_t kStrictFeatures =
    kFeatureBoundary | kFeatureNonManifold | kFeatureUvSeam | kFeatureMaterialBorder;
inline constexpr std::uint8_t kAllFeatures = 0x3f;

struct FeatureParams {
  /// Manifold edges with a dihedral angle of at least this many degrees are hard edges. 60° is
  /// the paper's epsilon_theta (§3.2.2), the angle it uses for sharp breakpoints.
  double hard_angle_deg = 60.0;
  /// Use OBJ smoothing groups (`s`) when the mesh has them.
  bool smoothing_groups = true;
  /// Two feature edges meeting at a vertex turn by more than this many degrees: the vertex is a
  /// feature corner and may not move.
  double corner_angle_deg = 45.0;
  /// Which bits count at all (e.g. kStrictFeatures to ignore hard edges).
  std::uint8_t enabled = kAllFeatures;
  /// Which bits are strict (never merged with another line; see above).
  std::uint8_t strict = kStrictFeatures;
  /// A UV set in which more than this fraction of the faces are alone in their island is a
  /// per-face layout (the OpenSubdiv cages): it can only be reduced by letting islands vanish, so
  /// its seams are placement seams, not strict ones. Corpus: 1.00 on the two cages, at most 0.06
  /// on every other mesh (docs/attributes.md).
  double per_face_layout_fraction = 0.5;
};

struct FeatureEdges {
  std::vector<std::uint8_t> edge_bits;           ///< per Connectivity edge, OR of FeatureBit
  std::vector<std::uint32_t> edge_uv_seam_sets;  ///< per edge: bit k = seam in UV set k (k < 32)
  std::vector<std::uint8_t> vertex_bits;         ///< per vertex, OR over its incident edges
  std::vector<Index> vertex_valence;             ///< per vertex, number of incident feature edges
  std::vector<std::uint8_t> vertex_corner;       ///< per vertex, 1 = feature corner (see above)
  std::vector<Index> edge_line;  ///< per edge, its feature line; kInvalidIndex if no feature
  Index num_lines = 0;
  /// Edges carrying each bit (index = bit position), and feature edges / corners in total.
  std::array<Index, 6> edges_with_bit{};
  Index feature_edges = 0;
  Index corners = 0;
  /// Strictness (see above): per edge, and per vertex (on a strict edge); strict edges in total.
  std::vector<std::uint8_t> edge_strict, vertex_strict;
  Index strict_edges = 0;

  bool is_feature(Index e) const { return edge_bits[e] != 0; }
  bool is_strict(Index e) const { return edge_strict[e] != 0; }
  bool on_feature(Index v) const { return vertex_bits[v] != 0; }
  bool on_strict(Index v) const { return vertex_strict[v] != 0; }
};

/// Classifies every edge of `conn` (built from `mesh`). Linear in the corners.
FeatureEdges find_feature_edges(const PolyMesh& mesh, const Connectivity& conn,
                                const FeatureParams& params = {});

/// UV islands of one UV set: faces joined across manifold edges that are not seams of that set.
struct UvIslands {
  std::vector<Index> face_island;  ///< per face; kInvalidIndex when a corner of it has no UV
  Index num_islands = 0;
  std::vector<Vec2> uv_min, uv_max;  ///< UV bounding box of each island
  std::vector<double> area_3d;       ///< surface area of each island
};
/// Precondition: uv_set < mesh.uv_sets.size().
UvIslands find_uv_islands(const PolyMesh& mesh, const Connectivity& conn, Index uv_set);

}  // namespace quadlod
