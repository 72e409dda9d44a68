// Issue 24, measuring and pricing error under animation: the branch-and-bound Hausdorff of
// `eval` (src/eval/hausdorff_bound.h) against hand-computed maxima that lie inside faces, and
// the deformation-sensitive quadrics (src/skin/pose_quadrics.h): a pulled-back quadric measures
// the posed point, and a rigid pose gives back the bind-pose quadric.
#include "eval/hausdorff_bound.h"
#include "quadlod/generators.h"
#include "quadlod/metrics.h"
#include "quadlod/skin.h"
#include "skin/pose_quadrics.h"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <cmath>

namespace quadlod {
namespace {

using eval_detail::directed_hausdorff_bound;
using eval_detail::HausdorffBoundParams;
using Tri = std::array<Vec3, 3>;

/// The unit square [0, 1]² at z = 0 as two triangles.
std::vector<Tri> unit_square() {
  return {Tri{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0)}, Tri{Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)}};
}

/// A tiny triangle at p (a point, for distances much larger than 1e-9).
Tri dot(const Vec3& p) { return {p, p + Vec3(1e-9, 0, 0), p + Vec3(0, 1e-9, 0)}; }

TEST(HausdorffBound, FindsTheMaximumInsideAnEdgeThatNoCornerShows) {
  // From the square to the two dots (0,0) and (1,0): every corner is at distance 1 (or 0), but
  // (½, 1) on the top edge is at √(¼ + 1) from both.
  const std::vector<Tri> to = {dot(Vec3(0, 0, 0)), dot(Vec3(1, 0, 0))};
  const TriangleBvh bvh(to);
  HausdorffBoundParams p;
  p.tolerance = 1e-6;
  const auto r = directed_hausdorff_bound(unit_square(), bvh, to, p);
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.lower, std::sqrt(1.25), 1e-6);
  EXPECT_GE(r.upper, std::sqrt(1.25) - 1e-9);
  EXPECT_LE(r.upper - r.lower, 1e-6);
  EXPECT_NEAR(r.at.x(), 0.5, 1e-3);
  EXPECT_NEAR(r.at.y(), 1.0, 1e-9);
}

TEST(HausdorffBound, FindsTheMaximumInsideAFace) {
  // The four corners of the square as dots: the centre is the farthest point (√½ from each).
  const std::vector<Tri> to = {dot(Vec3(0, 0, 0)), dot(Vec3(1, 0, 0)), dot(Vec3(1, 1, 0)), dot(Vec3(0, 1, 0))};
  const TriangleBvh bvh(to);
  HausdorffBoundParams p;
  p.tolerance = 1e-6;
  const auto r = directed_hausdorff_bound(unit_square(), bvh, to, p);
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.lower, std::sqrt(0.5), 1e-6);
}

TEST(HausdorffBound, AParallelPlaneIsAtItsOffsetEverywhere) {
  std::vector<Tri> to = unit_square();
  for (Tri& t : to)
    for (Vec3& c : t) c.z() = 0.25;
  const TriangleBvh bvh(to);
  // A plateau: every point is at the maximum. The one-triangle bound closes each piece at once.
  const auto r = directed_hausdorff_bound(unit_square(), bvh, to);
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.lower, 0.25, 1e-12);
  EXPECT_LE(r.upper, 0.25 + HausdorffBoundParams{}.tolerance + 1e-12);
  EXPECT_LT(r.queries, 100u);
}

TEST(HausdorffBound, EvaluateReportsTheBracketAndIgnoresTheSeed) {
  // A tube against a coarser one: the bounded Hausdorff is the same for every seed, and at least
  // the sampled one.
  const PolyMesh fine = make_bending_tube(16, 24, 2).mesh, coarse = make_bending_tube(6, 6, 2).mesh;
  EvalParams p;
  p.samples = 2000;
  p.curve_samples = 2000;
  const EvalResult sampled = evaluate(fine, coarse, p);
  ASSERT_TRUE(sampled.ok()) << sampled.error;
  EXPECT_FALSE(sampled.hausdorff_bounded);
  p.hausdorff_tolerance = 1e-6;
  const EvalResult a = evaluate(fine, coarse, p);
  p.seed = 7;
  const EvalResult b = evaluate(fine, coarse, p);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(a.hausdorff_bounded);
  EXPECT_TRUE(a.hausdorff_converged);
  EXPECT_EQ(a.hausdorff, b.hausdorff);
  EXPECT_GE(a.hausdorff, sampled.hausdorff - 1e-12);
  EXPECT_GE(a.hausdorff_upper, a.hausdorff);
  EXPECT_LE(a.hausdorff_upper - a.hausdorff, 1e-6 + 1e-12);
}

