// quadlod — scenes: several meshes, their materials and a node hierarchy, read and written
// through assimp (FBX, glTF 2.0, Collada, 3DS, … — whatever assimp 5.2 reads) and through the
// native OBJ / PLY / OFF readers (a one-mesh scene).
//
// Polygons stay polygons: the assimp reader runs no triangulation, and it welds the corners
// assimp splits per attribute back into shared vertices, so per-corner UVs and normals become
// PolyMesh pools (see read_scene). Errors are values, as in io.h: one line naming the file.
#pragma once

#include "quadlod/io.h"
#include "quadlod/mesh.h"
#include "quadlod/skin.h"

#include <Eigen/Core>

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace quadlod {

/// A material as far as quadlod carries it: its name (what PolyMesh::material_names refer to),
/// the base colour and the base-colour texture path as the file gives it (not resolved).
struct SceneMaterial {
  std::string name;
  Eigen::Vector4d base_color{1.0, 1.0, 1.0, 1.0};  ///< RGBA in [0,1]
  std::string base_color_texture;                   ///< "" when none
};

/// One mesh of the scene, in the space of the nodes that reference it.
///
/// `mesh.face_material` indexes `mesh.material_names`, and each of those names is the `name` of
/// an entry of Scene::materials (the writers resolve by name; an unknown name gets a default
/// material). A mesh referenced by several nodes is an instance: it is stored and reduced once.
struct SceneMesh {
  std::string name;
  PolyMesh mesh;
  // Skins (issue 24): mesh.skin holds the bone weights (joints index Scene::rig.skeleton), filled
  // in by the assimp reader from glTF skins / FBX clusters (aiBone weights).
};

/// A node of the hierarchy. nodes[0] is the root when the scene has nodes.
struct SceneNode {
  std::string name;
  Index parent = kInvalidIndex;                      ///< kInvalidIndex for the root
  Eigen::Matrix4d local = Eigen::Matrix4d::Identity();  ///< column-vector convention: p_parent = local · p
  std::vector<Index> meshes;                         ///< indices into Scene::meshes
};

struct Scene {
  std::vector<SceneMesh> meshes;
  std::vector<SceneMaterial> materials;
  std::vector<SceneNode> nodes;  ///< parents precede children; empty = every mesh at the origin
  /// What the file held that a Scene does not represent (cameras, lights, animations, point and
  /// line primitives); informational, for `quadlod info`-style summaries and for tests.
  Index cameras = 0, lights = 0, animations = 0;
  std::uint64_t dropped_primitives = 0;  ///< points / lines / faces with < 3 distinct corners
  /// Binary FBX: how many meshes took their vertices from the file's control points (the exact
  /// vertices and float64 positions; src/io/fbx_control_points.h) instead of gluing corners, and
  /// when some did not, why (one line; empty otherwise).
  Index fbx_control_point_meshes = 0;
  std::string fbx_note;
  /// Skeleton and animations (issue 24): the joints are the nodes the meshes' bones name (plus
  /// the nodes between them), with their hierarchy, local transforms as rest pose and the bones'
  /// offset matrices as inverse bind matrices; animation channels on joints, times in seconds.
  /// Empty when no mesh is skinned.
  Rig rig;
  /// The node whose space the skinned meshes are posed in (issue 24): FBX / Collada bind in the
  /// skinned mesh node's space (the reader puts that node's inverse world transform in
  /// rig.skeleton.root_transform); kInvalidIndex = world space (glTF, and scenes built in code).
  /// The skinned .glb writer places unskinned meshes relative to it.
  Index skin_frame_node = kInvalidIndex;

  std::uint64_t tri_equivalent_count() const;
  /// The world transform of node n (product of the locals from the root down).
  Eigen::Matrix4d world_transform(Index node) const;
};

struct SceneReadOptions {
  /// For the native readers (.obj / .ply / .off).
  ReadOptions native;
  /// The assimp reader gives two corners of one welded vertex the same normal when their
  /// normals are within this angle (degrees). Exporters store normals with rounding (Blender's
  /// FBX: 0.01° between the corners of one smooth vertex), and normals that differ by value are a
  /// normal seam to the reduction (src/mesh/features.h), so without this every edge of a smooth
  /// mesh read from FBX would be one. Real creases are degrees apart. 0 = exact equality only.
  double normal_weld_degrees = 0.1;
  /// Binary FBX: take each mesh's vertices from the file's control points where every corner
  /// verifiably maps onto one (src/io/fbx_control_points.h); false glues corners along edges as
  /// for the other assimp formats.
  bool fbx_control_points = true;
};

struct SceneReadResult {
  Scene scene;
  std::string error;     ///< empty on success: one line naming the file
  double seconds = 0.0;  ///< wall time of the read
  bool ok() const { return error.empty(); }
};

/// The writers' formats. Native ones hold one mesh: a scene is flattened into it (below).
enum class SceneFormat { Obj, Ply, Off, Glb, Fbx, Collada };

/// Output format from the extension (.obj .ply .off .glb .fbx .dae, case-insensitive).
bool scene_format_from_path(const std::filesystem::path& path, SceneFormat& format);
/// The extension of a format, with the dot (".glb").
std::string scene_format_extension(SceneFormat format);
/// The output extension that keeps an input's format where quadlod writes it (".obj" for
/// .obj, ".fbx" for .fbx, …) and ".glb" for formats it reads only (.gltf, .3ds, …).
std::string default_output_extension(const std::filesystem::path& input);
/// True when the extension is one read_scene can read (native or assimp).
bool scene_readable_path(const std::filesystem::path& path);

/// Reads a scene. .obj / .ply / .off go through read_mesh (io.h) and become a scene of one mesh
/// under one root node named after the file stem; every other extension goes through assimp.
///
/// The assimp reader (src/io/assimp_read.cpp):
///   * runs no triangulation and no vertex joining of assimp's: the meshes of one node (assimp
///     splits a mesh by material) become one PolyMesh whose vertices come from gluing the corners
///     along edges — two half-edges on the same two positions (exact float equality) running
///     opposite ways make their faces neighbours — so the topology the exporter split at UV /
///     normal / material seams comes back while parts that only touch, or lie on top of each
///     other, stay apart (a binary FBX not written by assimp: its control points are the
///     vertices instead, where every corner verifiably maps onto one — Scene::fbx_note); UV sets (all of them, named when the file names them), normals and the
///     first colour set are pools with one index per corner (deduplicated by value; the normals
///     of one vertex within SceneReadOptions::normal_weld_degrees share an entry);
///   * drops points, lines and faces with fewer than 3 distinct corners (counted in
///     dropped_primitives);
///   * keeps the node hierarchy with local transforms (FBX pivot helpers folded), materials with
///     name / base colour / base-colour texture. Two nodes with the same set of assimp meshes
///     share one Scene mesh (an instance).
/// A file assimp cannot read is an error naming the file and assimp's message. A scene with no
/// meshes (empty, or a camera only) is NOT an error here: callers that need geometry check.
SceneReadResult read_scene(const std::filesystem::path& path, const SceneReadOptions& options = {});

/// The same from memory (assimp formats only; for fuzzing and tests): `hint` is the extension
/// without the dot ("glb", "fbx", "dae"); `name` names the data in error messages.
SceneReadResult read_scene_from_memory(const void* data, std::size_t size, std::string_view hint,
                                       const std::string& name = "<memory>", const SceneReadOptions& options = {});

/// A one-mesh scene around a mesh (one root node named `name`).
Scene scene_from_mesh(PolyMesh mesh, const std::string& name);

/// Every node's meshes in world space, in one PolyMesh: positions and normals transformed,
/// one `o` object per (node, mesh) named after the node, materials kept by name. Used to write a
/// scene as OBJ / PLY / OFF and to measure a whole scene.
PolyMesh flatten_scene(const Scene& scene);

/// Writes a scene; the format comes from the extension, the file appears atomically.
///   * .obj / .ply / .off: a one-mesh scene whose root has the identity transform is written as
///     that mesh unchanged; anything else is flattened (flatten_scene).
///   * .glb (glTF 2.0 binary), .fbx (binary FBX 7.4) and .dae (Collada 1.4) through assimp's
///     exporters with the same nodes, meshes, materials, UV sets, normals and vertex colours.
///     Vertices are split where a corner's UV / normal differs (those formats have per-vertex
///     attributes only), and each mesh is split into one assimp mesh per material. glTF has no
///     polygons: .glb faces are triangulated on write (fans). FBX and Collada keep polygons.
WriteResult write_scene(const Scene& scene, const std::filesystem::path& path,
                        const WriteOptions& options = {});

}  // namespace quadlod
