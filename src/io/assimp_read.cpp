// quadlod — the assimp front end of read_scene (include/quadlod/scene.h).
//
// assimp hands over meshes whose vertices are split wherever a corner's attributes differ (and
// FBX/glTF importers give every corner its own vertex), one aiMesh per material. quadlod's
// reduction needs the surface's topology, so the meshes of one node are glued back together:
//
//   aiMesh "body/mat A" ─┐   one PolyMesh: corners glued along edges with opposite half-edges
//   aiMesh "body/mat B" ─┼─► on the same positions (glue_corners), per-corner UV / normal pools
//                        │   (deduplicated by value), face_material from each aiMesh's material
//
// A binary FBX that assimp did not write keeps its own vertices instead of being glued: its
// control points, read by src/io/fbx_binary.cpp and mapped onto assimp's corners with a check
// (src/io/fbx_control_points.h, docs/scenes.md).
//
// No post-process step triangulates or joins vertices (aiProcess_Triangulate /
// JoinIdenticalVertices are not used): polygons stay polygons.
//
// Issue 24 (skins) adds bones / weights in `per_mesh_extras` and skeleton / animations in
// `scene_extras`; nothing else here needs to change for it.
#include "io/assimp_detail.h"
#include "io/fbx_control_points.h"
#include "mesh/union_find.h"
#include "quadlod/scene.h"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <unordered_map>

namespace quadlod {

namespace {

/// Exact bit pattern of up to three floats: the welding and pooling key.
struct FloatKey {
  std::array<std::uint32_t, 3> bits{};
  bool operator==(const FloatKey&) const = default;
};
struct FloatKeyHash {
  std::size_t operator()(const FloatKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint32_t b : k.bits) h = (h ^ b) * 1099511628211ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};
FloatKey key_of(float x, float y, float z) {
  // +0 and -0 weld together: both are the same point.
  const auto b = [](float v) { return std::bit_cast<std::uint32_t>(v == 0.0f ? 0.0f : v); };
  return {{b(x), b(y), b(z)}};
}

/// A pool of values deduplicated by bit pattern.
template <class Value>
struct Pool {
  std::vector<Value>* values = nullptr;
  std::unordered_map<FloatKey, Index, FloatKeyHash> index_of;
  Index add(const FloatKey& key, const Value& value) {
    auto [it, inserted] = index_of.try_emplace(key, static_cast<Index>(values->size()));
    if (inserted) values->push_back(value);
    return it->second;
  }
};

std::string material_name(const aiMaterial& material, unsigned index) {
  aiString name;
  if (material.Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length > 0) return name.C_Str();
  return "material_" + std::to_string(index);
}

SceneMaterial read_material(const aiMaterial& material, unsigned index) {
  SceneMaterial out;
  out.name = material_name(material, index);
  aiColor4D colour;
  if (material.Get(AI_MATKEY_BASE_COLOR, colour) == AI_SUCCESS ||
      material.Get(AI_MATKEY_COLOR_DIFFUSE, colour) == AI_SUCCESS)
    out.base_color = {colour.r, colour.g, colour.b, colour.a};
  aiString texture;
  if (material.GetTexture(aiTextureType_BASE_COLOR, 0, &texture) == AI_SUCCESS ||
      material.GetTexture(aiTextureType_DIFFUSE, 0, &texture) == AI_SUCCESS)
    out.base_color_texture = texture.C_Str();
  return out;
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out(r, c) = m[r][c];
  return out;
}

class SceneBuilder {
 public:
  /// `fbx`: the file's FBX geometries when it is a binary FBX whose control points are its
  /// vertices (fbx_control_points.h), else nullptr (every mesh glued).
  SceneBuilder(const aiScene& ai, const SceneReadOptions& options, const fbx::GeometryRead* fbx)
      : ai_(ai), normal_weld_cos_(std::cos(options.normal_weld_degrees * 3.14159265358979323846 / 180.0)), fbx_(fbx) {}

  Scene build() {
    for (unsigned i = 0; i < ai_.mNumMaterials; ++i) scene_.materials.push_back(read_material(*ai_.mMaterials[i], i));
    if (ai_.mRootNode) add_node(*ai_.mRootNode, kInvalidIndex);
    scene_.cameras = ai_.mNumCameras;
    scene_.lights = ai_.mNumLights;
    scene_.animations = ai_.mNumAnimations;
    scene_extras();
    return std::move(scene_);
  }

