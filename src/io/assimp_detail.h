// quadlod — the assimp halves of read_scene / write_scene (private to src/io/): scene_io.cpp
// dispatches by extension, these do the assimp formats.
#pragma once

#include "quadlod/scene.h"

namespace quadlod::io_detail {

/// read_scene for every non-native extension (src/io/assimp_read.cpp).
SceneReadResult read_scene_with_assimp(const std::filesystem::path& path, const SceneReadOptions& options);

/// Serialises `scene` with assimp's exporter `format_id` ("glb2", "fbx", "collada") into `out`;
/// false with `error` set (without the path) on failure (src/io/assimp_write.cpp).
/// `triangulate`: fan-triangulate polygons (glTF holds triangles only).
bool format_scene_with_assimp(const Scene& scene, const char* format_id, bool triangulate,
                              std::string& out, std::string& error);

/// Issue 34: adds glTF's `mesh.weights` (the blend shapes' default weights, which assimp 5.2's
/// exporter does not write) to a .glb assimp wrote for `scene` (src/io/gltf_morph_weights.cpp).
/// Unchanged when no mesh has shapes; false when `glb` is not a GLB with a JSON chunk.
bool add_gltf_morph_weights(const Scene& scene, std::string& glb);

}  // namespace quadlod::io_detail
