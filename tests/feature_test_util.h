// Shared fixtures of the feature and feature-metric tests: generated meshes with UV seams and
// materials at known places.
#pragma once

#include "quadlod/generators.h"
#include "quadlod/mesh.h"

#include <string>
#include <vector>

namespace quadlod::feature_test {

/// make_grid(n, m) whose faces in columns i >= split get their own UV pool entries shifted by
/// `shift` in u: the vertical line x = split/n becomes a UV seam (values differ across it) and
/// the grid has two UV islands, [0, split/n] × [0, 1] and [split/n + shift, 1 + shift] × [0, 1].
inline PolyMesh grid_with_seam_column(Index n, Index m, Index split, double shift) {
  PolyMesh g = make_grid(n, m);
  UvSet& uv = g.uv_sets[0];
  const Index base = static_cast<Index>(uv.values.size());
  for (Index k = 0; k < base; ++k) uv.values.push_back(uv.values[k] + Vec2(shift, 0.0));
  for (Index j = 0; j < m; ++j)
    for (Index i = split; i < n; ++i) {
      const Index f = j * n + i;
      for (Index c = g.face_begin(f); c < g.face_end(f); ++c) uv.corner[c] += base;
    }
  return g;
}

/// make_grid(n, m) with its own UV pool entry per corner: UV = position + (shift(face), 0). Faces
/// with equal shifts that share an edge are one island (equal values are not a seam); edges
/// between different shifts are seams.
template <class Shift>
PolyMesh grid_with_face_uvs(Index n, Index m, Shift&& shift) {
  PolyMesh g = make_grid(n, m);
  UvSet& uv = g.uv_sets[0];
  uv.values.clear();
  for (Index f = 0; f < g.num_faces(); ++f)
    for (Index c = g.face_begin(f); c < g.face_end(f); ++c) {
      const Vec3& p = g.positions[g.corner_vertex[c]];
      uv.corner[c] = static_cast<Index>(uv.values.size());
      uv.values.push_back(Vec2(p.x() + shift(f), p.y()));
    }
  return g;
}

/// Sets the material of every face of a make_grid(n, ·) mesh from its column:
/// names[column_material[i]] for column i.
inline void paint_columns(PolyMesh& g, Index n, std::vector<std::string> names,
                          const std::vector<Index>& column_material) {
  g.material_names = std::move(names);
  g.face_material.resize(g.num_faces());
  for (Index f = 0; f < g.num_faces(); ++f) g.face_material[f] = column_material[f % n];
}

}  // namespace quadlod::feature_test
