// quadlod — a binary FBX's mesh geometry as the file holds it: control points (float64, each one
// vertex) and polygons over them. assimp's FBX importer gives every polygon corner its own aiMesh
// vertex and rounds positions to float32; gluing those corners back by position (assimp_read.cpp)
// cannot tell a seam from two parts whose boundaries coincide. The control points can: the
// assimp reader maps each aiMesh corner back to its control point (control_point_faces) and, when
// the mapping verifies, uses the file's own vertices instead of gluing. docs/scenes.md.
#pragma once

#include "io/fbx_binary.h"
#include "quadlod/mesh.h"

#include <string>
#include <string_view>
#include <vector>

struct aiScene;

namespace quadlod::fbx {

/// One `Geometry` object of class "Mesh".
struct MeshGeometry {
  std::string name;                 ///< the object name before its "\0\1Geometry" class suffix
  std::vector<Vec3> control_points;  ///< `Vertices`, float64 as stored
  std::vector<Index> polygon_offsets{0};
  std::vector<Index> polygon_corners;  ///< control point of each corner (`PolygonVertexIndex`, the
                                       ///< last corner of a polygon stored as -(i + 1))
  /// `LayerElementMaterial` mapped ByPolygon: the material slot of each polygon; empty when the
  /// file has none or maps it AllSame (every polygon one material).
  std::vector<std::int64_t> polygon_material;
  Index num_polygons() const { return static_cast<Index>(polygon_offsets.size() - 1); }
};

struct GeometryRead {
  std::string creator;  ///< the file's top-level `Creator` ("Blender (stable FBX IO) - 3.4.1 …")
  std::vector<MeshGeometry> geometries;
  std::string error;  ///< empty on success; else one line
  bool ok() const { return error.empty(); }
};

/// The mesh geometries of a binary FBX (every check of parse_binary_fbx, plus: Vertices a
/// multiple of 3 and finite, every polygon index a control point, the last polygon closed, a
/// ByPolygon material layer with one entry per polygon).
GeometryRead read_mesh_geometries(std::string_view bytes, const ParseParams& params = {});

/// True when the file's control points are the mesh's own vertices. assimp's FBX exporter
/// (quadlod's .fbx output) writes its aiMesh vertices instead — quadlod's writer makes one per
/// (vertex, UV, normal) of a corner, so they are split at every seam, one geometry per material:
/// those files are glued along edges as every other assimp format is.
bool control_points_are_vertices(const GeometryRead& read);

/// The faces of a group of aiMeshes (one node's, assimp_read.cpp) over control points.
struct ControlPointFaces {
  std::vector<unsigned> mesh;         ///< per corner: the aiMesh (an index into aiScene::mMeshes)
  std::vector<unsigned> mesh_vertex;  ///< per corner: its aiMesh vertex
  std::vector<Index> vertex;          ///< per corner: the vertex (one per control point used)
  std::vector<Index> face_offsets{0};
  std::vector<Vec3> positions;        ///< per vertex: the control point, float64
};

/// Maps every face corner of the aiMeshes `group` to a control point of `geometries`, in file
/// order. assimp's FBX importer makes one aiMesh per (geometry, material) with the polygons of
/// that material in file order, one vertex per corner, and SortByPType splits that into its
/// triangles and its larger polygons (points and lines removed); so aiMesh m is taken to be
/// geometry g's polygons of one material and of the sizes m holds (triangles, larger, or both)
/// when the counts agree and every corner's aiMesh position is the float rounding of its
/// control point. Each aiMesh must match (the first geometry / material that verifies), else
/// false and `out` is unspecified. Faces come out in (geometry, polygon) order, vertices in
/// control-point order: the order the file has them.
bool control_point_faces(const aiScene& scene, const std::vector<unsigned>& group,
                         const std::vector<MeshGeometry>& geometries, ControlPointFaces& out);

}  // namespace quadlod::fbx
