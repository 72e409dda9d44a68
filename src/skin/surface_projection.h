// The projection behind the per-vertex data a reduction carries (skin weights, issue 24; blend
// shapes, issue 34): every target vertex finds its closest point on the source surface, on a
// triangle facing its way and on its own part (SkinTransferParams says how), and blends that
// triangle's three corners by the point's barycentric coordinates. One projection serves every
// kind of per-vertex data, so the weights and the shapes of one output vertex always come from
// the same place of the input (docs/skinning.md "Why projection", docs/blend_shapes.md).
#pragma once

#include "quadlod/skin.h"

#include <array>
#include <memory>
#include <vector>

namespace quadlod {

struct SurfaceProjection {
  /// Per target vertex: the source vertices of the triangle its closest point lies on
  /// (all kInvalidIndex when the source has no face) and that point's barycentric coordinates
  /// (clamped into the triangle, summing to 1; exactly (1,0,0) at the triangle's first corner).
  std::vector<std::array<Index, 3>> corners;
  std::vector<Vec3> barycentric;
  Index same_side = 0, nearest_only = 0, parts = 0, parts_matched = 0;
  double max_distance = 0.0, mean_distance = 0.0;
};

/// See the file comment; params.max_influences and min_weight are not used. Deterministic.
SurfaceProjection project_onto_surface(const PolyMesh& source, const PolyMesh& target, const SkinTransferParams& params = {});

/// The same, with the source's search structures (triangles, BVHs, parts) built once and used
/// for every target: a reduction projects each pass's output onto its original input.
/// project(target) == project_onto_surface(source, target, params). `source` must outlive it
/// only while it is constructed (it keeps copies of what it needs).
class SurfaceProjector {
 public:
  explicit SurfaceProjector(const PolyMesh& source, const SkinTransferParams& params = {});
  ~SurfaceProjector();
  SurfaceProjector(const SurfaceProjector&) = delete;
  SurfaceProjector& operator=(const SurfaceProjector&) = delete;
  SurfaceProjection project(const PolyMesh& target) const;

 private:
  struct Surface;  // weight_transfer.cpp's SourceSurface
  std::unique_ptr<Surface> surface_;
  SkinTransferParams params_;
};

}  // namespace quadlod