 private:
  void add_node(const aiNode& node, Index parent) {
    const Index id = static_cast<Index>(scene_.nodes.size());
    SceneNode out;
    out.name = node.mName.C_Str();
    out.parent = parent;
    out.local = to_eigen(node.mTransformation);
    std::vector<unsigned> group;
    for (unsigned i = 0; i < node.mNumMeshes; ++i)
      if (node.mMeshes[i] < ai_.mNumMeshes) group.push_back(node.mMeshes[i]);
    const std::vector<const aiNode*> folded = per_material_children(node);
    for (const aiNode* child : folded)
      for (unsigned i = 0; i < child->mNumMeshes; ++i)
        if (child->mMeshes[i] < ai_.mNumMeshes) group.push_back(child->mMeshes[i]);
    std::sort(group.begin(), group.end());
    group.erase(std::unique(group.begin(), group.end()), group.end());
    scene_.nodes.push_back(std::move(out));
    if (!group.empty()) {
      const Index mesh = mesh_of_group(group, node);
      if (mesh != kInvalidIndex) scene_.nodes[id].meshes.push_back(mesh);
    }
    for (unsigned i = 0; i < node.mNumChildren; ++i)
      if (std::find(folded.begin(), folded.end(), node.mChildren[i]) == folded.end()) add_node(*node.mChildren[i], id);
  }

  /// assimp's FBX exporter (and so our .fbx files) moves the meshes of a node with several
  /// materials into one child node per material, all named after the mesh, identity transform,
  /// no children of their own:  grid_a → {grid (red), grid (blue)}. Read back as they are, the
  /// mesh would come apart at its material borders. Such children (two or more, one shared
  /// name, under a node without meshes) are folded back into their parent's mesh.
  std::vector<const aiNode*> per_material_children(const aiNode& node) const {
    std::vector<const aiNode*> children;
    if (node.mNumMeshes > 0) return children;
    for (unsigned i = 0; i < node.mNumChildren; ++i) {
      const aiNode* c = node.mChildren[i];
      if (c->mNumChildren > 0 || c->mNumMeshes == 0 || !c->mTransformation.IsIdentity()) continue;
      bool named_after_mesh = true;
      for (unsigned k = 0; k < c->mNumMeshes; ++k)
        named_after_mesh = named_after_mesh && c->mMeshes[k] < ai_.mNumMeshes &&
                           ai_.mMeshes[c->mMeshes[k]]->mName == c->mName;
      if (named_after_mesh && (children.empty() || children[0]->mName == c->mName)) children.push_back(c);
    }
    if (children.size() < 2) children.clear();
    return children;
  }

  /// The Scene mesh of a node's set of aiMeshes; the same set in another node is an instance.
  Index mesh_of_group(const std::vector<unsigned>& group, const aiNode& node) {
    if (auto it = mesh_of_group_.find(group); it != mesh_of_group_.end()) return it->second;
    SceneMesh out;
    // The aiMeshes' name when they share one (a mesh split by material), else the node's.
    out.name = ai_.mMeshes[group[0]]->mName.C_Str();
    for (unsigned m : group)
      if (ai_.mMeshes[m]->mName != ai_.mMeshes[group[0]]->mName) out.name.clear();
    if (out.name.empty()) out.name = node.mName.C_Str();
    weld(group, out.mesh);
    Index id = kInvalidIndex;
    if (out.mesh.num_faces() > 0) {
      for (unsigned m : group) per_mesh_extras(*ai_.mMeshes[m], out);
      read_morph_targets(group, out.mesh);
      id = static_cast<Index>(scene_.meshes.size());
      scene_.meshes.push_back(std::move(out));
    }
    mesh_of_group_.emplace(group, id);
    return id;
  }

