// Skin weights, skeletons, animations and linear blend skinning (issue 24): hand-computed poses,
// the bind pose, weight projection, weights through the reduction, joint-influence borders.
#include "quadlod/generators.h"
#include "quadlod/io.h"
#include "quadlod/simplify.h"
#include "quadlod/skin.h"

#include "mesh/connectivity.h"
#include "skin/skin_borders.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <unistd.h>
#include <cmath>
#include <numbers>

namespace quadlod {
namespace {

// Two joints on +Z: joint 0 at the origin, joint 1 at z = 1 (child of 0), bind pose = rest pose.
Skeleton two_bone_skeleton() {
  Skeleton s;
  Joint root;
  root.name = "root";
  Joint tip;
  tip.name = "tip";
  tip.parent = 0;
  tip.rest.translation = Vec3(0, 0, 1);
  tip.inverse_bind(2, 3) = -1.0;  // inverse of the rest global T(0, 0, 1)
  s.joints = {root, tip};
  return s;
}

TEST(SkinWeights, CanonicalFormIsCheckedByTheLayout) {
  PolyMesh mesh = make_grid(1, 1);
  mesh.skin = make_skin_weights({{{1, 0.2}, {0, 0.6}, {1, 0.2}}, {{0, 1.0}}, {{2, 3.0}}, {}});
  EXPECT_EQ(mesh.check_layout(), "");
  // Duplicates merged, sorted by weight, normalised.
  ASSERT_EQ(mesh.skin.influences(0), 2u);
  EXPECT_EQ(mesh.skin.joint[0], 0u);
  EXPECT_NEAR(mesh.skin.weight[0], 0.6, 1e-12);
  EXPECT_NEAR(mesh.skin.weight[1], 0.4, 1e-12);
  EXPECT_NEAR(mesh.skin.weight[mesh.skin.offsets[2]], 1.0, 1e-12);
  EXPECT_EQ(mesh.skin.influences(3), 0u);
  EXPECT_EQ(mesh.skin.max_influences(), 2u);

  PolyMesh bad = mesh;
  bad.skin.weight[0] = 0.9;  // sums to 1.3
  EXPECT_NE(bad.check_layout().find("skin: vertex 0: weights sum to"), std::string::npos) << bad.check_layout();
  bad = mesh;
  std::swap(bad.skin.weight[0], bad.skin.weight[1]);
  EXPECT_NE(bad.check_layout().find("not sorted"), std::string::npos);
  bad = mesh;
  bad.skin.offsets.pop_back();
  EXPECT_NE(bad.check_layout().find("vertices of weights for 4 vertices"), std::string::npos);
}

TEST(SkinWeights, ObjAndPlyIgnoreThem) {
  const SkinnedMesh tube = make_bending_tube(6, 4, 2);
  const auto dir = std::filesystem::temp_directory_path() / ("quadlod-skin-obj-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* name : {"tube.obj", "tube.ply"}) {
    ASSERT_TRUE(write_mesh(tube.mesh, dir / name).ok());
    const ReadResult r = read_mesh(dir / name);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_TRUE(r.mesh.skin.empty());
    EXPECT_EQ(r.mesh.num_vertices(), tube.mesh.num_vertices());
  }
  std::filesystem::remove_all(dir);
}

TEST(SkinWeights, CanonicalInfluencesTruncateAndRenormalise) {
  const auto c = canonical_influences({{3, 0.1}, {1, 0.5}, {2, 0.3}, {0, 0.1}}, 2);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].joint, 1u);
  EXPECT_EQ(c[1].joint, 2u);
  EXPECT_NEAR(c[0].weight, 0.5 / 0.8, 1e-12);
  EXPECT_NEAR(c[1].weight, 0.3 / 0.8, 1e-12);
  // Ties keep the smaller joint first; min_weight drops relative to the largest.
  const auto t = canonical_influences({{5, 0.4}, {4, 0.4}, {1, 0.01}}, 0, 0.05);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].joint, 4u);
  EXPECT_EQ(t[1].joint, 5u);
}

