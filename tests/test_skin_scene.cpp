// Skinned scenes of several meshes written as .glb (issue 24): every skinned mesh with its skin
// on the shared skeleton, unskinned meshes where their nodes put them; read back through assimp
// (read_scene) and the project's glTF reader; the CLI's scene path; Blender (skipped without it).
#include "cli_runner.h"

#include "quadlod/generators.h"
#include "quadlod/scene.h"
#include "quadlod/skin_io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace quadlod {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDirTest;

std::vector<Vec3> posed(const PolyMesh& mesh, const Rig& rig, double time) {
  const Skeleton& s = rig.skeleton;
  return pose_mesh(mesh, skinning_matrices(s, global_joint_matrices(s, sample_pose(s, rig.animations[0], time)))).positions;
}

Index vertex_at(const PolyMesh& m, const Vec3& p) {
  for (Index v = 0; v < m.num_vertices(); ++v)
    if ((m.positions[v] - p).norm() < 1e-5) return v;
  return kInvalidIndex;
}

/// Two tubes on one two-bone rig: "left" as generated, "right" a coarser tube beside it
/// (shifted 1.5 along x, same weights by construction), plus an unskinned copy placed by its node.
Scene two_skinned_tubes() {
  const SkinnedMesh a = make_bending_tube(10, 12, 2);
  SkinnedMesh b = make_bending_tube(8, 10, 2);
  for (Vec3& p : b.mesh.positions) p.x() += 1.5;
  Scene scene;
  scene.meshes.push_back({"left", a.mesh});
  scene.meshes.push_back({"right", b.mesh});
  PolyMesh plain = b.mesh;
  plain.skin = {};
  scene.meshes.push_back({"static", plain});
  scene.nodes.push_back({"root", kInvalidIndex, Eigen::Matrix4d::Identity(), {}});
  scene.nodes.push_back({"left", 0, Eigen::Matrix4d::Identity(), {0}});
  scene.nodes.push_back({"right", 0, Eigen::Matrix4d::Identity(), {1}});
  Eigen::Matrix4d up = Eigen::Matrix4d::Identity();
  up(2, 3) = -3.0;  // below the tubes
  scene.nodes.push_back({"static", 0, up, {2}});
  scene.rig = a.rig;
  return scene;
}

class SkinScene : public ScratchDirTest {};

TEST_F(SkinScene, TwoSkinnedMeshesRoundTripThroughGlbWithTheirSkins) {
  const Scene scene = two_skinned_tubes();
  const fs::path file = dir / "scene.glb";
  const WriteResult w = write_scene(scene, file);
  ASSERT_TRUE(w.ok()) << w.error;

  const SceneReadResult r = read_scene(file);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.scene.meshes.size(), 3u);
  ASSERT_EQ(r.scene.rig.skeleton.num_joints(), 2u);
  ASSERT_EQ(r.scene.rig.animations.size(), 1u);
  EXPECT_EQ(r.scene.rig.animations[0].frame_times().size(),
            scene.rig.animations[0].frame_times().size());
  const double t = scene.rig.animations[0].end_time();
  Index skinned = 0;
  for (const SceneMesh& back : r.scene.meshes) {
    const SceneMesh* orig = nullptr;
    for (const SceneMesh& m : scene.meshes)
      if (m.name == back.name) orig = &m;
    ASSERT_NE(orig, nullptr) << back.name;
    ASSERT_EQ(back.mesh.num_vertices(), orig->mesh.num_vertices()) << back.name;
    ASSERT_EQ(back.mesh.skin.empty(), orig->mesh.skin.empty()) << back.name;
    if (orig->mesh.skin.empty()) {
      // The unskinned mesh comes back where its node put it (3 below the tubes).
      Index node = kInvalidIndex;
      for (Index n = 0; n < r.scene.nodes.size(); ++n)
        for (Index k : r.scene.nodes[n].meshes)
          if (&r.scene.meshes[k] == &back) node = n;
      ASSERT_NE(node, kInvalidIndex);
      const Eigen::Matrix4d world = r.scene.world_transform(node);
      const Vec3 p = (world * back.mesh.positions[0].homogeneous()).head<3>();
      EXPECT_NE(vertex_at(orig->mesh, p + Vec3(0, 0, 3.0)), kInvalidIndex) << p.transpose();
      continue;
    }
    ++skinned;
    // Weights equal vertex by vertex (matched by bind position), and the posed last frame agrees.
    const auto want = posed(orig->mesh, scene.rig, t), got = posed(back.mesh, r.scene.rig, t);
    for (Index v = 0; v < back.mesh.num_vertices(); ++v) {
      const Index u = vertex_at(orig->mesh, back.mesh.positions[v]);
      ASSERT_NE(u, kInvalidIndex) << back.name << " vertex " << v;
      ASSERT_NEAR(weight_distance(back.mesh.skin, v, orig->mesh.skin, u), 0.0, 1e-6) << back.name << " vertex " << v;
      ASSERT_NEAR((want[u] - got[v]).norm(), 0.0, 1e-4) << back.name << " vertex " << v;
    }
  }
  EXPECT_EQ(skinned, 2u);

  // The project's own reader takes the first skinned mesh and says how many mesh nodes there are.
  const SkinnedReadResult first = read_skinned_gltf(file);
  ASSERT_TRUE(first.ok()) << first.error;
  EXPECT_EQ(first.mesh_nodes, 3u);
  EXPECT_EQ(first.skinned.mesh.num_vertices(), scene.meshes[0].mesh.num_vertices());
  EXPECT_EQ(first.skinned.mesh.num_faces(), scene.meshes[0].mesh.num_faces());
}

