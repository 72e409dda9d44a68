// quadlod — polygon mesh kernel (triangles, quads and n-gons).
//
// The mesh is flat and index based (see docs/architecture.md, "Mesh kernel"):
//   * vertices are rows of `positions`;
//   * faces are stored as CSR: face f owns the corners [face_offsets[f], face_offsets[f+1]),
//     listed counter-clockwise as read from the file; `corner_vertex[c]` is the vertex of corner c;
//   * attributes are parallel arrays. Per-corner attributes (any number of UV sets, normals) are
//     OBJ-style: a pool of values plus one pool index per corner, so seams and shared values
//     survive a read/write round trip unchanged;
//   * per-face tags (object, group, material, smoothing group) index name tables.
// Connectivity (edges, adjacency, boundary loops, components) is derived data and lives in
// src/mesh/connectivity.h; nothing here caches it, so a PolyMesh can be edited freely.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace quadlod {

/// Every element id (vertex, face, corner, edge, pool entry) is a 32-bit index.
using Index = std::uint32_t;
/// The one invalid value of an Index ("none", "not present").
inline constexpr Index kInvalidIndex = ~Index{0};

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

/// Axis-aligned bounding box. Empty when min > max (the default).
struct BoundingBox {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());

  bool empty() const { return (min.array() > max.array()).any(); }
  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  Vec3 extent() const { return empty() ? Vec3::Zero() : Vec3(max - min); }
  double diagonal() const { return extent().norm(); }
  double longest_side() const { return extent().maxCoeff(); }
};

/// One UV set (texture coordinate layer): a pool of values plus one pool index per corner.
/// uv_sets[0] is what OBJ `vt` reads and writes; PLY names the sets `texcoord`, `texcoord1`, …
struct UvSet {
  std::string name;            ///< layer name ("" when the file gives none)
  std::vector<Vec2> values;    ///< the pool
  std::vector<Index> corner;   ///< per corner: pool index or kInvalidIndex
};

/// Skin weights (issue 24; include/quadlod/skin.h has the skeleton, animations and skinning):
/// per vertex, any number of (joint, weight) influences as CSR — vertex v owns the entries
/// [offsets[v], offsets[v+1]) of `joint` and `weight`. Empty (offsets empty) = the mesh is not
/// skinned. Joints index the skeleton's joint list (Skeleton::joints). Kept canonical: within a
/// vertex, weights are > 0, sorted by decreasing weight (ties by increasing joint), joints
/// distinct, and they sum to 1 (within SkinWeights::kSumTolerance). A vertex may have no influence (it then follows no
/// joint: glTF's "all weights zero", rare, kept as is). The OBJ / PLY / OFF paths ignore skins.
struct SkinWeights {
  std::vector<Index> offsets;  ///< num_vertices() + 1 entries when skinned, else empty
  std::vector<Index> joint;
  std::vector<double> weight;

  /// How far a vertex's weights may sum from 1 (weights read from files are 32-bit floats).
  static constexpr double kSumTolerance = 1e-5;

  bool empty() const { return offsets.empty(); }
  Index num_vertices() const { return offsets.empty() ? 0 : static_cast<Index>(offsets.size() - 1); }
  Index influences(Index v) const { return offsets[v + 1] - offsets[v]; }
  /// Largest number of influences of any vertex (0 when empty).
  Index max_influences() const;
  /// Checks the canonical form above for a mesh of `vertices` vertices; "" when it holds, else
  /// the first violation naming the vertex ("skin: vertex 7: weights sum to 0.5").
  std::string check(Index vertices) const;
};

/// A blend shape (issue 34; glTF morph target, FBX blend shape channel, Blender shape key): one
/// displacement per vertex, added to the base positions at full weight. docs/blend_shapes.md.
/// The OBJ / PLY / OFF paths ignore blend shapes.
struct MorphTarget {
  std::string name;                 ///< "" when the file gives none
  double default_weight = 0.0;      ///< glTF `mesh.weights[k]`; FBX DeformPercent / 100
  std::vector<Vec3> displacement;   ///< per vertex, in the mesh's own space (same units as positions)
};

/// A polygon mesh with optional per-corner UVs and normals and per-face tags.
///
/// Invariants (checked by `check_layout()`):
///   * face_offsets.size() == num_faces() + 1, face_offsets[0] == 0, non-decreasing,
///     face_offsets.back() == corner_vertex.size(); every face has >= 3 corners;
///   * every corner_vertex entry < num_vertices();
///   * every UV set's `corner` has one entry per corner, each < values.size() or kInvalidIndex
///     (that corner has no UV in this set); corner_normal is empty (no normals) or likewise;
///   * face_object / face_group / face_material / face_smoothing are empty or one per face;
///     the first three index their name tables or are kInvalidIndex; smoothing 0 means "off";
///   * vertex_colors is empty or one per vertex;
///   * skin is empty or covers every vertex in canonical form (SkinWeights::check);
///   * every morph target has one finite displacement per vertex.
struct PolyMesh {
  // --- geometry -------------------------------------------------------------------------
  std::vector<Vec3> positions;
  std::vector<Vec3> vertex_colors;  ///< optional per-vertex RGB in [0,1] (OBJ `v x y z r g b`)