  /// The meshes of `group` as one PolyMesh (see the file comment): gather the faces, decide
  /// which corners are one vertex (glue_corners), then build pools and faces.
  void weld(const std::vector<unsigned>& group, PolyMesh& mesh) {
    welded_of_.clear();  // issue 24: the map per_mesh_extras reads, for this group only
    unsigned uv_sets = 0;
    bool normals = false, colours = false;
    for (unsigned m : group) {
      const aiMesh& a = *ai_.mMeshes[m];
      uv_sets = std::max(uv_sets, a.GetNumUVChannels());
      normals = normals || a.HasNormals();
      colours = colours || a.HasVertexColors(0);
    }
    // A binary FBX's own vertices (its control points, float64) where every corner maps onto
    // one; else the corners glued along edges.
    Corners corners;
    Index vertex_count = 0;
    std::vector<Index> vertex_of;
    std::vector<Vec3> exact_positions;
    if (fbx_ && from_control_points(group, corners, vertex_of, exact_positions)) {
      vertex_count = static_cast<Index>(exact_positions.size());
      ++scene_.fbx_control_point_meshes;
    } else {
      if (fbx_ && scene_.fbx_note.empty())
        scene_.fbx_note = "mesh '" + fbx::printable(ai_.mMeshes[group[0]]->mName.C_Str()) +
                          "': corners do not map onto the FBX control points; glued along edges";
      corners = gather_corners(group);
      vertex_of = glue_corners(corners, vertex_count);
    }

    mesh.positions.resize(vertex_count);
    std::vector<char> placed(vertex_count, 0);
    if (colours) mesh.vertex_colors.assign(vertex_count, Vec3(1, 1, 1));
    mesh.uv_sets.resize(uv_sets);
    std::vector<Pool<Vec2>> uv_pools(uv_sets);
    for (unsigned k = 0; k < uv_sets; ++k) uv_pools[k].values = &mesh.uv_sets[k].values;
    Pool<Vec3> normal_pool{&mesh.normals, {}};
    std::vector<std::vector<Index>> normals_at(vertex_count);  // per vertex: the normal entries its corners use
    std::map<std::string, Index> material_of;
    for (unsigned m : group) {
      const aiMesh& a = *ai_.mMeshes[m];
      for (unsigned k = 0; k < uv_sets; ++k)
        if (mesh.uv_sets[k].name.empty() && a.HasTextureCoordsName(k))
          mesh.uv_sets[k].name = a.mTextureCoordsNames[k]->C_Str();
    }
    for (std::size_t f = 0; f + 1 < corners.face_offsets.size(); ++f) {
      const Index begin = corners.face_offsets[f], end = corners.face_offsets[f + 1];
      // Gluing can (rarely) bring two corners of one face onto one vertex: such a face is dropped.
      bool repeated = false;
      for (Index c = begin; c < end && !repeated; ++c)
        for (Index d = c + 1; d < end && !repeated; ++d) repeated = vertex_of[c] == vertex_of[d];
      if (repeated) {
        ++scene_.dropped_primitives;
        continue;
      }
      const aiMesh& a = *ai_.mMeshes[corners.mesh[begin]];
      std::vector<Index>& welded_of = welded_of_[&a];  // issue 24: for the bone weights
      if (welded_of.empty()) welded_of.assign(a.mNumVertices, kInvalidIndex);
      for (Index c = begin; c < end; ++c) {
        const unsigned v = corners.vertex[c];
        const Index w = vertex_of[c];
        if (welded_of[v] == kInvalidIndex) welded_of[v] = w;
        if (!placed[w]) {
          placed[w] = 1;
          mesh.positions[w] = exact_positions.empty() ? Vec3(a.mVertices[v].x, a.mVertices[v].y, a.mVertices[v].z)
                                                      : exact_positions[w];
          if (colours && a.HasVertexColors(0)) {
            const aiColor4D& col = a.mColors[0][v];
            mesh.vertex_colors[w] = Vec3(col.r, col.g, col.b);
          }
        }
        mesh.corner_vertex.push_back(w);
        for (unsigned k = 0; k < uv_sets; ++k) {
          Index uv = kInvalidIndex;
          if (a.HasTextureCoords(k)) {
            const aiVector3D& t = a.mTextureCoords[k][v];
            uv = uv_pools[k].add(key_of(t.x, t.y, 0.0f), Vec2(t.x, t.y));
          }
          mesh.uv_sets[k].corner.push_back(uv);
        }
        if (normals) {
          Index n = kInvalidIndex;
          if (a.HasNormals()) {
            const aiVector3D& t = a.mNormals[v];
            n = normal_pool.add(key_of(t.x, t.y, t.z), Vec3(t.x, t.y, t.z));
            n = weld_normal(mesh.normals, normals_at[w], n);
          }
          mesh.corner_normal.push_back(n);
        }
      }
      mesh.face_offsets.push_back(mesh.num_corners());
      if (!scene_.materials.empty()) {
        Index material = kInvalidIndex;
        if (a.mMaterialIndex < scene_.materials.size()) {
          const std::string& name = scene_.materials[a.mMaterialIndex].name;
          auto [it, inserted] = material_of.try_emplace(name, static_cast<Index>(mesh.material_names.size()));
          if (inserted) mesh.material_names.push_back(name);
          material = it->second;
        }
        mesh.face_material.push_back(material);
      }
    }
    // Vertices only used by dropped faces: compact them away.
    compact_unused(mesh, placed);
    // Issue 24: the bone-weight map follows the compaction (compact_unused keeps the order).
    std::vector<Index> new_id(placed.size(), kInvalidIndex);
    for (Index v = 0, n = 0; v < placed.size(); ++v)
      if (placed[v]) new_id[v] = n++;
    for (auto& [ai_mesh, map] : welded_of_)
      for (Index& w : map)
        if (w != kInvalidIndex) w = new_id[w];
  }

  /// The faces of a group's aiMeshes as corners: which aiMesh, which of its vertices, which
  /// distinct position. Consecutive corners on one position are merged; faces that still use a
  /// position twice or have fewer than 3 corners are dropped (counted).
  struct Corners {
    std::vector<unsigned> mesh, vertex;
    std::vector<Index> position;
    std::vector<Index> face_offsets{0};
  };

