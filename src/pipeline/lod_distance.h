// quadlod — the Hausdorff distance of every LOD level to the input (src/pipeline/lod.cpp), as
// `quadlod eval` defines it (docs/metrics.md §1–3: the input's longest bbox side is 1, samples
// from Xoshiro256(seed, stream 0 / 1) on the fan triangulations, plus every used vertex), but
// with the input's samples and BVH built once for the whole chain and nothing else of evaluate()
// computed (PCCD, features, flow): those took 3–6× the reductions' time on the corpus.
#pragma once

#include "geometry/bvh.h"
#include "geometry/sampling.h"
#include "quadlod/mesh.h"

#include <cstdint>
#include <vector>

namespace quadlod::lod_detail {

class HausdorffToInput {
 public:
  /// Precondition: input.check_layout() is empty. `samples` per direction (EvalParams::samples).
  HausdorffToInput(const PolyMesh& input, std::uint64_t samples, std::uint64_t seed = 1);
  /// Symmetric Hausdorff distance of `level` to the input in units of the input's longest bbox
  /// side — evaluate(input, level).hausdorff for the same samples and seed; NaN when either
  /// surface has no area.
  double measure(const PolyMesh& level) const;

 private:
  Vec3 centre_ = Vec3::Zero();
  double scale_ = 0.0;
  std::uint64_t samples_, seed_;
  std::vector<Vec3> points_;  // the input's samples and used vertices, scaled
  TriangleBvh bvh_;
  bool ok_ = false;
};

}  // namespace quadlod::lod_detail
