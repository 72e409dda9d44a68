// Metrics under animation (issue 24; include/quadlod/animation_metrics.h): the paper's Fig. 10
// measures PCCD, Chamfer and Hausdorff frame by frame between the deformed original and the
// deformed LOD; here both are deformed by the same skeleton and weights of their own.
#include "quadlod/animation_metrics.h"

#include "util/progress.h"

#include <algorithm>
#include <cmath>

namespace quadlod {

namespace {

std::string check_skin(const PolyMesh& mesh, const Skeleton& skeleton, const char* which) {
  if (mesh.skin.empty()) return std::string("the ") + which + " has no skin weights";
  if (std::string p = mesh.skin.check(mesh.num_vertices()); !p.empty()) return std::string("the ") + which + ": " + p;
  for (Index j : mesh.skin.joint)
    if (j >= skeleton.num_joints())
      return std::string("the ") + which + " has a weight on joint " + std::to_string(j) + " but the skeleton has " +
             std::to_string(skeleton.num_joints());
  return {};
}

double json_number(double v) { return v; }

/// The largest-weight joint of the vertex nearest to p (a linear scan: one query per frame).
Index dominant_joint_near(const PolyMesh& mesh, const Vec3& p) {
  Index best = kInvalidIndex;
  double best_d2 = INFINITY;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const double d2 = (mesh.positions[v] - p).squaredNorm();
    if (d2 < best_d2 && mesh.skin.influences(v) > 0) {
      best_d2 = d2;
      best = v;
    }
  }
  return best == kInvalidIndex ? kInvalidIndex : mesh.skin.joint[mesh.skin.offsets[best]];
}

}  // namespace

FrameSummary summarise_frames(const std::vector<AnimationFrame>& frames, double (*metric)(const EvalResult&)) {
  FrameSummary s;
  std::vector<double> values;
  double worst = -INFINITY;
  for (Index f = 0; f < frames.size(); ++f) {
    const double v = metric(frames[f].metrics);
    if (!std::isfinite(v)) continue;
    values.push_back(v);
    if (v > worst) {
      worst = v;
      s.worst_frame = f;
    }
  }
  if (values.empty()) {
    s.median = s.worst = s.mean = std::nan("");
    return s;
  }
  std::sort(values.begin(), values.end());
  s.median = values[(values.size() - 1) / 2];
  s.worst = values.back();
  double sum = 0.0;
  for (double v : values) sum += v;
  s.mean = sum / double(values.size());
  return s;
}

AnimationEvalResult evaluate_animation(const PolyMesh& input, const PolyMesh& output, const Rig& rig,
                                       const AnimationEvalParams& params) {
  AnimationEvalResult result;
  Stopwatch clock;
  if (std::string p = rig.skeleton.check(); !p.empty()) {
    result.error = "skeleton: " + p;
    return result;
  }
  if (params.animation >= rig.animations.size()) {
    result.error = "animation " + std::to_string(params.animation) + " does not exist (the rig has " +
                   std::to_string(rig.animations.size()) + ")";
    return result;
  }
  for (auto [mesh, which] : {std::pair{&input, "input"}, std::pair{&output, "output"}})
    if (std::string p = check_skin(*mesh, rig.skeleton, which); !p.empty()) {
      result.error = p;
      return result;
    }
  const Animation& anim = rig.animations[params.animation];
  result.animation = anim.name;
  const std::vector<double> times = anim.frame_times();
  const Index step = std::max<Index>(1, params.frame_step);
  for (std::size_t f = 0; f < times.size(); f += step) {
    const std::vector<Mat4> m =
        skinning_matrices(rig.skeleton, global_joint_matrices(rig.skeleton, sample_pose(rig.skeleton, anim, times[f])));
    AnimationFrame frame;
    frame.time = times[f];
    const PolyMesh posed_input = pose_mesh(input, m);
    frame.metrics = evaluate(posed_input, pose_mesh(output, m), params.metrics);
    if (!frame.metrics.ok()) {
      result.error = "frame " + std::to_string(f) + " (t = " + std::to_string(times[f]) + " s): " + frame.metrics.error;
      return result;
    }
    if (frame.metrics.hausdorff_bounded) frame.hausdorff_joint = dominant_joint_near(posed_input, frame.metrics.hausdorff_point);
    result.frames.push_back(std::move(frame));
  }
  result.pccd = summarise_frames(result.frames, [](const EvalResult& r) { return r.pccd_defined ? r.pccd : std::nan(""); });
  result.chamfer = summarise_frames(result.frames, [](const EvalResult& r) { return r.chamfer; });
  result.hausdorff = summarise_frames(result.frames, [](const EvalResult& r) { return r.hausdorff; });
  result.flow_deviation_deg = summarise_frames(result.frames, [](const EvalResult& r) { return r.flow_deviation_deg; });
  result.seconds = clock.seconds();
  return result;
}

nlohmann::json to_json(const AnimationEvalResult& r, const Skeleton* skeleton) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(json_number(v)) : nlohmann::json(); };
  nlohmann::json frames = nlohmann::json::array();
  for (const AnimationFrame& f : r.frames) {
    frames.push_back({{"time", f.time},
                      {"pccd", f.metrics.pccd_defined ? num(f.metrics.pccd) : nlohmann::json()},
                      {"chamfer", num(f.metrics.chamfer)},
                      {"hausdorff", num(f.metrics.hausdorff)},
                      {"hausdorff_in_to_out", num(f.metrics.hausdorff_in_to_out)},
                      {"hausdorff_out_to_in", num(f.metrics.hausdorff_out_to_in)},
                      {"flow_deviation_deg", num(f.metrics.flow_deviation_deg)},
                      {"flow_coverage", num(f.metrics.flow_coverage)},
                      {"flipped_faces", f.metrics.flipped_faces}});
    if (f.metrics.hausdorff_bounded) {
      nlohmann::json& j = frames.back();
      j["hausdorff_upper"] = num(f.metrics.hausdorff_upper);
      j["hausdorff_converged"] = f.metrics.hausdorff_converged;
      const Vec3& p = f.metrics.hausdorff_point;
      j["hausdorff_point"] = {p.x(), p.y(), p.z()};
      j["hausdorff_on"] = f.metrics.hausdorff_point_on_output ? "output" : "input";
      if (f.hausdorff_joint != kInvalidIndex)
        j["hausdorff_joint"] = skeleton && f.hausdorff_joint < skeleton->num_joints()
                                   ? nlohmann::json(skeleton->joints[f.hausdorff_joint].name)
                                   : nlohmann::json(f.hausdorff_joint);
    }
  }
  auto summary = [&](const FrameSummary& s) {
    return nlohmann::json{{"median", num(s.median)},
                          {"worst", num(s.worst)},
                          {"mean", num(s.mean)},
                          {"worst_frame", s.worst_frame == kInvalidIndex ? nlohmann::json() : nlohmann::json(s.worst_frame)}};
  };
  return {{"animation", r.animation},
          {"frames", frames},
          {"summary",
           {{"pccd", summary(r.pccd)},
            {"chamfer", summary(r.chamfer)},
            {"hausdorff", summary(r.hausdorff)},
            {"flow_deviation_deg", summary(r.flow_deviation_deg)}}},
          {"seconds", r.seconds}};
}

}  // namespace quadlod