  /// The group's faces over the FBX control points (fbx::control_point_faces): each corner's
  /// vertex is its control point, so `position` (what the drop rules compare) is the vertex too.
  bool from_control_points(const std::vector<unsigned>& group, Corners& corners, std::vector<Index>& vertex_of,
                           std::vector<Vec3>& positions) const {
    fbx::ControlPointFaces faces;
    if (!fbx::control_point_faces(ai_, group, fbx_->geometries, faces)) return false;
    corners.mesh = std::move(faces.mesh);
    corners.vertex = std::move(faces.mesh_vertex);
    corners.position = faces.vertex;
    corners.face_offsets = std::move(faces.face_offsets);
    vertex_of = std::move(faces.vertex);
    positions = std::move(faces.positions);
    return true;
  }
  Corners gather_corners(const std::vector<unsigned>& group) {
    Corners out;
    std::unordered_map<FloatKey, Index, FloatKeyHash> position_of;
    std::vector<unsigned> face;
    for (unsigned m : group) {
      const aiMesh& a = *ai_.mMeshes[m];
      std::vector<Index> position(a.mNumVertices);
      for (unsigned v = 0; v < a.mNumVertices; ++v) {
        const aiVector3D& p = a.mVertices[v];
        position[v] = position_of.try_emplace(key_of(p.x, p.y, p.z), static_cast<Index>(position_of.size())).first->second;
      }
      for (unsigned f = 0; f < a.mNumFaces; ++f) {
        const aiFace& af = a.mFaces[f];
        face.clear();
        for (unsigned c = 0; c < af.mNumIndices; ++c) {
          const unsigned v = af.mIndices[c];
          if (v >= a.mNumVertices) { face.clear(); break; }
          if (!face.empty() && position[face.back()] == position[v]) continue;
          face.push_back(v);
        }
        while (face.size() > 1 && position[face.front()] == position[face.back()]) face.pop_back();
        bool repeated = face.size() < 3;
        for (std::size_t i = 0; i < face.size() && !repeated; ++i)
          for (std::size_t j = i + 1; j < face.size() && !repeated; ++j) repeated = position[face[i]] == position[face[j]];
        if (repeated) {
          ++scene_.dropped_primitives;
          continue;
        }
        for (unsigned v : face) {
          out.mesh.push_back(m);
          out.vertex.push_back(v);
          out.position.push_back(position[v]);
        }
        out.face_offsets.push_back(static_cast<Index>(out.position.size()));
      }
    }
    return out;
  }

  /// Which corners are one vertex. Corners sharing an aiMesh vertex are (the file says so). Then
  /// the surface is glued along its edges, not at its points:
  ///
  ///     face A  a0 ──► a1          two half-edges on the same two positions, running opposite
  ///             b1 ◄── b0  face B  ways: A and B are neighbours, a0 ~ b1 and a1 ~ b0
  ///
  /// so a seam the exporter split comes back, while parts that only touch at a point, or lie on
  /// top of each other, stay apart — welding by position would join them into non-manifold
  /// vertices and edges, and doubled surfaces into repeated faces. Where more than two half-edges
  /// share a position pair, each pairs with the first later opposite one in file order (a doubled
  /// card: its own faces come next to each other). Half-edges running the same way are not
  /// glued: that is how the boundaries of a doubled card meet, and the price is that a neighbour
  /// with the opposite orientation comes back across a crack (two boundary edges) where the
  /// source had one inconsistently oriented edge. Returns a vertex per corner, numbered by first
  /// corner.
  std::vector<Index> glue_corners(const Corners& corners, Index& vertex_count) const {
    const Index n = static_cast<Index>(corners.position.size());
    UnionFind sets(n);
    std::unordered_map<std::uint64_t, Index> first_use;  // (aiMesh, vertex) → corner
    for (Index c = 0; c < n; ++c) {
      const std::uint64_t key = std::uint64_t{corners.mesh[c]} << 32 | corners.vertex[c];
      const auto [it, inserted] = first_use.try_emplace(key, c);
      if (!inserted) sets.unite(it->second, c);
    }
    // Half-edge c runs from corner c to the next corner of its face.
    std::vector<Index> next(n);
    for (std::size_t f = 0; f + 1 < corners.face_offsets.size(); ++f)
      for (Index c = corners.face_offsets[f]; c < corners.face_offsets[f + 1]; ++c)
        next[c] = c + 1 == corners.face_offsets[f + 1] ? corners.face_offsets[f] : c + 1;
    std::unordered_map<std::uint64_t, std::vector<Index>> half_edges;  // position pair → half-edges, file order
    for (Index c = 0; c < n; ++c) {
      const Index p = corners.position[c], q = corners.position[next[c]];
      half_edges[std::uint64_t{std::min(p, q)} << 32 | std::max(p, q)].push_back(c);
    }
    const auto glue = [&](Index c, Index d) {  // c runs p → q, d runs q → p
      sets.unite(c, next[d]);
      sets.unite(next[c], d);
    };
    std::vector<char> paired;
    for (const auto& [key, list] : half_edges) {
      if (list.size() < 2) continue;
      paired.assign(list.size(), 0);
      for (std::size_t i = 0; i < list.size(); ++i) {
        if (paired[i]) continue;
        for (std::size_t j = i + 1; j < list.size(); ++j)
          if (!paired[j] && corners.position[list[j]] == corners.position[next[list[i]]]) {
            glue(list[i], list[j]);
            paired[i] = paired[j] = 1;
            break;
          }
      }
    }
    return sets.dense_labels(vertex_count);
  }