TEST(SkinWeights, WeightDistanceIsTotalVariation) {
  const SkinWeights s = make_skin_weights({{{0, 1.0}}, {{1, 1.0}}, {{0, 0.5}, {1, 0.5}}, {{0, 1.0}}});
  EXPECT_DOUBLE_EQ(weight_distance(s, 0, s, 1), 1.0);
  EXPECT_DOUBLE_EQ(weight_distance(s, 0, s, 2), 0.5);
  EXPECT_DOUBLE_EQ(weight_distance(s, 0, s, 3), 0.0);
}

// Linear blend skinning against a pose computed by hand: joint 1 turned by 90° about +X.
TEST(LinearBlendSkinning, TwoBonesByHand) {
  const Skeleton skeleton = two_bone_skeleton();
  ASSERT_EQ(skeleton.check(), "");
  std::vector<JointTransform> pose = rest_pose(skeleton);
  pose[1].rotation = Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()));
  const auto m = skinning_matrices(skeleton, global_joint_matrices(skeleton, pose));
  PolyMesh mesh;
  mesh.add_vertex(Vec3(0, 0, 2));      // tip bone only
  mesh.add_vertex(Vec3(0, 0, 1));      // half and half, at the joint
  mesh.add_vertex(Vec3(0.1, 0, 1.5));  // 0.25 root, 0.75 tip
  mesh.add_face({0, 1, 2});
  mesh.skin = make_skin_weights({{{1, 1.0}}, {{0, 0.5}, {1, 0.5}}, {{0, 0.25}, {1, 0.75}}});
  const PolyMesh posed = pose_mesh(mesh, m);
  // M1 = T(0,0,1) · Rx(90°) · T(0,0,−1): (0,0,2) → (0,0,1) → (0,−1,0) → (0,−1,1).
  EXPECT_NEAR((posed.positions[0] - Vec3(0, -1, 1)).norm(), 0.0, 1e-12);
  // The joint itself does not move under either matrix.
  EXPECT_NEAR((posed.positions[1] - Vec3(0, 0, 1)).norm(), 0.0, 1e-12);
  // 0.25 · (0.1, 0, 1.5) + 0.75 · (0.1, −0.5, 1) = (0.1, −0.375, 1.125).
  EXPECT_NEAR((posed.positions[2] - Vec3(0.1, -0.375, 1.125)).norm(), 0.0, 1e-12);
}

TEST(LinearBlendSkinning, SamplingInterpolatesKeys) {
  Skeleton skeleton = two_bone_skeleton();
  Animation a;
  AnimationChannel rot;
  rot.joint = 1;
  rot.path = AnimationChannel::Path::Rotation;
  rot.times = {0.0, 1.0};
  const Quat q0 = Quat::Identity(), q1(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()));
  rot.values = {Eigen::Vector4d(q0.x(), q0.y(), q0.z(), q0.w()), Eigen::Vector4d(q1.x(), q1.y(), q1.z(), q1.w())};
  AnimationChannel move;
  move.joint = 0;
  move.path = AnimationChannel::Path::Translation;
  move.interpolation = AnimationChannel::Interpolation::Step;
  move.times = {0.0, 0.5};
  move.values = {Eigen::Vector4d(0, 0, 0, 0), Eigen::Vector4d(1, 0, 0, 0)};
  a.channels = {rot, move};
  EXPECT_EQ(a.frame_times(), (std::vector<double>{0.0, 0.5, 1.0}));
  const auto half = sample_pose(skeleton, a, 0.25);
  EXPECT_NEAR(half[1].rotation.angularDistance(Quat(Eigen::AngleAxisd(std::numbers::pi / 8, Vec3::UnitX()))), 0.0, 1e-12);
  EXPECT_EQ(half[0].translation, Vec3::Zero());  // step: still the first key
  EXPECT_EQ(sample_pose(skeleton, a, 0.75)[0].translation, Vec3(1, 0, 0));
  EXPECT_EQ(sample_pose(skeleton, a, 5.0)[1].rotation.coeffs(), q1.coeffs());  // clamped
  EXPECT_EQ(half[1].translation, Vec3(0, 0, 1));  // not animated: rest
}

