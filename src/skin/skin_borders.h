// Joint-influence borders (issue 24; docs/skinning.md "Borders in the selection"): the edges a
// reduction must not collapse because their endpoints follow unrelated bones.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <cstdint>
#include <vector>

namespace quadlod {

struct SkinBorderParams {
  /// weight_distance() (total variation of the two weight vectors, in [0, 1]) above which an
  /// edge can be a border; SimplifyOptions::skin_border_distance.
  double max_weight_distance = 0.7;
  /// Parent per joint (kInvalidIndex: root); empty = distinct joints are never related.
  std::vector<Index> joint_parents;
};

struct SkinBorders {
  std::vector<std::uint8_t> edge_border;  ///< per Connectivity edge: 1 = keep it
  Index border_edges = 0;
  /// Edges whose weights differ by more than the distance but whose dominant joints are related
  /// (a rigid split at a knee): not borders.
  Index related_edges = 0;
};

/// An edge (a, b) is a border when weight_distance(a, b) > max_weight_distance and the dominant
/// joints of a and b (largest weight) differ and, when joint_parents is given, are not parent and
/// child. Vertices without
/// influences border nothing. Precondition: mesh.skin covers the mesh (not empty).
SkinBorders find_skin_borders(const PolyMesh& mesh, const Connectivity& conn, const SkinBorderParams& params);

}  // namespace quadlod
