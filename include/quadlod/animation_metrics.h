// quadlod — metrics of a reduction under animation (issue 24; docs/metrics.md §7; the paper's
// Fig. 10): the input and the output are posed with the same skeleton at every frame (linear blend
// skinning, include/quadlod/skin.h) and evaluate() (metrics.h) compares the posed meshes.
#pragma once

#include "quadlod/metrics.h"
#include "quadlod/skin.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace quadlod {

struct AnimationEvalParams {
  /// Per-frame metrics. Fewer samples than a static eval's default: 82 frames of the ram at 50000
  /// samples per direction take about as long as one eval at 200000 × 20, and the per-frame
  /// Chamfer's standard error stays below 1 % of the values measured (docs/metrics.md §7).
  EvalParams metrics = [] {
    EvalParams p;
    p.samples = 50000;
    p.curve_samples = 50000;
    // The per-frame Hausdorff by branch and bound: the sampled maximum moved by ±1.5 % with the
    // seed on the ram, as much as the two methods of Fig. 10 differ (docs/skinning.md).
    p.hausdorff_tolerance = 1e-5;
    return p;
  }();
  /// Which of rig.animations (index).
  Index animation = 0;
  /// Evaluate every `frame_step`-th frame of Animation::frame_times() (>= 1).
  Index frame_step = 1;
};

struct AnimationFrame {
  double time = 0.0;  ///< seconds
  EvalResult metrics;
  /// With a bounded Hausdorff: the joint with the largest weight at the posed input vertex
  /// nearest to where the Hausdorff is attained (which part of the character; kInvalidIndex
  /// otherwise).
  Index hausdorff_joint = kInvalidIndex;
};

/// Median (the lower middle for an even count), worst (largest) and mean of one metric over the
/// frames, and the worst frame's index in `frames`; NaN when no frame has a finite value.
struct FrameSummary {
  double median = 0.0, worst = 0.0, mean = 0.0;
  Index worst_frame = kInvalidIndex;
};

struct AnimationEvalResult {
  std::string error;  ///< empty on success
  bool ok() const { return error.empty(); }
  std::string animation;
  std::vector<AnimationFrame> frames;
  FrameSummary pccd, chamfer, hausdorff, flow_deviation_deg;
  double seconds = 0.0;
};

/// Poses `input` and `output` (both with skin weights indexing rig.skeleton) at every frame of
/// rig.animations[params.animation] and evaluates the posed output against the posed input.
/// Each frame is normalised as evaluate() does, by the posed input's bounding box. Errors: no
/// such animation, a mesh without weights, a weight naming a joint the skeleton lacks, a frame
/// that evaluate() rejects (the error names the frame).
AnimationEvalResult evaluate_animation(const PolyMesh& input, const PolyMesh& output, const Rig& rig,
                                       const AnimationEvalParams& params = {});

/// Summary of one metric picked from each frame (used by the CLI and the bench).
FrameSummary summarise_frames(const std::vector<AnimationFrame>& frames, double (*metric)(const EvalResult&));

/// {"animation", "frames": [{"time", "pccd", "chamfer", "hausdorff", "flow_deviation_deg", ...}],
///  "summary": {"pccd": {"median", "worst", "mean", "worst_frame"}, ...}}; NaN becomes null.
/// With a skeleton, a frame's "hausdorff_joint" is the joint's name, else its index.
nlohmann::json to_json(const AnimationEvalResult& result, const Skeleton* skeleton = nullptr);

}  // namespace quadlod