  // --- faces (CSR) ----------------------------------------------------------------------
  std::vector<Index> face_offsets{0};
  std::vector<Index> corner_vertex;

  // --- per-corner attributes (pool + per-corner index) ------------------------------------
  std::vector<UvSet> uv_sets;  ///< empty when the mesh has no UVs; each set covers every corner
  std::vector<Vec3> normals;
  std::vector<Index> corner_normal;

  // --- per-face tags ------------------------------------------------------------------------
  std::vector<Index> face_object;     ///< OBJ `o`
  std::vector<Index> face_group;      ///< OBJ `g` (the whole name list of the `g` line)
  std::vector<Index> face_material;   ///< OBJ `usemtl`
  std::vector<Index> face_smoothing;  ///< OBJ `s` (0 = off)
  std::vector<std::string> object_names;
  std::vector<std::string> group_names;
  std::vector<std::string> material_names;
  std::vector<std::string> material_libraries;  ///< OBJ `mtllib` arguments, in file order

  // --- skinning (issue 24) ----------------------------------------------------------------------
  SkinWeights skin;  ///< per-vertex joint influences; empty when the mesh is not skinned

  // --- blend shapes (issue 34) ----------------------------------------------------------------
  std::vector<MorphTarget> morph_targets;  ///< empty when the mesh has none

  // --- sizes ----------------------------------------------------------------------------------
  Index num_vertices() const { return static_cast<Index>(positions.size()); }
  Index num_faces() const { return static_cast<Index>(face_offsets.size() - 1); }
  Index num_corners() const { return static_cast<Index>(corner_vertex.size()); }

  // --- face access ------------------------------------------------------------------------------
  Index face_begin(Index f) const { return face_offsets[f]; }
  Index face_end(Index f) const { return face_offsets[f + 1]; }
  Index face_size(Index f) const { return face_offsets[f + 1] - face_offsets[f]; }
  std::span<const Index> face_vertices(Index f) const {
    return {corner_vertex.data() + face_offsets[f], face_size(f)};
  }
  /// The corner after / before corner c inside face f (c must belong to f).
  Index next_corner(Index f, Index c) const { return c + 1 == face_end(f) ? face_begin(f) : c + 1; }
  Index prev_corner(Index f, Index c) const { return c == face_begin(f) ? face_end(f) - 1 : c - 1; }

  bool has_uvs() const { return !uv_sets.empty(); }
  bool has_normals() const { return !corner_normal.empty(); }

  // --- building ---------------------------------------------------------------------------------
  Index add_vertex(const Vec3& p) {
    positions.push_back(p);
    return num_vertices() - 1;
  }
  /// Appends a face with the given vertices (>= 3). Per-corner attribute arrays that are
  /// present are extended with kInvalidIndex, per-face tags with kInvalidIndex / 0; callers that
  /// know the values overwrite them. Returns the new face id.
  Index add_face(std::span<const Index> vertices);
  Index add_face(std::initializer_list<Index> vertices) {
    return add_face(std::span<const Index>(vertices.begin(), vertices.size()));
  }

  /// Checks the invariants above; returns an empty string when they hold, else a description of
  /// the first violation naming the element ("face 12: corner index 40 out of range").
  std::string check_layout() const;
};

// --- small geometric helpers shared by every stage ---------------------------------------------

/// Bounding box of all vertices (used or not).
BoundingBox bounding_box(const PolyMesh& mesh);

/// Area vector of face f (Newell's method): direction = normal, length = area.
/// Exact for planar polygons; for non-planar ones it is the projected-area vector.
Vec3 face_area_vector(const PolyMesh& mesh, Index f);

/// Unit normal of face f; zero vector when the face has zero area.
Vec3 face_normal(const PolyMesh& mesh, Index f);

/// Centroid of the corner positions of face f.
Vec3 face_centroid(const PolyMesh& mesh, Index f);

/// Triangle-equivalent size of a face of `degree` corners, as the paper counts faces (§3.1:
/// "we treat each quad face as two triangular faces"): k-gon = k - 2.
inline Index tri_equivalent(Index degree) { return degree >= 3 ? degree - 2 : 0; }

/// Sum of tri_equivalent over all faces.
std::uint64_t tri_equivalent_count(const PolyMesh& mesh);

}  // namespace quadlod