TEST(HausdorffBound, TheJsonNamesThePointAndTheMeshItLiesOn) {
  // A 4×4 grid against itself with its centre vertex raised by 0.3: the farthest point is that
  // vertex, on the output; the other way round it is on the input.
  const PolyMesh flat = make_grid(4, 4);
  PolyMesh raised = flat;
  Index centre = 0;
  for (Index v = 0; v < raised.num_vertices(); ++v)
    if ((raised.positions[v] - Vec3(0.5, 0.5, 0.0)).norm() < 1e-9) centre = v;
  raised.positions[centre].z() = 0.3;
  EvalParams p;
  p.samples = 2000;
  p.curve_samples = 2000;
  p.hausdorff_tolerance = 1e-7;
  for (const bool raised_is_output : {true, false}) {
    const EvalResult r = raised_is_output ? evaluate(flat, raised, p) : evaluate(raised, flat, p);
    ASSERT_TRUE(r.ok()) << r.error;
    const nlohmann::json j = to_json(r);
    ASSERT_TRUE(j.contains("hausdorff_point"));
    EXPECT_EQ(j["hausdorff_on"], raised_is_output ? "output" : "input");
    const Vec3 at(j["hausdorff_point"][0].get<double>(), j["hausdorff_point"][1].get<double>(),
                  j["hausdorff_point"][2].get<double>());
    EXPECT_NEAR((at - raised.positions[centre]).norm(), 0.0, 1e-6);
  }
  // A default (sampled) evaluation keeps its JSON as it was.
  EXPECT_FALSE(to_json(evaluate(flat, raised, EvalParams{})).contains("hausdorff_point"));
}

TEST(PoseQuadrics, APulledBackQuadricMeasuresThePosedPoint) {
  Quadric q = Quadric::plane(Vec3(0.2, -0.1, 0.4), Vec3(1, 2, 2).normalized());
  q += Quadric::plane(Vec3(0, 0, 1), Vec3(0, 0, 1));
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.7, Vec3(0, 1, 1).normalized()).toRotationMatrix() * 1.3;
  m.topRightCorner<3, 1>() = Vec3(0.5, -2, 3);
  const Quadric back = pull_back_quadric(q, m);
  for (const Vec3& x : {Vec3(0, 0, 0), Vec3(1, 2, 3), Vec3(-0.4, 0.9, 0.1)}) {
    const Vec3 y = (m * x.homogeneous()).head<3>();
    EXPECT_NEAR(back(x), q(y), 1e-9 * (1 + q(y)));
  }
}

TEST(PoseQuadrics, RigidPosesGiveTheBindPoseQuadricsAndBendingChangesOnlyTheJoint) {
  const SkinnedMesh tube = make_bending_tube(8, 12, 2);
  const PolyMesh& mesh = tube.mesh;
  const Connectivity conn = build_connectivity(mesh);
  const QuadricPlacementParams placement;
  const VertexQuadrics bind = build_vertex_quadrics(mesh, conn, placement);
  // The whole tube moved rigidly (every joint by the same transform).
  Eigen::Matrix4d rigid = Eigen::Matrix4d::Identity();
  rigid.topLeftCorner<3, 3>() = Eigen::AngleAxisd(1.1, Vec3(1, 0, 0)).toRotationMatrix();
  rigid.topRightCorner<3, 1>() = Vec3(0.3, 0.2, -1);
  const std::vector<std::vector<Eigen::Matrix4d>> rigid_poses(3, std::vector<Eigen::Matrix4d>(2, rigid));
  const VertexQuadrics same = build_pose_vertex_quadrics(mesh, conn, placement, rigid_poses);
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Vec3& p = mesh.positions[v];
    const Vec3 off = p + Vec3(0.01, -0.02, 0.015);
    ASSERT_NEAR(same.terms[v].q(off), bind.terms[v].q(off), 1e-9 * (1 + bind.terms[v].q(off))) << "vertex " << v;
  }
  // The bend of the generator's last frame: vertices on one bone only keep their quadric (each
  // half moves rigidly), blended ones (around the joint) get another.
  const Skeleton& s = tube.rig.skeleton;
  const Animation& anim = tube.rig.animations[0];
  const std::vector<std::vector<Eigen::Matrix4d>> bend = {
      skinning_matrices(s, global_joint_matrices(s, sample_pose(s, anim, anim.end_time())))};
  const VertexQuadrics bent = build_pose_vertex_quadrics(mesh, conn, placement, bend);
  // A vertex is rigid when it and every vertex of its faces have one influence on one joint.
  std::vector<Index> joint_of(mesh.num_vertices(), kInvalidIndex);
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (mesh.skin.influences(v) == 1) joint_of[v] = mesh.skin.joint[mesh.skin.offsets[v]];
  std::vector<char> rigid_vertex(mesh.num_vertices(), 1);
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const auto vs = mesh.face_vertices(f);
    bool one_joint = true;
    for (Index v : vs) one_joint &= joint_of[v] != kInvalidIndex && joint_of[v] == joint_of[vs[0]];
    if (!one_joint)
      for (Index v : vs) rigid_vertex[v] = 0;
  }
  Index rigid_count = 0, changed = 0;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Vec3 off = mesh.positions[v] + Vec3(0.01, -0.02, 0.015);
    const double a = bent.terms[v].q(off), b = bind.terms[v].q(off);
    const bool differs = std::abs(a - b) > 1e-9 * (1 + b);
    if (rigid_vertex[v]) {
      ++rigid_count;
      EXPECT_FALSE(differs) << "rigid vertex " << v << ": " << a << " vs " << b;
    } else {
      changed += differs;
    }
  }
  EXPECT_GT(rigid_count, mesh.num_vertices() / 2);  // most of the tube is on one bone
  EXPECT_GT(changed, 0u);                           // the blend zone is priced otherwise
}

}  // namespace
}  // namespace quadlod