TEST_F(SkinScene, CliReducesASkinnedSceneAndKeepsEverySkin) {
  const fs::path in = dir / "scene.glb", out = dir / "lod.glb";
  ASSERT_TRUE(write_scene(two_skinned_tubes(), in).ok());
  const auto s = testing::run_cli("-q simplify '" + in.string() + "' -o '" + out.string() + "' --ratio 0.5", dir);
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const SceneReadResult r = read_scene(out);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.scene.meshes.size(), 3u);
  ASSERT_EQ(r.scene.rig.skeleton.num_joints(), 2u);
  ASSERT_EQ(r.scene.rig.animations.size(), 1u);
  Index skinned = 0;
  for (const SceneMesh& m : r.scene.meshes) {
    if (m.mesh.skin.empty()) continue;
    ++skinned;
    EXPECT_EQ(m.mesh.skin.check(m.mesh.num_vertices()), "") << m.name;
  }
  EXPECT_EQ(skinned, 2u);
  // The skinned meshes were reduced in the rig's animation frames (docs/skinning.md, "Poses"),
  // the static one at its bind pose only.
  const fs::path report = dir / "report.json";
  const auto again = testing::run_cli(
      "-q simplify '" + in.string() + "' -o '" + out.string() + "' --ratio 0.5 --report '" + report.string() + "'", dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  std::ifstream file(report);
  const nlohmann::json j = nlohmann::json::parse(file);
  const int frames = int(two_skinned_tubes().rig.animations[0].frame_times().size());
  std::map<std::string, int> poses;
  for (const auto& m : j["meshes"]) poses[m["name"].get<std::string>()] = m["simplify"]["options"]["skin_poses"].get<int>();
  EXPECT_EQ(poses["left"], std::min(frames, 16));
  EXPECT_EQ(poses["right"], std::min(frames, 16));
  EXPECT_EQ(poses["static"], 0);
}

TEST_F(SkinScene, BlenderImportsBothSkinnedMeshesOnOneArmature) {
  if (std::system("command -v blender >/dev/null 2>&1") != 0) GTEST_SKIP() << "blender not installed";
  const fs::path glb = dir / "scene.glb", script = dir / "check.py", log = dir / "blender.log";
  ASSERT_TRUE(write_scene(two_skinned_tubes(), glb).ok());
  testing::write_text(script, R"PY(
import sys, numpy
if not hasattr(numpy, "bool"):
    numpy.bool = numpy.bool_  # Blender 3.4's glTF importer with numpy >= 1.24
import bpy
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=sys.argv[sys.argv.index("--") + 1])
arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
meshes = [o for o in bpy.data.objects if o.type == "MESH"]
mods = [m for o in meshes for m in o.modifiers if m.type == "ARMATURE" and m.object in arms]
print("RESULT armatures=%d meshes=%d modifiers=%d actions=%d" % (len(arms), len(meshes), len(mods), len(bpy.data.actions)))
)PY");
  const std::string cmd = "blender -b --factory-startup --python-exit-code 1 --python '" + script.string() + "' -- '" +
                          glb.string() + "' > '" + log.string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << testing::slurp(log);
  const std::string text = testing::slurp(log);
  const auto at = text.find("RESULT ");
  ASSERT_NE(at, std::string::npos) << text;
  int armatures = 0, meshes = 0, modifiers = 0, actions = 0;
  ASSERT_EQ(std::sscanf(text.c_str() + at, "RESULT armatures=%d meshes=%d modifiers=%d actions=%d", &armatures, &meshes,
                        &modifiers, &actions),
            4)
      << text;
  EXPECT_EQ(armatures, 1);
  EXPECT_EQ(meshes, 3);
  EXPECT_EQ(modifiers, 2);  // the two skinned tubes; the static copy has none
  EXPECT_GE(actions, 1);
}

}  // namespace
}  // namespace quadlod
