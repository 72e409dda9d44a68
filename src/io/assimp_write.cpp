// quadlod — the assimp back end of write_scene (include/quadlod/scene.h): builds an aiScene
// from a Scene and hands it to assimp's exporters (glb2, fbx, collada) in memory, so the file is
// then written atomically like every other output.
//
// PolyMesh attributes are per corner (pools); assimp's, like glTF's and FBX's, are per vertex.
// Each (vertex, UV index of every set, normal index) combination a corner uses becomes one
// aiMesh vertex, and each mesh becomes one aiMesh per material it uses, all referenced by the
// same nodes. glTF holds triangles only, so for it polygons are fan-triangulated here.
#include "io/assimp_detail.h"

#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>

#include <map>
#include <string_view>
#include <memory>
#include <unordered_map>

namespace quadlod::io_detail {

namespace {

struct CornerKeyHash {
  std::size_t operator()(const std::vector<Index>& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (Index v : k) h = (h ^ v) * 1099511628211ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

aiMaterial* make_material(const SceneMaterial& material) {
  auto* out = new aiMaterial();
  const aiString name(material.name);
  out->AddProperty(&name, AI_MATKEY_NAME);
  const aiColor4D colour(static_cast<float>(material.base_color[0]), static_cast<float>(material.base_color[1]),
                         static_cast<float>(material.base_color[2]), static_cast<float>(material.base_color[3]));
  out->AddProperty(&colour, 1, AI_MATKEY_COLOR_DIFFUSE);
  out->AddProperty(&colour, 1, AI_MATKEY_BASE_COLOR);
  if (!material.base_color_texture.empty()) {
    const aiString texture(material.base_color_texture);
    out->AddProperty(&texture, AI_MATKEY_TEXTURE_DIFFUSE(0));
    out->AddProperty(&texture, AI_MATKEY_TEXTURE(aiTextureType_BASE_COLOR, 0));
  }
  return out;
}

/// One aiMesh of the faces of `mesh` whose material resolves to `material` (faces listed).
aiMesh* make_mesh(const PolyMesh& mesh, const std::string& name, const std::vector<Index>& faces, unsigned material,
                  bool triangulate) {
  const unsigned uv_sets = std::min<unsigned>(static_cast<unsigned>(mesh.uv_sets.size()), AI_MAX_NUMBER_OF_TEXTURECOORDS);
  const bool normals = mesh.has_normals();
  const bool colours = mesh.vertex_colors.size() == mesh.positions.size() && !mesh.positions.empty();
  std::unordered_map<std::vector<Index>, unsigned, CornerKeyHash> vertex_of;
  std::vector<Index> source_corner;  // a corner of each output vertex (its attributes)
  std::vector<std::vector<unsigned>> polygons;
  std::vector<Index> key(1 + uv_sets + (normals ? 1 : 0));
  for (Index f : faces) {
    std::vector<unsigned> polygon;
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) {
      key[0] = mesh.corner_vertex[c];
      for (unsigned k = 0; k < uv_sets; ++k) key[1 + k] = mesh.uv_sets[k].corner[c];
      if (normals) key[1 + uv_sets] = mesh.corner_normal[c];
      auto [it, inserted] = vertex_of.try_emplace(key, static_cast<unsigned>(source_corner.size()));
      if (inserted) source_corner.push_back(c);
      polygon.push_back(it->second);
    }
    if (triangulate && polygon.size() > 3) {
      for (std::size_t i = 1; i + 1 < polygon.size(); ++i) polygons.push_back({polygon[0], polygon[i], polygon[i + 1]});
    } else {
      polygons.push_back(std::move(polygon));
    }
  }
  auto* out = new aiMesh();
  out->mName = aiString(name);
  out->mMaterialIndex = material;
  const unsigned n = static_cast<unsigned>(source_corner.size());
  out->mNumVertices = n;
  out->mVertices = new aiVector3D[n];
  if (normals) out->mNormals = new aiVector3D[n];
  if (colours) out->mColors[0] = new aiColor4D[n];
  for (unsigned k = 0; k < uv_sets; ++k) {
    out->mTextureCoords[k] = new aiVector3D[n];
    out->mNumUVComponents[k] = 2;
    if (!mesh.uv_sets[k].name.empty()) out->SetTextureCoordsName(k, aiString(mesh.uv_sets[k].name));
  }
  for (unsigned i = 0; i < n; ++i) {
    const Index c = source_corner[i];
    const Vec3& p = mesh.positions[mesh.corner_vertex[c]];
    out->mVertices[i] = aiVector3D(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    if (normals) {
      const Index ni = mesh.corner_normal[c];
      const Vec3 v = ni == kInvalidIndex ? Vec3::Zero() : mesh.normals[ni];
      out->mNormals[i] = aiVector3D(static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
    }
    if (colours) {
      const Vec3& col = mesh.vertex_colors[mesh.corner_vertex[c]];
      out->mColors[0][i] = aiColor4D(static_cast<float>(col.x()), static_cast<float>(col.y()), static_cast<float>(col.z()), 1.0f);
    }
    for (unsigned k = 0; k < uv_sets; ++k) {
      const Index ti = mesh.uv_sets[k].corner[c];
      const Vec2 t = ti == kInvalidIndex ? Vec2::Zero() : mesh.uv_sets[k].values[ti];
      out->mTextureCoords[k][i] = aiVector3D(static_cast<float>(t.x()), static_cast<float>(t.y()), 0.0f);
    }
  }
  out->mNumFaces = static_cast<unsigned>(polygons.size());
  out->mFaces = new aiFace[out->mNumFaces];
  unsigned types = 0;
  for (unsigned f = 0; f < out->mNumFaces; ++f) {
    const std::vector<unsigned>& polygon = polygons[f];
    aiFace& face = out->mFaces[f];
    face.mNumIndices = static_cast<unsigned>(polygon.size());
    face.mIndices = new unsigned[polygon.size()];
    std::copy(polygon.begin(), polygon.end(), face.mIndices);
    types |= polygon.size() == 3 ? aiPrimitiveType_TRIANGLE : aiPrimitiveType_POLYGON;
  }
  out->mPrimitiveTypes = types;
  return out;
}

aiMatrix4x4 to_assimp(const Eigen::Matrix4d& m) {
  aiMatrix4x4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[r][c] = static_cast<float>(m(r, c));
  return out;
}

std::unique_ptr<aiScene> build_scene(const Scene& scene, bool triangulate) {
  auto ai = std::make_unique<aiScene>();
  // Materials: the scene's, plus one default for faces whose material name is unknown (assimp's
  // exporters need at least one material).
  std::vector<aiMaterial*> materials;
  std::map<std::string, unsigned> material_of;
  for (const SceneMaterial& m : scene.materials) {
    material_of.try_emplace(m.name, static_cast<unsigned>(materials.size()));
    materials.push_back(make_material(m));
  }
  unsigned default_material = ~0u;
  const auto fallback = [&]() {
    if (default_material == ~0u) {
      default_material = static_cast<unsigned>(materials.size());
      SceneMaterial m;
      m.name = "quadlod_default";
      materials.push_back(make_material(m));
    }
    return default_material;
  };

  // Meshes: per scene mesh, the aiMeshes (one per material) that stand for it.
  std::vector<aiMesh*> meshes;
  std::vector<std::vector<unsigned>> ai_meshes_of(scene.meshes.size());
  for (std::size_t s = 0; s < scene.meshes.size(); ++s) {
    const PolyMesh& mesh = scene.meshes[s].mesh;
    std::map<unsigned, std::vector<Index>> faces_of;
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      const Index local = mesh.face_material.empty() ? kInvalidIndex : mesh.face_material[f];
      unsigned material = ~0u;
      if (local != kInvalidIndex && local < mesh.material_names.size()) {
        auto it = material_of.find(mesh.material_names[local]);
        if (it != material_of.end()) material = it->second;
      }
      faces_of[material == ~0u ? fallback() : material].push_back(f);
    }
    for (const auto& [material, faces] : faces_of) {
      ai_meshes_of[s].push_back(static_cast<unsigned>(meshes.size()));
      meshes.push_back(make_mesh(mesh, scene.meshes[s].name, faces, material, triangulate));
    }
  }
  if (materials.empty()) fallback();

  ai->mNumMaterials = static_cast<unsigned>(materials.size());
  ai->mMaterials = new aiMaterial*[materials.size()];
  std::copy(materials.begin(), materials.end(), ai->mMaterials);
  ai->mNumMeshes = static_cast<unsigned>(meshes.size());
  if (!meshes.empty()) {
    ai->mMeshes = new aiMesh*[meshes.size()];
    std::copy(meshes.begin(), meshes.end(), ai->mMeshes);
  }

  // Nodes. A scene without nodes gets a root holding every mesh; nodes whose parent is missing
  // hang under the root.
  std::vector<aiNode*> nodes;
  std::vector<SceneNode> source = scene.nodes;
  if (source.empty()) {
    SceneNode root;
    root.name = "root";
    for (Index s = 0; s < scene.meshes.size(); ++s) root.meshes.push_back(s);
    source.push_back(std::move(root));
  }
  std::vector<std::vector<aiNode*>> children(source.size());
  for (std::size_t i = 0; i < source.size(); ++i) {
    auto* node = new aiNode(source[i].name);
    node->mTransformation = to_assimp(source[i].local);
    std::vector<unsigned> refs;
    for (Index s : source[i].meshes)
      if (s < ai_meshes_of.size()) refs.insert(refs.end(), ai_meshes_of[s].begin(), ai_meshes_of[s].end());
    node->mNumMeshes = static_cast<unsigned>(refs.size());
    if (!refs.empty()) {
      node->mMeshes = new unsigned[refs.size()];
      std::copy(refs.begin(), refs.end(), node->mMeshes);
    }
    nodes.push_back(node);
    if (i > 0) {
      const Index parent = source[i].parent < i ? source[i].parent : 0;
      children[parent].push_back(node);
      node->mParent = nodes[parent];
    }
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (children[i].empty()) continue;
    nodes[i]->mNumChildren = static_cast<unsigned>(children[i].size());
    nodes[i]->mChildren = new aiNode*[children[i].size()];
    std::copy(children[i].begin(), children[i].end(), nodes[i]->mChildren);
  }
  ai->mRootNode = nodes[0];
  // Shared vertices between faces: tell exporters that may need unique ones.
  ai->mFlags |= AI_SCENE_FLAGS_NON_VERBOSE_FORMAT;
  return ai;
}

// --- binary FBX repair ----------------------------------------------------------------------------
//
// assimp 5.2's binary FBX writer drops the 25-byte NULL record that must close every nested record
// list (assimp issue #4686: the padding constant is written as an empty string), so neither
// assimp's reader ("FBX-Tokenize … block offset is out of range") nor Blender reads its files.
// The node tree is parsed by the end offsets the writer did get right and written again with the
// NULL records, every end offset recomputed. Records (FBX 7.5, 64-bit):
//
//   [u64 end offset][u64 property count][u64 property bytes][u8 name length][name][properties]
//   [nested records … NULL record (25 zero bytes)]        ← only when there are nested records

struct FbxRecord {
  std::string_view head;  // property count, property bytes, name length, name, properties
  std::vector<FbxRecord> children;
};

constexpr std::size_t kFbxHeader = 27, kFbxNull = 25;

std::uint64_t read_u64(std::string_view d, std::size_t pos) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(d[pos + i]);
  return v;
}

void write_u64(std::string& out, std::size_t pos, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out[pos + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}

/// Parses the records in [pos, limit) up to a NULL record (or limit); returns where it stopped
/// (the NULL record's offset, or limit), or npos when the data is inconsistent.
std::size_t parse_fbx_records(std::string_view d, std::size_t pos, std::size_t limit, std::vector<FbxRecord>& out,
                              int depth) {
  if (depth > 64) return std::string_view::npos;
  while (pos < limit) {
    if (pos + kFbxNull > d.size()) return std::string_view::npos;
    const std::uint64_t end = read_u64(d, pos);
    if (end == 0) return pos;
    const std::uint64_t property_bytes = read_u64(d, pos + 16);
    const std::size_t name_length = static_cast<unsigned char>(d[pos + 24]);
    const std::uint64_t properties_end = pos + kFbxNull + name_length + property_bytes;
    if (end > limit || properties_end > end) return std::string_view::npos;
    FbxRecord record;
    record.head = d.substr(pos + 8, properties_end - (pos + 8));
    if (properties_end < end &&
        parse_fbx_records(d, properties_end, end, record.children, depth + 1) == std::string_view::npos)
      return std::string_view::npos;
    out.push_back(std::move(record));
    pos = end;
  }
  return limit;
}

void write_fbx_record(const FbxRecord& record, std::string& out) {
  const std::size_t start = out.size();
  out.append(8, '\0');
  out.append(record.head);
  for (const FbxRecord& child : record.children) write_fbx_record(child, out);
  if (!record.children.empty()) out.append(kFbxNull, '\0');
  write_u64(out, start, out.size());
}

/// The repaired file; `data` unchanged when it is not a 64-bit binary FBX this can parse.
std::string repair_fbx_null_records(const std::string& data) {
  const std::string_view d(data);
  if (d.size() < kFbxHeader + kFbxNull || d.substr(0, 18) != "Kaydara FBX Binary") return data;
  const std::uint32_t version = static_cast<unsigned char>(d[23]) | static_cast<unsigned char>(d[24]) << 8 |
                                static_cast<unsigned char>(d[25]) << 16 | static_cast<std::uint32_t>(static_cast<unsigned char>(d[26])) << 24;
  if (version < 7500) return data;
  std::vector<FbxRecord> top;
  const std::size_t null_at = parse_fbx_records(d, kFbxHeader, d.size(), top, 0);
  if (null_at == std::string_view::npos || null_at + kFbxNull > d.size()) return data;
  std::string out(d.substr(0, kFbxHeader));
  for (const FbxRecord& record : top) write_fbx_record(record, out);
  // The footer: NULL record, 16-byte id, zero padding, version, zeros, magic. The padding keeps
  // the version at the same offset modulo 16 as the writer put it (readers do not check it).
  constexpr std::size_t kFooterTail = 4 + 120 + 16;
  const std::size_t footer = null_at + kFbxNull + 16;
  if (d.size() < footer + kFooterTail) return data;
  out.append(d.substr(null_at, kFbxNull + 16));
  const std::size_t tail_at = d.size() - kFooterTail;
  std::size_t pad = (tail_at - footer) % 16;
  while ((out.size() + pad) % 16 != tail_at % 16) ++pad;
  out.append(pad, '\0');
  out.append(d.substr(tail_at));
  return out;
}

}  // namespace

bool format_scene_with_assimp(const Scene& scene, const char* format_id, bool triangulate, std::string& out,
                              std::string& error) {
  if (scene.meshes.empty()) {
    error = "the scene has no mesh to write";
    return false;
  }
  for (const SceneMesh& m : scene.meshes) {
    const std::string problem = m.mesh.check_layout();
    if (!problem.empty()) {
      error = "mesh '" + m.name + "': " + problem;
      return false;
    }
  }
  const std::unique_ptr<aiScene> ai = build_scene(scene, triangulate);
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(ai.get(), format_id, 0u);
  if (!blob) {
    error = std::string("assimp ") + format_id + " exporter: " + exporter.GetErrorString();
    return false;
  }
  if (blob->next) {
    error = std::string("assimp ") + format_id + " exporter wrote more than one file";
    return false;
  }
  out.assign(static_cast<const char*>(blob->data), blob->size);
  if (std::string_view(format_id) == "fbx") out = repair_fbx_null_records(out);
  return true;
}

}  // namespace quadlod::io_detail