  /// Drops the vertices no kept face uses (`used` per vertex) and renumbers the corners.
  static void compact_unused(PolyMesh& mesh, const std::vector<char>& used) {
    if (std::all_of(used.begin(), used.end(), [](char u) { return u != 0; })) return;
    std::vector<Index> new_id(used.size(), kInvalidIndex);
    Index count = 0;
    for (std::size_t v = 0; v < used.size(); ++v)
      if (used[v]) {
        new_id[v] = count;
        mesh.positions[count] = mesh.positions[v];
        if (!mesh.vertex_colors.empty()) mesh.vertex_colors[count] = mesh.vertex_colors[v];
        ++count;
      }
    mesh.positions.resize(count);
    if (!mesh.vertex_colors.empty()) mesh.vertex_colors.resize(count);
    for (Index& v : mesh.corner_vertex) v = new_id[v];
  }

  /// The normal entry a corner of a vertex uses: an entry another corner of that vertex already
  /// uses when it lies within the weld angle (SceneReadOptions::normal_weld_degrees), else `n`.
  Index weld_normal(const std::vector<Vec3>& pool, std::vector<Index>& at_vertex, Index n) const {
    for (Index used : at_vertex) {
      if (used == n) return n;
      const double lengths = pool[used].norm() * pool[n].norm();
      if (lengths > 0 && pool[used].dot(pool[n]) >= normal_weld_cos_ * lengths) return used;
    }
    at_vertex.push_back(n);
    return n;
  }

  /// Issue 24: bones and weights of aiMesh `a` into out.mesh.skin (an aiMesh vertex maps to the
  /// welded vertex its first face corner took in weld(), recorded in welded_of_). A welded vertex
  /// that an earlier aiMesh of the group already weighted keeps those weights (the same vertex in
  /// two primitives carries the same influences; adding both would count them twice).
  void per_mesh_extras(const aiMesh& a, SceneMesh& out) {
    if (!a.HasBones()) return;
    PolyMesh& mesh = out.mesh;
    const auto recorded = welded_of_.find(&a);
    if (recorded == welded_of_.end()) return;  // no face of `a` survived the weld
    const std::vector<Index>& welded_of = recorded->second;
    std::vector<std::vector<Influence>> lists(mesh.num_vertices());
    std::vector<std::uint8_t> weighted_before(mesh.num_vertices(), 0);
    if (!mesh.skin.empty())
      for (Index v = 0; v < mesh.num_vertices(); ++v) {
        lists[v] = influences_of(mesh.skin, v);
        weighted_before[v] = !lists[v].empty();
      }
    for (unsigned b = 0; b < a.mNumBones; ++b) {
      const aiBone& bone = *a.mBones[b];
      const Index joint = joint_of(bone.mName.C_Str(), to_eigen(bone.mOffsetMatrix));
      for (unsigned w = 0; w < bone.mNumWeights; ++w) {
        const aiVertexWeight& vw = bone.mWeights[w];
        if (vw.mVertexId >= a.mNumVertices || !(vw.mWeight > 0.0f)) continue;
        const Index welded = welded_of[vw.mVertexId];
        if (welded == kInvalidIndex || weighted_before[welded]) continue;  // used by no face / weighted before
        lists[welded].push_back({joint, vw.mWeight});
      }
    }
    mesh.skin = make_skin_weights(lists);
  }

