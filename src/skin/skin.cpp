// Skeleton poses and linear blend skinning (issue 24; include/quadlod/skin.h). Conventions are
// glTF 2.0's: local = T·R·S, joint matrix = G_j · B_j⁻¹ (§3.7.3), linear interpolation with
// slerp for rotations (§3.11 and Appendix C "Interpolation").
#include "quadlod/skin.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

namespace quadlod {

Mat4 JointTransform::matrix() const {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = rotation.normalized().toRotationMatrix() * scale.asDiagonal();
  m.topRightCorner<3, 1>() = translation;
  return m;
}

std::string Skeleton::check() const {
  const Index n = num_joints();
  for (Index j = 0; j < n; ++j) {
    const Joint& joint = joints[j];
    const std::string what = "joint " + std::to_string(j) + " (" + joint.name + "): ";
    if (joint.parent != kInvalidIndex && joint.parent >= n)
      return what + "parent " + std::to_string(joint.parent) + " out of range";
    if (!joint.inverse_bind.allFinite() || !joint.rest.matrix().allFinite()) return what + "non-finite transform";
    // Walking up more than n steps means a cycle.
    Index steps = 0;
    for (Index p = joint.parent; p != kInvalidIndex; p = joints[p].parent)
      if (++steps > n) return what + "the hierarchy has a cycle";
  }
  if (!root_transform.allFinite()) return "skeleton: non-finite root transform";
  return {};
}

double Animation::start_time() const {
  double t = INFINITY;
  for (const AnimationChannel& c : channels)
    if (!c.times.empty()) t = std::min(t, c.times.front());
  return std::isfinite(t) ? t : 0.0;
}

double Animation::end_time() const {
  double t = -INFINITY;
  for (const AnimationChannel& c : channels)
    if (!c.times.empty()) t = std::max(t, c.times.back());
  return std::isfinite(t) ? t : 0.0;
}

std::vector<double> Animation::frame_times(double merge) const {
  std::vector<double> all;
  for (const AnimationChannel& c : channels) all.insert(all.end(), c.times.begin(), c.times.end());
  std::sort(all.begin(), all.end());
  std::vector<double> frames;
  for (double t : all)
    if (frames.empty() || t - frames.back() > merge) frames.push_back(t);
  return frames;
}

std::vector<JointTransform> rest_pose(const Skeleton& skeleton) {
  std::vector<JointTransform> pose;
  pose.reserve(skeleton.joints.size());
  for (const Joint& j : skeleton.joints) pose.push_back(j.rest);
  return pose;
}

std::vector<std::vector<JointTransform>> range_of_motion_poses(const Skeleton& skeleton, Index count,
                                                               double angle_deg) {
  std::vector<std::vector<JointTransform>> poses;
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double angle = angle_deg * std::numbers::pi / 180.0;
  for (Index k = 0; k < count; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / count, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vec3 axis(r * std::cos(k * golden_angle), r * std::sin(k * golden_angle), z);
    const Quat turn(Eigen::AngleAxisd(angle, axis.normalized()));
    std::vector<JointTransform> pose = rest_pose(skeleton);
    for (JointTransform& t : pose) t.rotation = (t.rotation * turn).normalized();
    poses.push_back(std::move(pose));
  }
  return poses;
}

namespace {

// The value of one channel at time t (see sample_pose's contract).
Eigen::Vector4d sample_channel(const AnimationChannel& c, double t) {
  const std::size_t n = std::min(c.times.size(), c.values.size());
  if (n == 0) return Eigen::Vector4d::Zero();
  if (t <= c.times[0] || n == 1) return c.values[0];
  if (t >= c.times[n - 1]) return c.values[n - 1];
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(c.times.begin(), c.times.begin() + n, t) - c.times.begin());
  const std::size_t i = k - 1;  // times[i] <= t < times[k]
  if (c.interpolation == AnimationChannel::Interpolation::Step) return c.values[i];
  const double span = c.times[k] - c.times[i];
  const double u = span > 0.0 ? (t - c.times[i]) / span : 0.0;
  if (c.path != AnimationChannel::Path::Rotation) return (1.0 - u) * c.values[i] + u * c.values[k];
  const Quat a(c.values[i][3], c.values[i][0], c.values[i][1], c.values[i][2]);
  const Quat b(c.values[k][3], c.values[k][0], c.values[k][1], c.values[k][2]);
  const Quat q = a.normalized().slerp(u, b.normalized());  // Eigen's slerp takes the shorter arc
  return Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
}

}  // namespace

std::vector<JointTransform> sample_pose(const Skeleton& skeleton, const Animation& animation, double time) {
  std::vector<JointTransform> pose = rest_pose(skeleton);
  for (const AnimationChannel& c : animation.channels) {
    if (c.joint >= pose.size()) continue;
    const Eigen::Vector4d v = sample_channel(c, time);
    JointTransform& local = pose[c.joint];
    switch (c.path) {
      case AnimationChannel::Path::Translation: local.translation = v.head<3>(); break;
      case AnimationChannel::Path::Scale: local.scale = v.head<3>(); break;
      case AnimationChannel::Path::Rotation: local.rotation = Quat(v[3], v[0], v[1], v[2]).normalized(); break;
    }
  }
  return pose;
}