TEST(LinearBlendSkinning, BindPoseGivesTheUnposedMesh) {
  for (Index bones : {2u, 3u}) {
    const SkinnedMesh tube = make_bending_tube(12, 18, bones);
    ASSERT_EQ(tube.mesh.check_layout(), "");
    const Skeleton& s = tube.rig.skeleton;
    for (const auto& pose : {rest_pose(s), sample_pose(s, tube.rig.animations[0], 0.0)}) {
      const PolyMesh posed = pose_mesh(tube.mesh, skinning_matrices(s, global_joint_matrices(s, pose)));
      for (Index v = 0; v < tube.mesh.num_vertices(); ++v)
        ASSERT_NEAR((posed.positions[v] - tube.mesh.positions[v]).norm(), 0.0, 1e-12) << "vertex " << v;
    }
  }
}

TEST(BendingTube, KnownWeightsAndFinalPose) {
  const SkinnedMesh tube = make_bending_tube(16, 24, 2, 0.25, 2.0, 0.25, 12, 60.0);
  const PolyMesh& m = tube.mesh;
  EXPECT_EQ(m.num_vertices(), 16u * 25u);
  EXPECT_EQ(tube.rig.skeleton.num_joints(), 2u);
  ASSERT_EQ(tube.rig.animations.size(), 1u);
  EXPECT_EQ(tube.rig.animations[0].frame_times().size(), 12u);
  for (Index v = 0; v < m.num_vertices(); ++v) {
    const double z = m.positions[v].z();
    const auto in = influences_of(m.skin, v);
    if (z < 0.75 - 1e-9) {
      ASSERT_EQ(in.size(), 1u);
      EXPECT_EQ(in[0].joint, 0u);
    } else if (z > 1.25 + 1e-9) {
      ASSERT_EQ(in.size(), 1u);
      EXPECT_EQ(in[0].joint, 1u);
    } else {
      double w1 = 0.0;
      for (const Influence& i : in) w1 += i.joint == 1 ? i.weight : 0.0;
      EXPECT_NEAR(w1, std::clamp((z - 0.75) / 0.5, 0.0, 1.0), 1e-12) << "z " << z;
    }
  }
  // Last frame: the top ring (bone 1 only) turned by 60° about X around the joint at z = 1.
  const Skeleton& s = tube.rig.skeleton;
  const auto& anim = tube.rig.animations[0];
  const PolyMesh posed =
      pose_mesh(m, skinning_matrices(s, global_joint_matrices(s, sample_pose(s, anim, anim.end_time()))));
  const double a = std::numbers::pi / 3;
  for (Index v = 0; v < m.num_vertices(); ++v) {
    const Vec3& p = m.positions[v];
    if (p.z() < 2.0 - 1e-9) continue;
    const Vec3 expected(p.x(), p.y() * std::cos(a) - (p.z() - 1) * std::sin(a), 1 + p.y() * std::sin(a) + (p.z() - 1) * std::cos(a));
    EXPECT_NEAR((posed.positions[v] - expected).norm(), 0.0, 1e-12);
  }
}

TEST(SkinTransfer, OntoItselfReproducesTheWeights) {
  const SkinnedMesh tube = make_bending_tube(12, 16, 3);
  const SkinTransferResult r = transfer_skin_weights(tube.mesh, tube.mesh);
  ASSERT_EQ(r.skin.check(tube.mesh.num_vertices()), "");
  EXPECT_EQ(r.same_side, tube.mesh.num_vertices());
  EXPECT_NEAR(r.max_distance, 0.0, 1e-12);
  for (Index v = 0; v < tube.mesh.num_vertices(); ++v)
    EXPECT_NEAR(weight_distance(r.skin, v, tube.mesh.skin, v), 0.0, 1e-9) << "vertex " << v;
}