  /// Issue 34: the blend shapes of a group's aiMeshes (aiMesh::mAnimMeshes, absolute positions
  /// per aiMesh vertex) as per-vertex displacements of the welded mesh. Target k of every aiMesh
  /// of the group is one MorphTarget (glTF: every primitive of a mesh has the same targets; FBX:
  /// one channel per shape), named by the first aiMesh that names it. A welded vertex takes its
  /// displacement from the first aiMesh vertex that maps onto it (the corners of one vertex split
  /// at a UV seam carry the same shape). The default weight is glTF's `mesh.weights`; for a
  /// binary FBX the channel's DeformPercent / 100 (fbx_deform_percent: assimp's reader gives the
  /// channel's full weight instead, 1), else 0. Anim meshes without positions give no target.
  void read_morph_targets(const std::vector<unsigned>& group, PolyMesh& mesh) {
    unsigned targets = 0;
    for (unsigned m : group) targets = std::max(targets, ai_.mMeshes[m]->mNumAnimMeshes);
    if (targets == 0) return;
    const bool gltf = source_is_gltf();
    std::vector<MorphTarget> out(targets);
    std::vector<char> has_positions(targets, 0);
    for (MorphTarget& t : out) t.displacement.assign(mesh.num_vertices(), Vec3::Zero());
    std::vector<std::vector<char>> set(targets, std::vector<char>(mesh.num_vertices(), 0));
    for (unsigned m : group) {
      const aiMesh& a = *ai_.mMeshes[m];
      const auto recorded = welded_of_.find(&a);
      if (recorded == welded_of_.end()) continue;  // no face of `a` survived the weld
      const std::vector<Index>& welded_of = recorded->second;
      for (unsigned k = 0; k < a.mNumAnimMeshes; ++k) {
        const aiAnimMesh* am = a.mAnimMeshes[k];
        if (!am || !am->mVertices || am->mNumVertices != a.mNumVertices) continue;
        has_positions[k] = 1;
        if (out[k].name.empty() && am->mName.length > 0) {
          out[k].name = am->mName.C_Str();
          if (gltf) out[k].default_weight = am->mWeight;
          if (const auto it = fbx_deform_percent.find(out[k].name); it != fbx_deform_percent.end())
            out[k].default_weight = it->second / 100.0;
        } else if (gltf && out[k].default_weight == 0.0) {
          out[k].default_weight = am->mWeight;
        }
        for (unsigned v = 0; v < a.mNumVertices; ++v) {
          const Index w = welded_of[v];
          if (w == kInvalidIndex || set[k][w]) continue;
          set[k][w] = 1;
          const aiVector3D d = am->mVertices[v] - a.mVertices[v];
          out[k].displacement[w] = Vec3(d.x, d.y, d.z);
          if (!out[k].displacement[w].allFinite() && error_.empty())
            error_ = "mesh '" + fbx::printable(a.mName.C_Str()) + "': blend shape '" + fbx::printable(am->mName.C_Str()) +
                     "': vertex " + std::to_string(v) + ": displacement is not finite";
        }
      }
    }
    for (unsigned k = 0; k < targets; ++k)
      if (has_positions[k]) mesh.morph_targets.push_back(std::move(out[k]));
  }

  /// The joint of a bone name, created on first use with the bone's offset matrix as B⁻¹.
  Index joint_of(const std::string& name, const Eigen::Matrix4d& inverse_bind) {
    auto [it, inserted] = joint_index_.try_emplace(name, static_cast<Index>(scene_.rig.skeleton.joints.size()));
    if (inserted) {
      Joint j;
      j.name = name;
      j.inverse_bind = inverse_bind;
      scene_.rig.skeleton.joints.push_back(j);
    }
    return it->second;
  }

  bool source_is_gltf() const {
    aiString format;
    return ai_.mMetaData && ai_.mMetaData->Get("SourceAsset_Format", format) &&
           std::string(format.C_Str()).find("glTF") != std::string::npos;
  }

  static Eigen::Matrix4d world_of(const aiNode* node) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (const aiNode* n = node; n; n = n->mParent) m = to_eigen(n->mTransformation) * m;
    return m;
  }