std::vector<Mat4> global_joint_matrices(const Skeleton& skeleton, const std::vector<JointTransform>& local) {
  const Index n = skeleton.num_joints();
  std::vector<Mat4> global(n, Mat4::Identity());
  std::vector<std::uint8_t> done(n, 0);
  // Parents may come after children: resolve each chain root-first.
  std::function<const Mat4&(Index)> resolve = [&](Index j) -> const Mat4& {
    if (!done[j]) {
      const Index p = skeleton.joints[j].parent;
      global[j] = (p == kInvalidIndex ? skeleton.root_transform : resolve(p)) * local[j].matrix();
      done[j] = 1;
    }
    return global[j];
  };
  for (Index j = 0; j < n; ++j) resolve(j);
  return global;
}

std::vector<Mat4> skinning_matrices(const Skeleton& skeleton, const std::vector<Mat4>& globals) {
  std::vector<Mat4> m(globals.size());
  for (std::size_t j = 0; j < globals.size(); ++j) m[j] = globals[j] * skeleton.joints[j].inverse_bind;
  return m;
}

PolyMesh pose_mesh(const PolyMesh& mesh, const std::vector<Mat4>& matrices) {
  PolyMesh posed = mesh;
  posed.normals.clear();
  posed.corner_normal.clear();
  const SkinWeights& skin = mesh.skin;
  for (Index v = 0; v < mesh.num_vertices() && v < skin.num_vertices(); ++v) {
    if (skin.influences(v) == 0) continue;
    Mat4 blend = Mat4::Zero();
    for (Index i = skin.offsets[v]; i < skin.offsets[v + 1]; ++i) blend += skin.weight[i] * matrices[skin.joint[i]];
    const Eigen::Vector4d p = blend * mesh.positions[v].homogeneous();
    posed.positions[v] = p.head<3>();
  }
  return posed;
}

std::vector<Influence> canonical_influences(std::vector<Influence> in, Index max_influences, double min_weight) {
  std::sort(in.begin(), in.end(), [](const Influence& a, const Influence& b) { return a.joint < b.joint; });
  std::vector<Influence> merged;
  for (const Influence& i : in) {
    if (!(i.weight > 0.0) || !std::isfinite(i.weight)) continue;
    if (!merged.empty() && merged.back().joint == i.joint) merged.back().weight += i.weight;
    else merged.push_back(i);
  }
  auto by_weight = [](const Influence& a, const Influence& b) {
    return a.weight != b.weight ? a.weight > b.weight : a.joint < b.joint;
  };
  std::sort(merged.begin(), merged.end(), by_weight);
  if (merged.empty()) return merged;
  const double largest = merged.front().weight;
  std::erase_if(merged, [&](const Influence& i) { return i.weight <= min_weight * largest; });
  if (max_influences > 0 && merged.size() > max_influences) merged.resize(max_influences);
  double sum = 0.0;
  for (const Influence& i : merged) sum += i.weight;
  for (Influence& i : merged) i.weight /= sum;
  // Renormalising keeps the order; equal weights keep the joint order.
  return merged;
}

SkinWeights make_skin_weights(const std::vector<std::vector<Influence>>& per_vertex, Index max_influences,
                              double min_weight) {
  SkinWeights skin;
  skin.offsets.reserve(per_vertex.size() + 1);
  skin.offsets.push_back(0);
  for (const auto& list : per_vertex) {
    for (const Influence& i : canonical_influences(list, max_influences, min_weight)) {
      skin.joint.push_back(i.joint);
      skin.weight.push_back(i.weight);
    }
    skin.offsets.push_back(static_cast<Index>(skin.joint.size()));
  }
  return skin;
}

std::vector<Influence> influences_of(const SkinWeights& skin, Index v) {
  std::vector<Influence> out;
  for (Index i = skin.offsets[v]; i < skin.offsets[v + 1]; ++i) out.push_back({skin.joint[i], skin.weight[i]});
  return out;
}

double weight_distance(const SkinWeights& a, Index va, const SkinWeights& b, Index vb) {
  // Influence lists are short (glTF: 4): quadratic matching is cheapest.
  double l1 = 0.0;
  for (Index i = a.offsets[va]; i < a.offsets[va + 1]; ++i) {
    double other = 0.0;
    for (Index k = b.offsets[vb]; k < b.offsets[vb + 1]; ++k)
      if (b.joint[k] == a.joint[i]) other = b.weight[k];
    l1 += std::abs(a.weight[i] - other);
  }
  for (Index k = b.offsets[vb]; k < b.offsets[vb + 1]; ++k) {
    bool shared = false;
    for (Index i = a.offsets[va]; i < a.offsets[va + 1]; ++i) shared |= a.joint[i] == b.joint[k];
    if (!shared) l1 += b.weight[k];
  }
  return std::min(1.0, 0.5 * l1);
}

}  // namespace quadlod
