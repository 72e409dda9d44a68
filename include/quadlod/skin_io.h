// quadlod — skinned meshes in glTF 2.0 (issue 24): read a skinned mesh with its skeleton and
// animations, write one back as .glb so that the LOD plays in a glTF viewer.
//
// This is a small reader / writer of its own (src/io/gltf_skin.cpp) rather than assimp's: it is
// what `quadlod simplify --rig`, `quadlod eval --animation` and bench/fig10 need, it keeps glTF's
// exact conventions (node TRS, inverse bind matrices, sampler times) without a round trip through
// aiScene, and its writer controls what Blender's importer sees. docs/skinning.md has the details.
// Errors are values as in io.h: one line naming the file and the element.
#pragma once

#include "quadlod/io.h"
#include "quadlod/skin.h"

#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace quadlod {

struct SkinnedReadResult {
  SkinnedMesh skinned;  ///< mesh with skin; rig with skeleton and animations
  /// Base colour (RGBA) per material name, as the file gives them (written back by the writer).
  std::vector<std::pair<std::string, Eigen::Vector4d>> material_colors;
  std::string error;  ///< empty on success
  Index ignored_channels = 0;       ///< animation channels on nodes that are not joints of the skin
  Index dropped_triangles = 0;      ///< triangles with a repeated vertex after welding
  /// Nodes of the file that hold a mesh (skinned or not); only the first skinned one is read, so
  /// callers take a file with more than one through read_scene (scene.h) instead.
  Index mesh_nodes = 0;
  bool ok() const { return error.empty(); }
};

/// Reads the first node of the default scene (else of the file) that has both a mesh and a skin,
/// from .glb or .gltf (buffers in the .glb's BIN chunk, in data: URIs or in files beside the
/// .gltf). All its triangle primitives become one PolyMesh: corners welded into shared vertices by
/// exact position and equal influences (glTF splits vertices at UV / normal / material seams),
/// UV set 0 and normals as per-corner pools (deduplicated by value), one material per primitive
/// (face_material, by material name). Influences come from JOINTS_n / WEIGHTS_n (all sets), in
/// canonical form (mesh.h); joints are the skin's joint list. The skeleton: each joint's parent is
/// its nearest ancestor node that is a joint, its rest transform its node's TRS (or matrix,
/// decomposed), Skeleton::root_transform the world transform of the roots' parent node (the
/// skinned mesh node's own transform is ignored, as glTF §3.7.3.3 requires). Every animation with
/// a channel on a joint becomes an Animation (other channels are counted in ignored_channels).
/// Files written by write_skinned_glb carry each primitive's polygon sizes in
/// extras.quadlod_polygon_sizes; their polygons are rebuilt from the fans (quads read back as quads).
/// Morph targets (issue 34) become mesh.morph_targets: POSITION displacements, names from the
/// mesh's extras.targetNames, default weights from its `weights`.
/// Rejects: unreadable file, malformed JSON / chunks, out-of-range accessors, sparse accessors,
/// non-triangle primitives, no skinned mesh node.
SkinnedReadResult read_skinned_gltf(const std::filesystem::path& path);

/// Writes `mesh` (mesh.skin indexing rig.skeleton) with its skeleton and all animations as a
/// binary glTF 2.0 file: one mesh node with the skin, the joints as nodes under one root node
/// holding skeleton.root_transform, one primitive per material (fan-triangulated polygons,
/// vertices split per (vertex, UV, normal) corner, JOINTS_n / WEIGHTS_n in sets of four, weights
/// renormalised in float; the polygon sizes in the primitive's extras), one glTF animation per Animation (LINEAR or STEP samplers).
/// mesh.morph_targets (issue 34) become morph targets of every primitive, with the mesh's
/// `weights` and extras.targetNames (the names Blender gives the shape keys).
/// `material_colors` gives base colours by material name (others are grey). Precondition:
/// mesh.check_layout() and rig.skeleton.check() are empty and mesh.skin is not empty;
/// otherwise an error. Written atomically (write_file_atomically).
WriteResult write_skinned_glb(const PolyMesh& mesh, const Rig& rig, const std::filesystem::path& path,
                              const std::vector<std::pair<std::string, Eigen::Vector4d>>& material_colors = {});

/// One mesh of a skinned scene for write_skinned_scene_glb.
struct SkinnedGlbMesh {
  std::string name;
  const PolyMesh* mesh = nullptr;  ///< skin (indexing the rig's skeleton) or none
  /// Unskinned meshes only: where the mesh is drawn, in the space the skinned meshes are posed in
  /// (empty = once, untransformed). Skinned meshes are drawn once, where their joints put them.
  std::vector<Eigen::Matrix4d> placements;
};

/// Several meshes on one skeleton (issue 24): every mesh with weights becomes a skinned mesh node
/// with its own skin, all skins on the same joint nodes and inverse bind matrices; meshes without
/// weights become plain nodes (one per placement); materials are shared by name. Otherwise as
/// write_skinned_glb (which is this with one mesh named "lod"). Errors: a mesh that fails
/// check_layout() or names a joint the skeleton lacks, no mesh with weights, an invalid skeleton.
WriteResult write_skinned_scene_glb(const std::vector<SkinnedGlbMesh>& meshes, const Rig& rig,
                                    const std::filesystem::path& path,
                                    const std::vector<std::pair<std::string, Eigen::Vector4d>>& material_colors = {});

}  // namespace quadlod
