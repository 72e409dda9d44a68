// What `simplify` and `eval` share for skinned meshes (issue 24): reading a mesh with its weights
// and rig from a skinned glTF, or an OBJ / PLY / OFF that takes its weights from one (--rig).
#pragma once

#include "quadlod/skin.h"
#include "quadlod/skin_io.h"

#include <string>
#include <utility>
#include <vector>

namespace quadlod::cli {

struct SkinnedInput {
  PolyMesh mesh;  ///< with skin when a rig was found
  Rig rig;        ///< empty when neither the file nor --rig has one
  std::vector<std::pair<std::string, Eigen::Vector4d>> material_colors;
  std::string error;
  /// Meshes in the file (glTF: nodes with a mesh; 1 for OBJ / PLY / OFF).
  std::size_t file_meshes = 1;
  /// Filled when the weights came by projection from the rig file's mesh.
  bool projected = false;
  SkinTransferResult transfer;
};

/// True for .glb / .gltf (case-insensitive).
bool is_gltf_path(const std::string& path);

/// Reads `path`: a glTF through read_skinned_gltf, OBJ / PLY / OFF through read_mesh, any other
/// scene format (FBX, Collada, …) through read_scene — its first skinned mesh with the scene's rig.
/// With `rig_path` (a skinned glTF): its skeleton and animations are the rig, and a mesh without
/// weights gets them by projection onto the rig file's mesh (transfer_skin_weights) — at the
/// bind pose both are the same surface.
SkinnedInput read_skinned_input(const std::string& path, const std::string& rig_path);

/// Remaps `mesh.skin` from the joints of `from` to those of `to` by joint name; error when a
/// joint of `from` that carries weight has no namesake in `to`.
std::string remap_joints(PolyMesh& mesh, const Skeleton& from, const Skeleton& to);

/// Skinning matrices (per pose, per joint) at up to `max_poses` frames of the rig's animations:
/// the union of every animation's frame times, taken evenly (first and last included) when there
/// are more. For SimplifyOptions::skin_poses. 0 or no animation: none.
std::vector<std::vector<Mat4>> rig_poses(const Rig& rig, Index max_poses);

/// Skinning matrices of `count` range-of-motion poses of the rig's skeleton (range_of_motion_poses).
std::vector<std::vector<Mat4>> range_poses(const Rig& rig, Index count, double angle_deg);

/// --skin-poses, --skin-pose-source, --skin-pose-angle.
struct SkinPoseChoice {
  Index count = 16;
  std::string source = "auto";  ///< "animation", "range", or "auto" (range for a rig without animated frames)
  double angle_deg = 30.0;
};

/// The skinning matrices `choice` asks for (rig_poses or range_poses).
std::vector<std::vector<Mat4>> chosen_poses(const Rig& rig, const SkinPoseChoice& choice);

}  // namespace quadlod::cli