  /// Issue 24: the skeleton from the nodes the bones name, and ai_.mAnimations on them.
  void scene_extras() {
    Skeleton& sk = scene_.rig.skeleton;
    if (sk.joints.empty() || !ai_.mRootNode) return;
    auto is_joint_below = [&](const aiNode* n) {  // some ancestor of n (n included) is a joint
      for (; n; n = n->mParent)
        if (joint_index_.count(n->mName.C_Str())) return true;
      return false;
    };
    bool root_set = false;
    // Joints grow while this runs: a non-joint node between two joints becomes a joint (no
    // weights, identity B⁻¹) so that its transform stays in the chain.
    for (Index j = 0; j < sk.joints.size(); ++j) {
      const aiNode* node = ai_.mRootNode->FindNode(sk.joints[j].name.c_str());
      if (!node) continue;  // a bone without a node: a root at the origin
      aiVector3D scaling, position;
      aiQuaternion rotation;
      node->mTransformation.Decompose(scaling, rotation, position);
      sk.joints[j].rest.translation = Vec3(position.x, position.y, position.z);
      sk.joints[j].rest.rotation = Quat(rotation.w, rotation.x, rotation.y, rotation.z).normalized();
      sk.joints[j].rest.scale = Vec3(scaling.x, scaling.y, scaling.z);
      const aiNode* p = node->mParent;
      if (p && is_joint_below(p)) {
        sk.joints[j].parent = joint_of(p->mName.C_Str(), Eigen::Matrix4d::Identity());
      } else if (!root_set) {
        sk.root_transform = p ? world_of(p) : Eigen::Matrix4d::Identity();
        root_set = true;
      }
    }
    // Bind space. glTF binds in the skinned mesh's own space and ignores its node's transform
    // (glTF 2.0 §3.7.3.3): the inverse bind matrices already map it. assimp's other importers
    // (FBX clusters, Collada) give offset matrices from mesh space to bone space with the mesh
    // node's world transform W applied by the skinning, so G·B⁻¹·v lands in world space; W⁻¹ in
    // front of the roots brings the pose back to the mesh's space, and the bind pose gives the
    // unposed mesh in both cases (skin.h's convention).
    if (!source_is_gltf()) {
      for (Index n = 0; n < scene_.nodes.size(); ++n) {
        bool skinned = false;
        for (Index m : scene_.nodes[n].meshes) skinned |= !scene_.meshes[m].mesh.skin.empty();
        if (!skinned) continue;
        sk.root_transform = scene_.world_transform(n).inverse() * sk.root_transform;
        scene_.skin_frame_node = n;
        break;
      }
    }
    for (unsigned a = 0; a < ai_.mNumAnimations; ++a) {
      const aiAnimation& in = *ai_.mAnimations[a];
      const double ticks = in.mTicksPerSecond > 0.0 ? in.mTicksPerSecond : 25.0;
      Animation anim;
      anim.name = in.mName.length ? in.mName.C_Str() : "animation" + std::to_string(a);
      for (unsigned c = 0; c < in.mNumChannels; ++c) {
        const aiNodeAnim& ch = *in.mChannels[c];
        const auto it = joint_index_.find(ch.mNodeName.C_Str());
        if (it == joint_index_.end()) continue;
        AnimationChannel t, r, s;
        t.joint = r.joint = s.joint = it->second;
        t.path = AnimationChannel::Path::Translation;
        r.path = AnimationChannel::Path::Rotation;
        s.path = AnimationChannel::Path::Scale;
        for (unsigned k = 0; k < ch.mNumPositionKeys; ++k) {
          t.times.push_back(ch.mPositionKeys[k].mTime / ticks);
          const aiVector3D& v = ch.mPositionKeys[k].mValue;
          t.values.emplace_back(v.x, v.y, v.z, 0.0);
        }
        for (unsigned k = 0; k < ch.mNumRotationKeys; ++k) {
          r.times.push_back(ch.mRotationKeys[k].mTime / ticks);
          const aiQuaternion& q = ch.mRotationKeys[k].mValue;
          r.values.emplace_back(q.x, q.y, q.z, q.w);
        }
        for (unsigned k = 0; k < ch.mNumScalingKeys; ++k) {
          s.times.push_back(ch.mScalingKeys[k].mTime / ticks);
          const aiVector3D& v = ch.mScalingKeys[k].mValue;
          s.values.emplace_back(v.x, v.y, v.z, 0.0);
        }
        for (AnimationChannel* x : {&t, &r, &s})
          if (!x->times.empty() && std::is_sorted(x->times.begin(), x->times.end())) anim.channels.push_back(std::move(*x));
      }
      if (!anim.channels.empty()) scene_.rig.animations.push_back(std::move(anim));
    }
  }

