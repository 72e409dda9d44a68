// Internal to src/io: a skinned Scene written as .glb with its skins (issue 24), used by
// write_scene (scene_io.cpp) instead of assimp's exporter, which writes no skin.
#pragma once

#include "quadlod/scene.h"

#include <filesystem>

namespace quadlod::io_detail {

/// True when the scene has a skeleton and at least one mesh with weights.
bool scene_is_skinned(const Scene& scene);

/// Every skinned mesh once with its own skin (all on scene.rig's joints), every unskinned mesh
/// at each node that references it, in the space the skinned meshes are posed in
/// (Scene::skin_frame_node), materials by name with their base colours
/// (write_skinned_scene_glb, include/quadlod/skin_io.h).
WriteResult write_skinned_scene(const Scene& scene, const std::filesystem::path& path);

}  // namespace quadlod::io_detail
