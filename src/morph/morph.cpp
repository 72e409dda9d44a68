// Blend shapes: posing and the carry by projection (include/quadlod/morph.h).
#include "quadlod/morph.h"

#include "morph/morph_transfer.h"

namespace quadlod {

PolyMesh apply_morph_targets(const PolyMesh& mesh, std::span<const double> weights) {
  PolyMesh out = mesh;
  out.normals.clear();
  out.corner_normal.clear();
  const std::size_t n = std::min(weights.size(), mesh.morph_targets.size());
  for (std::size_t k = 0; k < n; ++k) {
    if (weights[k] == 0.0) continue;
    const std::vector<Vec3>& d = mesh.morph_targets[k].displacement;
    for (Index v = 0; v < out.num_vertices(); ++v) out.positions[v] += weights[k] * d[v];
  }
  return out;
}

PolyMesh apply_morph_target(const PolyMesh& mesh, Index k) {
  std::vector<double> weights(mesh.morph_targets.size(), 0.0);
  if (k < weights.size()) weights[k] = 1.0;
  return apply_morph_targets(mesh, weights);
}

std::vector<MorphTarget> transfer_morph_targets(const PolyMesh& source, const PolyMesh& target,
                                                const SkinTransferParams& params) {
  if (source.morph_targets.empty()) return {};
  return blend_morph_targets(source, target, project_onto_surface(source, target, params));
}

std::vector<MorphTarget> blend_morph_targets(const PolyMesh& source, const PolyMesh& target, SurfaceProjection projection) {
  std::vector<MorphTarget> out;
  if (source.morph_targets.empty()) return out;
  // A vertex on one of its triangle's corners (it did not move: the closest point is that corner
  // up to the rounding of the closest-point arithmetic) takes that corner alone, so it keeps its
  // input displacement bit for bit.
  for (Index v = 0; v < target.num_vertices(); ++v) {
    const auto& c = projection.corners[v];
    for (int k = 0; k < 3 && c[0] != kInvalidIndex; ++k)
      if (source.positions[c[k]] == target.positions[v]) {
        projection.barycentric[v] = Vec3::Unit(k);
        break;
      }
  }
  for (const MorphTarget& from : source.morph_targets) {
    MorphTarget to;
    to.name = from.name;
    to.default_weight = from.default_weight;
    to.displacement.assign(target.num_vertices(), Vec3::Zero());
    for (Index v = 0; v < target.num_vertices(); ++v) {
      const auto& c = projection.corners[v];
      if (c[0] == kInvalidIndex) continue;  // the source has no face: no displacement
      const Vec3& b = projection.barycentric[v];
      // Corners of zero weight are skipped: 1 · d is d exactly.
      Vec3 d = Vec3::Zero();
      for (int k = 0; k < 3; ++k)
        if (b[k] > 0.0) d += b[k] * from.displacement[c[k]];
      to.displacement[v] = d;
    }
    out.push_back(std::move(to));
  }
  return out;
}

}  // namespace quadlod
