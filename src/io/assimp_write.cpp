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

#include <cstring>
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

/// Issue 34: the mesh's blend shapes as aiAnimMeshes of `out` (absolute positions per aiMesh
/// vertex, as assimp's importers give them and its glTF 2 / FBX exporters take them; they store
/// the difference to the base). `source_corner[i]` is a corner of aiMesh vertex i.
void add_anim_meshes(const PolyMesh& mesh, const std::vector<Index>& source_corner, aiMesh& out) {
  if (mesh.morph_targets.empty()) return;
  const unsigned n = out.mNumVertices;
  out.mNumAnimMeshes = static_cast<unsigned>(mesh.morph_targets.size());
  out.mAnimMeshes = new aiAnimMesh*[out.mNumAnimMeshes];
  for (unsigned k = 0; k < out.mNumAnimMeshes; ++k) {
    const MorphTarget& target = mesh.morph_targets[k];
    auto* am = new aiAnimMesh();
    am->mName = aiString(target.name.empty() ? "shape_" + std::to_string(k) : target.name);
    am->mWeight = static_cast<float>(target.default_weight);
    am->mNumVertices = n;
    am->mVertices = new aiVector3D[n];
    for (unsigned i = 0; i < n; ++i) {
      const Index v = mesh.corner_vertex[source_corner[i]];
      const Vec3 p = mesh.positions[v] + target.displacement[v];
      am->mVertices[i] = aiVector3D(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
    out.mAnimMeshes[k] = am;
  }
}

/// One aiMesh of the faces of `mesh` whose material resolves to `material` (faces listed).
aiMesh* make_mesh(const PolyMesh& mesh, const std::string& name, const std::vector<Index>& faces, unsigned material,
                  bool triangulate, bool vertex_per_corner) {
  const unsigned uv_sets = std::min<unsigned>(static_cast<unsigned>(mesh.uv_sets.size()), AI_MAX_NUMBER_OF_TEXTURECOORDS);
  const bool normals = mesh.has_normals();
  const bool colours = mesh.vertex_colors.size() == mesh.positions.size() && !mesh.positions.empty();
  std::unordered_map<std::vector<Index>, unsigned, CornerKeyHash> vertex_of;
  std::vector<Index> source_corner;  // a corner of each output vertex (its attributes)
  std::vector<std::vector<unsigned>> polygons;
  std::vector<Index> key(1 + uv_sets + (normals ? 1 : 0) + (vertex_per_corner ? 1 : 0));
  for (Index f : faces) {
    std::vector<unsigned> polygon;
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) {
      key[0] = mesh.corner_vertex[c];
      if (vertex_per_corner) key.back() = c;
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
  add_anim_meshes(mesh, source_corner, *out);
  return out;
}

aiMatrix4x4 to_assimp(const Eigen::Matrix4d& m) {
  aiMatrix4x4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[r][c] = static_cast<float>(m(r, c));
  return out;
}

std::unique_ptr<aiScene> build_scene(const Scene& scene, bool triangulate, bool joins_vertices) {
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

  // Issue 34: assimp 5.2's MakeVerboseFormat, which its exporter runs on a scene flagged
  // non-verbose before a JoinIdenticalVertices step (glb2: `joins_vertices`), leaves the anim
  // meshes at the old vertex count, and JoinIdenticalVertices then asserts (Vertex.h: idx <
  // mNumVertices). For that exporter a scene with blend shapes is handed over verbose — one
  // aiMesh vertex per corner, the flag not set — and its JoinIdenticalVertices shares what is
  // equal, anim meshes included. The FBX exporter runs no such step: its control points stay shared.
  bool with_morph_targets = false;
  for (const SceneMesh& m : scene.meshes) with_morph_targets = with_morph_targets || !m.mesh.morph_targets.empty();
  const bool verbose = with_morph_targets && joins_vertices;

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
      meshes.push_back(make_mesh(mesh, scene.meshes[s].name, faces, material, triangulate, verbose));
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
  if (!verbose) ai->mFlags |= AI_SCENE_FLAGS_NON_VERBOSE_FORMAT;
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
  std::string own_head;   // issue 34: a rewritten head (used instead of `head` when not empty)
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
  out.append(record.own_head.empty() ? record.head : std::string_view(record.own_head));
  for (const FbxRecord& child : record.children) write_fbx_record(child, out);
  if (!record.children.empty()) out.append(kFbxNull, '\0');
  write_u64(out, start, out.size());
}

// --- FBX blend shapes (issue 34) ---------------------------------------------------------------
//
// assimp 5.2's FBX writer writes a blend shape as BlendShape → BlendShapeChannel → Shape, but
//   * names the Shape geometry's class "Blendshape" ("bump\0\1Blendshape"), where FBX (and
//     Blender's importer, which asserts on it) has "Geometry";
//   * writes no "Normals" in it, which assimp's own reader requires (GetRequiredElement: the
//     shape is dropped with a warning);
//   * writes DeformPercent 0 (the current value: Blender's shape key value) whatever the weight.
// Each Shape geometry gets its class "Geometry", a "Version" 100 and zero "Normals" (the shape's
// normals are the base's: quadlod carries positions only), and each channel DeformPercent = the
// shape's default weight × 100 (by its name).

std::uint32_t read_u32(std::string_view d, std::size_t pos) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(d[pos + i]);
  return v;
}

/// The properties of a head: (type, offset of the value) in order; empty when malformed.
struct FbxHead {
  std::string name;
  std::vector<std::pair<char, std::size_t>> properties;
};
FbxHead parse_head(std::string_view head) {
  FbxHead out;
  if (head.size() < 17) return out;
  const std::uint64_t count = read_u64(head, 0);
  const std::size_t name_length = static_cast<unsigned char>(head[16]);
  if (17 + name_length > head.size()) return out;
  out.name = std::string(head.substr(17, name_length));
  std::size_t pos = 17 + name_length;
  for (std::uint64_t i = 0; i < count && pos < head.size(); ++i) {
    const char type = head[pos];
    out.properties.emplace_back(type, pos + 1);
    const auto u32 = [&](std::size_t at) { return at + 4 <= head.size() ? read_u32(head, at) : 0u; };
    switch (type) {
      case 'Y': pos += 3; break;
      case 'C': pos += 2; break;
      case 'I': case 'F': pos += 5; break;
      case 'D': case 'L': pos += 9; break;
      case 'S': case 'R': pos += 5 + u32(pos + 1); break;
      case 'f': case 'd': case 'l': case 'i': case 'b': pos += 13 + u32(pos + 9); break;
      default: return {};
    }
  }
  if (pos != head.size()) return {};
  return out;
}

std::string head_string(std::string_view head, std::size_t at) {  // an 'S' property's value
  const std::uint32_t n = at + 4 <= head.size() ? read_u32(head, at) : 0u;
  if (at + 4 + n > head.size()) return {};
  return std::string(head.substr(at + 4, n));
}

void append_u32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

/// A record head from its name and its encoded properties.
std::string make_head(const std::string& name, std::uint64_t count, const std::string& properties) {
  std::string out(17, '\0');
  write_u64(out, 0, count);
  write_u64(out, 8, properties.size());
  out[16] = static_cast<char>(name.size());
  return out + name + properties;
}

std::string string_property(const std::string& s) {
  std::string out(1, 'S');
  append_u32(out, static_cast<std::uint32_t>(s.size()));
  return out + s;
}

void fix_fbx_blend_shapes(std::vector<FbxRecord>& top, const Scene& scene) {
  // The channels are named after the shapes (add_anim_meshes); two meshes with a shape of one
  // name share the first one's weight.
  std::map<std::string, double> weight_of;
  for (const SceneMesh& m : scene.meshes)
    for (const MorphTarget& t : m.mesh.morph_targets)
      weight_of.try_emplace(t.name.empty() ? "shape_" + std::to_string(&t - m.mesh.morph_targets.data()) : t.name, t.default_weight);
  for (FbxRecord& objects : top) {
    if (parse_head(objects.head).name != "Objects") continue;
    for (FbxRecord& object : objects.children) {
      const FbxHead h = parse_head(object.head);
      if (h.properties.size() != 3 || h.properties[0].first != 'L' || h.properties[1].first != 'S' ||
          h.properties[2].first != 'S')
        continue;
      const std::string name = head_string(object.head, h.properties[1].second);
      const std::string kind = head_string(object.head, h.properties[2].second);
      const std::string plain = name.substr(0, name.find(std::string("\0\1", 2)));
      if (h.name == "Geometry" && kind == "Shape") {
        // (L id, S "name\0\1Geometry", S "Shape")
        const std::size_t id_at = h.properties[0].second - 1;
        std::string properties(object.head.substr(id_at, 9));
        properties += string_property(plain + std::string("\0\1", 2) + "Geometry") + string_property("Shape");
        object.own_head = make_head("Geometry", 3, properties);
        std::uint32_t values = 0;  // of the Vertices array (3 per moved point); Normals as many
        for (const FbxRecord& child : object.children) {
          const FbxHead c = parse_head(child.head);
          if (c.name == "Vertices" && c.properties.size() == 1 && c.properties[0].first == 'd')
            values = read_u32(child.head, c.properties[0].second);
        }
        FbxRecord version;
        std::string v(1, 'I');
        append_u32(v, 100);
        version.own_head = make_head("Version", 1, v);
        FbxRecord normals;
        std::string n(1, 'd');
        append_u32(n, values);  // count
        append_u32(n, 0);       // raw
        append_u32(n, values * 8);
        n.append(std::size_t(values) * 8, '\0');
        normals.own_head = make_head("Normals", 1, n);
        object.children.insert(object.children.begin(), std::move(version));
        object.children.push_back(std::move(normals));
      } else if (h.name == "Deformer" && kind == "BlendShapeChannel") {
        const auto it = weight_of.find(plain);
        if (it == weight_of.end()) continue;
        for (FbxRecord& child : object.children) {
          const FbxHead c = parse_head(child.head);
          if (c.name != "DeformPercent" || c.properties.size() != 1) continue;
          std::string p(1, 'D');
          const double percent = 100.0 * it->second;
          std::uint64_t bits = 0;
          std::memcpy(&bits, &percent, 8);
          p.append(8, '\0');
          write_u64(p, 1, bits);
          child.own_head = make_head("DeformPercent", 1, p);
        }
      }
    }
  }
}

/// The repaired file; `data` unchanged when it is not a 64-bit binary FBX this can parse.
/// With `scene`'s blend shapes, their records are fixed too (fix_fbx_blend_shapes).
std::string repair_fbx_null_records(const std::string& data, const Scene& scene) {
  const std::string_view d(data);
  if (d.size() < kFbxHeader + kFbxNull || d.substr(0, 18) != "Kaydara FBX Binary") return data;
  const std::uint32_t version = static_cast<unsigned char>(d[23]) | static_cast<unsigned char>(d[24]) << 8 |
                                static_cast<unsigned char>(d[25]) << 16 | static_cast<std::uint32_t>(static_cast<unsigned char>(d[26])) << 24;
  if (version < 7500) return data;
  std::vector<FbxRecord> top;
  const std::size_t null_at = parse_fbx_records(d, kFbxHeader, d.size(), top, 0);
  if (null_at == std::string_view::npos || null_at + kFbxNull > d.size()) return data;
  bool with_morph_targets = false;
  for (const SceneMesh& m : scene.meshes) with_morph_targets = with_morph_targets || !m.mesh.morph_targets.empty();
  if (with_morph_targets) fix_fbx_blend_shapes(top, scene);
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
  const std::unique_ptr<aiScene> ai = build_scene(scene, triangulate, std::string_view(format_id) == "glb2");
  Assimp::Exporter exporter;
  // Issue 34: glTF morph targets keep their names (mesh.extras.targetNames, which Blender reads
  // as the shape keys' names); without the property assimp 5.2 writes them unnamed.
  Assimp::ExportProperties properties;
  properties.SetPropertyBool("GLTF2_TARGETNAMES_EXP", true);
  const aiExportDataBlob* blob = exporter.ExportToBlob(ai.get(), format_id, 0u, &properties);
  if (!blob) {
    error = std::string("assimp ") + format_id + " exporter: " + exporter.GetErrorString();
    return false;
  }
  if (blob->next) {
    error = std::string("assimp ") + format_id + " exporter wrote more than one file";
    return false;
  }
  out.assign(static_cast<const char*>(blob->data), blob->size);
  if (std::string_view(format_id) == "fbx") out = repair_fbx_null_records(out, scene);
  if (std::string_view(format_id) == "glb2" && !add_gltf_morph_weights(scene, out)) {
    error = "assimp glb2 exporter: no JSON chunk to add the blend shapes' weights to";
    return false;
  }
  return true;
}

}  // namespace quadlod::io_detail