TEST(SkinTransfer, TakesTheWeightsOfItsOwnSide) {
  // Two parallel plates 0.01 apart facing away from each other: the upper one (normal +Z) follows
  // joint 1, the lower (normal −Z) joint 0. A vertex just below the upper plate is nearer to it but
  // faces down: it must take the lower plate's joint.
  PolyMesh source;
  for (double z : {0.0, 0.01})
    for (double y : {0.0, 1.0})
      for (double x : {0.0, 1.0}) source.add_vertex(Vec3(x, y, z));
  source.add_face({0, 2, 3, 1});  // normal −Z
  source.add_face({4, 5, 7, 6});  // normal +Z
  source.skin = make_skin_weights({{{0, 1}}, {{0, 1}}, {{0, 1}}, {{0, 1}}, {{1, 1}}, {{1, 1}}, {{1, 1}}, {{1, 1}}});
  PolyMesh target;
  target.add_vertex(Vec3(0.4, 0.4, 0.008));
  target.add_vertex(Vec3(0.6, 0.4, 0.008));
  target.add_vertex(Vec3(0.5, 0.6, 0.008));
  target.add_face({0, 2, 1});  // faces −Z
  const SkinTransferResult r = transfer_skin_weights(source, target);
  for (Index v = 0; v < 3; ++v) {
    ASSERT_EQ(r.skin.influences(v), 1u);
    EXPECT_EQ(r.skin.joint[r.skin.offsets[v]], 0u);
  }
}

TEST(SkinPoses, RangeOfMotionTurnsEveryJointByTheAngleAboutSpreadAxes) {
  const SkinnedMesh tube = make_bending_tube(8, 12, 3);
  const Skeleton& s = tube.rig.skeleton;
  const auto poses = range_of_motion_poses(s, 16, 30.0);
  ASSERT_EQ(poses.size(), 16u);
  std::vector<Vec3> axes;
  for (const auto& pose : poses) {
    ASSERT_EQ(pose.size(), s.joints.size());
    for (Index j = 0; j < s.num_joints(); ++j) {
      const Quat turn = s.joints[j].rest.rotation.conjugate() * pose[j].rotation;  // in the joint's frame
      EXPECT_NEAR(Eigen::AngleAxisd(turn).angle() * 180.0 / std::numbers::pi, 30.0, 1e-9) << "joint " << j;
      EXPECT_EQ(pose[j].translation, s.joints[j].rest.translation);
      EXPECT_EQ(pose[j].scale, s.joints[j].rest.scale);
      if (j == 0) axes.push_back(Eigen::AngleAxisd(turn).axis());
    }
  }
  // Sixteen different axes, none closer than 25° to another (a Fibonacci spiral of 16 points
  // spreads them about 50° apart), and the same poses on a second call.
  for (std::size_t a = 0; a < axes.size(); ++a)
    for (std::size_t b = a + 1; b < axes.size(); ++b) EXPECT_LT(axes[a].dot(axes[b]), std::cos(25.0 * std::numbers::pi / 180.0));
  const auto again = range_of_motion_poses(s, 16, 30.0);
  for (std::size_t k = 0; k < poses.size(); ++k)
    for (Index j = 0; j < s.num_joints(); ++j) EXPECT_EQ(again[k][j].rotation.coeffs(), poses[k][j].rotation.coeffs());
  // They bend the tube: a vertex blended between two bones leaves the rigid motion of either.
  const std::vector<Mat4> m = skinning_matrices(s, global_joint_matrices(s, poses[3]));
  const PolyMesh posed = pose_mesh(tube.mesh, m);
  Index bent = 0;
  for (Index v = 0; v < tube.mesh.num_vertices(); ++v) {
    if (tube.mesh.skin.influences(v) < 2) continue;
    const Index j = tube.mesh.skin.joint[tube.mesh.skin.offsets[v]];
    bent += (posed.positions[v] - (m[j] * tube.mesh.positions[v].homogeneous()).head<3>()).norm() > 1e-6;
  }
  EXPECT_GT(bent, 0u);
}