  const aiScene& ai_;
  const double normal_weld_cos_;
  const fbx::GeometryRead* fbx_;
  std::string error_;  // issue 34: the first bad blend shape value (the read fails with it)
 public:
  const std::string& error() const { return error_; }
  /// Issue 34: a binary FBX's blend shape channels' DeformPercent by channel name (assimp 5.2
  /// hands over FullWeights, not the channel's current value, which Blender writes there).
  std::map<std::string, double> fbx_deform_percent;
 private:
  Scene scene_;
  std::map<std::vector<unsigned>, Index> mesh_of_group_;
  std::map<std::string, Index> joint_index_;  // issue 24: joint of each bone name
  std::map<const aiMesh*, std::vector<Index>> welded_of_;  // issue 24: aiMesh vertex → welded vertex
};

/// The post-processing steps: checks, and points / lines removed — nothing that triangulates,
/// joins vertices or reorders faces.
constexpr unsigned kImportSteps = aiProcess_ValidateDataStructure | aiProcess_SortByPType;

void configure(Assimp::Importer& importer) {
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // FBX pivots as separate "$AssimpFbx$" helper nodes would change the hierarchy on a round trip.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
}

/// `bytes`: the file's bytes when it may be a binary FBX (else empty): its control points give
/// the meshes their vertices (fbx_control_points.h). A binary FBX that assimp reads but our
/// parser refuses, or one written by assimp, is glued as before, with Scene::fbx_note saying why.
std::map<std::string, double> read_fbx_deform_percent(const aiScene& ai, std::string_view bytes);

SceneReadResult finish(const aiScene* ai, Assimp::Importer& importer, const std::string& name,
                       const SceneReadOptions& options, std::string_view bytes) {
  SceneReadResult result;
  if (!ai) {
    std::string message = importer.GetErrorString();
    if (message.empty()) message = "unreadable scene";
    result.error = name + ": assimp: " + message;
    return result;
  }
  fbx::GeometryRead geometries;
  std::string note;
  const bool binary_fbx = options.fbx_control_points && fbx::is_binary_fbx(bytes);
  if (binary_fbx) {
    geometries = fbx::read_mesh_geometries(bytes);
    if (!geometries.ok())
      note = "FBX control points not read (" + geometries.error + "); corners glued along edges";
    else if (!fbx::control_points_are_vertices(geometries))
      note = "FBX written by assimp (per-corner control points); corners glued along edges";
  }
  const bool use = binary_fbx && note.empty();
  SceneBuilder builder(*ai, options, use ? &geometries : nullptr);
  if (fbx::is_binary_fbx(bytes)) builder.fbx_deform_percent = read_fbx_deform_percent(*ai, bytes);
  result.scene = builder.build();
  if (!builder.error().empty()) {
    result = SceneReadResult{};
    result.error = name + ": " + builder.error();
    return result;
  }
  if (!note.empty()) result.scene.fbx_note = note;
  return result;
}

/// Issue 34: DeformPercent of every BlendShapeChannel of a binary FBX, by channel name (the
/// name before the "\0\1" class separator); empty when no aiMesh has blend shapes (the file is
/// not parsed again) or the record tree does not parse.
std::map<std::string, double> read_fbx_deform_percent(const aiScene& ai, std::string_view bytes) {
  std::map<std::string, double> out;
  bool shapes = false;
  for (unsigned m = 0; m < ai.mNumMeshes; ++m) shapes = shapes || ai.mMeshes[m]->mNumAnimMeshes > 0;
  if (!shapes) return out;
  const fbx::ParseResult parsed = fbx::parse_binary_fbx(bytes);
  const fbx::Record* objects = parsed.ok() ? parsed.document.find("Objects") : nullptr;
  if (!objects) return out;
  for (const fbx::Record& r : objects->children) {
    if (r.name != "Deformer" || r.string_property(2) != "BlendShapeChannel") continue;
    const fbx::Record* percent = r.find("DeformPercent");
    if (!percent || percent->properties.empty() || percent->properties[0].reals.empty()) continue;
    std::string name = r.string_property(1);
    name = name.substr(0, name.find(std::string_view("\0\1", 2)));
    out.try_emplace(name, percent->properties[0].reals[0]);
  }
  return out;
}

/// The file's bytes when it starts with the binary FBX magic, else "".
std::string binary_fbx_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char head[32] = {};
  in.read(head, sizeof head);
  if (!fbx::is_binary_fbx(std::string_view(head, static_cast<std::size_t>(in.gcount())))) return {};
  in.clear();
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size <= 0) return {};
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  in.read(bytes.data(), size);
  if (in.gcount() != size) return {};
  return bytes;
}

// A binary FBX whose record tree does not hold together (offsets out of order or past the end,
// lengths that wrap) is refused by quadlod's own reader before assimp sees it: assimp 5.2's
// tokenizer aborts the process on some of them (ai_assert in FBXBinaryTokenizer.cpp, found by
// fuzz target assimp_fbx; tests/fuzz_regressions/assimp_fbx). "" when `bytes` is empty or fine.
std::string refused_fbx(std::string_view bytes) {
  if (bytes.empty()) return {};
  const fbx::ParseResult parsed = fbx::parse_binary_fbx(bytes);
  return parsed.ok() ? std::string() : parsed.error;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

namespace io_detail {
SceneReadResult read_scene_with_assimp(const std::filesystem::path& path, const SceneReadOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    SceneReadResult result;
    result.error = "cannot read " + path.string() + ": " +
                   (std::filesystem::exists(path, ec) ? "not a regular file" : "No such file or directory");
    return result;
  }
  const std::string fbx_bytes = binary_fbx_bytes(path);
  if (std::string error = refused_fbx(fbx_bytes); !error.empty()) {
    SceneReadResult result;
    result.error = path.string() + ": " + error;
    return result;
  }
  Assimp::Importer importer;
  configure(importer);
  const aiScene* ai = importer.ReadFile(path.string(), kImportSteps);
  SceneReadResult result = finish(ai, importer, path.string(), options, fbx_bytes);
  result.seconds = seconds_since(start);
  return result;
}
}  // namespace io_detail

SceneReadResult read_scene_from_memory(const void* data, std::size_t size, std::string_view hint,
                                       const std::string& name, const SceneReadOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::string_view bytes(static_cast<const char*>(data), size);
  if (std::string error = refused_fbx(fbx::is_binary_fbx(bytes) ? bytes : std::string_view()); !error.empty()) {
    SceneReadResult result;
    result.error = name + ": " + error;
    return result;
  }
  Assimp::Importer importer;
  configure(importer);
  const std::string hint_text(hint);
  const aiScene* ai = size == 0 ? nullptr : importer.ReadFileFromMemory(data, size, kImportSteps, hint_text.c_str());
  SceneReadResult result;
  if (size == 0)
    result.error = name + ": empty buffer";
  else
    result = finish(ai, importer, name, options, std::string_view(static_cast<const char*>(data), size));
  result.seconds = seconds_since(start);
  return result;
}

}  // namespace quadlod
