// A skinned Scene as .glb (issue 24): see scene_skin_write.h and docs/skinning.md ("Scenes").
#include "io/scene_skin_write.h"

#include "quadlod/skin_io.h"

namespace quadlod::io_detail {

bool scene_is_skinned(const Scene& scene) {
  if (scene.rig.empty()) return false;
  for (const SceneMesh& m : scene.meshes)
    if (!m.mesh.skin.empty()) return true;
  return false;
}

WriteResult write_skinned_scene(const Scene& scene, const std::filesystem::path& path) {
  // Skinned meshes are posed (and, at the bind pose, drawn) in the space of skin_frame_node
  // (FBX: the skinned mesh's node, whose world transform the reader took out of the skeleton)
  // or in world space (glTF, which ignores a skinned mesh node's transform); an unskinned mesh
  // must be placed in that same space.
  const Eigen::Matrix4d frame = scene.skin_frame_node < scene.nodes.size()
                                    ? Eigen::Matrix4d(scene.world_transform(scene.skin_frame_node).inverse())
                                    : Eigen::Matrix4d::Identity();
  std::vector<SkinnedGlbMesh> meshes;
  for (const SceneMesh& m : scene.meshes) {
    SkinnedGlbMesh g{m.name, &m.mesh, {}};
    if (m.mesh.skin.empty()) {
      const Index k = static_cast<Index>(&m - scene.meshes.data());
      for (Index n = 0; n < scene.nodes.size(); ++n)
        for (Index used : scene.nodes[n].meshes)
          if (used == k) g.placements.push_back(frame * scene.world_transform(n));
      if (scene.nodes.empty()) g.placements.push_back(frame);
      if (g.placements.empty()) continue;  // referenced by no node: not drawn in the source either
    }
    meshes.push_back(std::move(g));
  }
  std::vector<std::pair<std::string, Eigen::Vector4d>> colors;
  for (const SceneMaterial& mat : scene.materials) colors.emplace_back(mat.name, mat.base_color);
  return write_skinned_scene_glb(meshes, scene.rig, path, colors);
}

}  // namespace quadlod::io_detail