// An n×n grid of quads over [x0, x0 + size] × [0, size] at height z, facing +Z, every vertex on `joint`.
void add_plate(PolyMesh& m, std::vector<std::vector<Influence>>& weights, double x0, double size, double z, Index n,
               Index joint) {
  const Index base = m.num_vertices();
  for (Index j = 0; j <= n; ++j)
    for (Index i = 0; i <= n; ++i) {
      m.add_vertex(Vec3(x0 + size * i / n, size * j / n, z));
      weights.push_back({{joint, 1.0}});
    }
  for (Index j = 0; j < n; ++j)
    for (Index i = 0; i < n; ++i) {
      const Index a = base + j * (n + 1) + i;
      m.add_face({a, a + 1, a + n + 2, a + n + 1});
    }
}

TEST(SkinTransfer, APartKeepsToTheInputPartItCameFrom) {
  // The ram's eye: an eyeball (joint 0) half covered, 0.003 above it, by an eyelid (joint 1, a
  // part of its own) facing the same way. A reduced eyeball 0.005 above the ball is nearer to the
  // lid where the lid is; it must still take the ball's weights everywhere, or its faces stretch
  // between the two bones. The lid's own reduction keeps to the lid.
  PolyMesh source;
  std::vector<std::vector<Influence>> w;
  add_plate(source, w, 0.0, 1.0, 0.0, 8, 0);     // the ball
  add_plate(source, w, 0.5, 0.5, 0.008, 4, 1);   // the lid over a quarter of it (x, y in [0.5, 1] × [0, 0.5])
  source.skin = make_skin_weights(w);
  PolyMesh target;
  std::vector<std::vector<Influence>> unused;
  add_plate(target, unused, 0.0, 1.0, 0.005, 2, 0);  // the reduced ball: 9 vertices, 4 of them under the lid
  add_plate(target, unused, 0.5, 0.5, 0.0085, 1, 0);  // the reduced lid
  const SkinTransferResult kept = transfer_skin_weights(source, target);
  EXPECT_EQ(kept.parts, 2u);
  EXPECT_EQ(kept.parts_matched, 2u);
  for (Index v = 0; v < target.num_vertices(); ++v) {
    ASSERT_EQ(kept.skin.influences(v), 1u) << "vertex " << v;
    EXPECT_EQ(kept.skin.joint[kept.skin.offsets[v]], v < 9 ? 0u : 1u) << "vertex " << v;
  }
  // Without the rule the ball's vertices under the lid take the lid's bone: the case it is for.
  SkinTransferParams nearest;
  nearest.keep_parts = false;
  const SkinTransferResult loose = transfer_skin_weights(source, target, nearest);
  Index on_lid = 0;
  for (Index v = 0; v < 9; ++v) on_lid += loose.skin.joint[loose.skin.offsets[v]] == 1u;
  EXPECT_EQ(on_lid, 4u);  // (0.5, 0), (1, 0), (0.5, 0.5), (1, 0.5): 0.003 from the lid, 0.005 from the ball
}

TEST(SkinTransfer, APartJoinedFromTwoProjectsOntoBoth) {
  // Two plates side by side on different bones, and one plate over both (a reducer that joined
  // them): no part is near enough to all of it, so each vertex takes the weights under it.
  PolyMesh source;
  std::vector<std::vector<Influence>> w;
  add_plate(source, w, 0.0, 1.0, 0.0, 4, 0);
  add_plate(source, w, 1.0, 1.0, 0.0, 4, 1);
  source.skin = make_skin_weights(w);
  PolyMesh target;
  std::vector<std::vector<Influence>> unused;
  add_plate(target, unused, 0.0, 2.0, 0.0, 4, 0);  // x = 0, 0.5, …, 2: edges of 0.5, 1 from the far plate
  const SkinTransferResult r = transfer_skin_weights(source, target);
  EXPECT_EQ(r.parts, 1u);
  EXPECT_EQ(r.parts_matched, 0u);
  for (Index v = 0; v < target.num_vertices(); ++v) {
    const double x = target.positions[v].x();
    if (x == 1.0) continue;  // on the seam: either
    ASSERT_EQ(r.skin.influences(v), 1u) << "vertex " << v;
    EXPECT_EQ(r.skin.joint[r.skin.offsets[v]], x < 1.0 ? 0u : 1u) << "vertex " << v;
  }
}

