#include "skin_cli.h"

#include "quadlod/io.h"
#include "quadlod/scene.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>

namespace quadlod::cli {

bool is_gltf_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".glb" || ext == ".gltf";
}

SkinnedInput read_skinned_input(const std::string& path, const std::string& rig_path) {
  SkinnedInput in;
  if (is_gltf_path(path)) {
    SkinnedReadResult r = read_skinned_gltf(path);
    if (!r.ok()) {
      in.error = r.error;
      return in;
    }
    in.mesh = std::move(r.skinned.mesh);
    in.rig = std::move(r.skinned.rig);
    in.material_colors = std::move(r.material_colors);
    in.file_meshes = r.mesh_nodes;
  } else if (MeshFormat native; !format_from_path(path, native) && scene_readable_path(path)) {
    // FBX, Collada, … through assimp (issue 21's reader): the first skinned mesh and the rig.
    SceneReadResult r = read_scene(path);
    if (!r.ok()) {
      in.error = r.error;
      return in;
    }
    const SceneMesh* skinned = nullptr;
    for (const SceneMesh& m : r.scene.meshes)
      if (!m.mesh.skin.empty() && !skinned) skinned = &m;
    if (!skinned && !r.scene.meshes.empty()) skinned = &r.scene.meshes[0];
    if (!skinned) {
      in.error = path + ": the scene has no mesh";
      return in;
    }
    in.mesh = skinned->mesh;
    in.file_meshes = r.scene.meshes.size();
    if (!in.mesh.skin.empty()) in.rig = r.scene.rig;
    for (const SceneMaterial& m : r.scene.materials) in.material_colors.emplace_back(m.name, m.base_color);
  } else {
    ReadResult r = read_mesh(path);
    if (!r.ok()) {
      in.error = r.error;
      return in;
    }
    in.mesh = std::move(r.mesh);
  }
  if (rig_path.empty()) return in;
  SkinnedReadResult rig = read_skinned_gltf(rig_path);
  if (!rig.ok()) {
    in.error = rig.error;
    return in;
  }
  if (in.mesh.skin.empty()) {
    in.transfer = transfer_skin_weights(rig.skinned.mesh, in.mesh);
    in.mesh.skin = in.transfer.skin;
    in.projected = true;
  } else if (!in.rig.empty()) {
    if (std::string e = remap_joints(in.mesh, in.rig.skeleton, rig.skinned.rig.skeleton); !e.empty()) {
      in.error = path + ": " + e;
      return in;
    }
  }
  in.rig = std::move(rig.skinned.rig);
  if (in.material_colors.empty()) in.material_colors = std::move(rig.material_colors);
  return in;
}

std::string remap_joints(PolyMesh& mesh, const Skeleton& from, const Skeleton& to) {
  std::map<std::string, Index> by_name;
  for (Index j = 0; j < to.num_joints(); ++j) by_name.emplace(to.joints[j].name, j);
  std::vector<std::vector<Influence>> lists(mesh.num_vertices());
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    for (Influence i : influences_of(mesh.skin, v)) {
      const auto it = i.joint < from.num_joints() ? by_name.find(from.joints[i.joint].name) : by_name.end();
      if (it == by_name.end())
        return "joint " + std::to_string(i.joint) + " (" + (i.joint < from.num_joints() ? from.joints[i.joint].name : "?") +
               ") is not in the rig's skeleton";
      i.joint = it->second;
      lists[v].push_back(i);
    }
  mesh.skin = make_skin_weights(lists);
  return {};
}

std::vector<std::vector<Mat4>> rig_poses(const Rig& rig, Index max_poses) {
  std::vector<std::pair<Index, double>> frames;  // (animation, time)
  for (Index a = 0; a < rig.animations.size(); ++a)
    for (double t : rig.animations[a].frame_times()) frames.emplace_back(a, t);
  std::vector<std::vector<Mat4>> poses;
  if (max_poses == 0 || frames.empty()) return poses;
  const std::size_t n = std::min<std::size_t>(max_poses, frames.size());
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = n == 1 ? 0 : k * (frames.size() - 1) / (n - 1);
    const auto& [a, t] = frames[i];
    const Skeleton& s = rig.skeleton;
    poses.push_back(skinning_matrices(s, global_joint_matrices(s, sample_pose(s, rig.animations[a], t))));
  }
  return poses;
}

std::vector<std::vector<Mat4>> chosen_poses(const Rig& rig, const SkinPoseChoice& choice) {
  bool animated = false;
  for (const Animation& a : rig.animations) animated = animated || !a.frame_times().empty();
  const bool range = choice.source == "range" || (choice.source == "auto" && !animated);
  return range ? range_poses(rig, choice.count, choice.angle_deg) : rig_poses(rig, choice.count);
}

std::vector<std::vector<Mat4>> range_poses(const Rig& rig, Index count, double angle_deg) {
  std::vector<std::vector<Mat4>> poses;
  const Skeleton& s = rig.skeleton;
  for (const auto& local : range_of_motion_poses(s, count, angle_deg))
    poses.push_back(skinning_matrices(s, global_joint_matrices(s, local)));
  return poses;
}

}  // namespace quadlod::cli