// The known-answer test: a tube whose halves follow two bones, reduced, keeps every vertex's
// weights within the input's range — at most the input's influences, only its joints, and the weight
// of joint 1 between the input's weights one ring below and one ring above the vertex's height.
TEST(SkinThroughReduction, TubeWeightsStayWithinTheInputRange) {
  const double length = 2.0;
  const Index along = 24;
  const SkinnedMesh tube = make_bending_tube(16, along, 2, 0.25, length, 0.25);
  auto input_w1 = [&](double z) {  // the generator's weight of joint 1 at height z
    return std::clamp((z - 0.75) / 0.5, 0.0, 1.0);
  };
  for (double ratio : {0.5, 0.25}) {
    SimplifyOptions o;
    o.ratio = ratio;
    o.skin_joint_parents = {kInvalidIndex, 0};
    const SimplifyResult r = simplify(tube.mesh, o);
    ASSERT_TRUE(r.ok()) << r.error;
    ASSERT_FALSE(r.mesh.skin.empty());
    ASSERT_EQ(r.mesh.check_layout(), "");
    EXPECT_LT(r.achieved, tri_equivalent_count(tube.mesh));
    const double ring = length / along;
    for (Index v = 0; v < r.mesh.num_vertices(); ++v) {
      const auto in = influences_of(r.mesh.skin, v);
      ASSERT_GE(in.size(), 1u);
      ASSERT_LE(in.size(), tube.mesh.skin.max_influences());
      double w1 = 0.0;
      for (const Influence& i : in) {
        ASSERT_LE(i.joint, 1u);
        w1 += i.joint == 1 ? i.weight : 0.0;
      }
      const double z = r.mesh.positions[v].z();
      EXPECT_GE(w1, input_w1(z - ring) - 1e-9) << "ratio " << ratio << " vertex " << v << " z " << z;
      EXPECT_LE(w1, input_w1(z + ring) + 1e-9) << "ratio " << ratio << " vertex " << v << " z " << z;
    }
  }
}

TEST(SkinBorders, UnrelatedBonesOnly) {
  // Rigid weights (blend 0): the ring of edges across z = 1 changes every weight.
  const SkinnedMesh tube = make_bending_tube(8, 8, 2, 0.25, 2.0, 0.0);
  const Connectivity conn = build_connectivity(tube.mesh);
  SkinBorderParams p;
  const SkinBorders unrelated = find_skin_borders(tube.mesh, conn, p);
  // Rings at z = 0.75 and z = 1.0 (joint 1 weight 1 from z = 1 on): the 8 edges along the axis
  // between them cross from bone 0 to bone 1.
  EXPECT_EQ(unrelated.border_edges, 8u);
  EXPECT_EQ(unrelated.related_edges, 0u);
  p.joint_parents = {kInvalidIndex, 0};
  const SkinBorders related = find_skin_borders(tube.mesh, conn, p);
  EXPECT_EQ(related.border_edges, 0u);
  EXPECT_EQ(related.related_edges, 8u);
  // And the pipeline keeps those edges: no output vertex blends the two bones.
  SimplifyOptions o;
  o.ratio = 0.5;
  const SimplifyResult r = simplify(tube.mesh, o);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_TRUE(r.report.contains("skin_borders"));
  EXPECT_EQ(r.report["passes"][0]["report"]["skin_borders"]["border_edges"].get<Index>(), 8u);
}

}  // namespace
}  // namespace quadlod
