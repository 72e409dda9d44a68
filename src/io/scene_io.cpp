// quadlod — read_scene / write_scene (include/quadlod/scene.h): the choice by extension
// between the native OBJ / PLY / OFF code (io.h) and assimp, and scene flattening.
#include "io/assimp_detail.h"
#include "io/scene_skin_write.h"
#include "quadlod/scene.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <map>

namespace quadlod {

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool is_native(const std::filesystem::path& path) {
  MeshFormat format;
  return format_from_path(path, format);
}

}  // namespace

std::uint64_t Scene::tri_equivalent_count() const {
  std::uint64_t total = 0;
  for (const SceneMesh& m : meshes) total += quadlod::tri_equivalent_count(m.mesh);
  return total;
}

Eigen::Matrix4d Scene::world_transform(Index node) const {
  Eigen::Matrix4d world = Eigen::Matrix4d::Identity();
  for (Index n = node, guard = 0; n < nodes.size() && guard <= nodes.size(); n = nodes[n].parent, ++guard)
    world = nodes[n].local * world;
  return world;
}

bool scene_format_from_path(const std::filesystem::path& path, SceneFormat& format) {
  static const std::map<std::string, SceneFormat> kFormats = {
      {".obj", SceneFormat::Obj}, {".ply", SceneFormat::Ply}, {".off", SceneFormat::Off},
      {".glb", SceneFormat::Glb}, {".fbx", SceneFormat::Fbx}, {".dae", SceneFormat::Collada}};
  const auto it = kFormats.find(lower_extension(path));
  if (it == kFormats.end()) return false;
  format = it->second;
  return true;
}

std::string scene_format_extension(SceneFormat format) {
  switch (format) {
    case SceneFormat::Obj: return ".obj";
    case SceneFormat::Ply: return ".ply";
    case SceneFormat::Off: return ".off";
    case SceneFormat::Glb: return ".glb";
    case SceneFormat::Fbx: return ".fbx";
    case SceneFormat::Collada: return ".dae";
  }
  return "";
}

std::string default_output_extension(const std::filesystem::path& input) {
  SceneFormat format;
  return scene_format_from_path(input, format) ? scene_format_extension(format) : ".glb";
}

bool scene_readable_path(const std::filesystem::path& path) {
  // The assimp formats quadlod documents and tests, plus the common others assimp 5.2 reads.
  static const char* kAssimp[] = {".fbx", ".gltf", ".glb", ".dae", ".3ds", ".blend", ".x",  ".ase",
                                  ".lwo", ".lws",  ".ms3d", ".stl", ".dxf", ".ifc",   ".x3d", ".ac",
                                  ".b3d", ".md2",  ".md3",  ".md5mesh", ".smd", ".irrmesh", ".ogex", ".3mf"};
  if (is_native(path)) return true;
  const std::string ext = lower_extension(path);
  return std::any_of(std::begin(kAssimp), std::end(kAssimp), [&](const char* e) { return ext == e; });
}

Scene scene_from_mesh(PolyMesh mesh, const std::string& name) {
  Scene scene;
  for (const std::string& m : mesh.material_names) {
    SceneMaterial material;
    material.name = m;
    scene.materials.push_back(std::move(material));
  }
  SceneNode root;
  root.name = name;
  root.meshes.push_back(0);
  scene.nodes.push_back(std::move(root));
  scene.meshes.push_back({name, std::move(mesh)});
  return scene;
}

SceneReadResult read_scene(const std::filesystem::path& path, const SceneReadOptions& options) {
  if (!is_native(path)) return io_detail::read_scene_with_assimp(path, options);
  ReadResult in = read_mesh(path, options.native);
  SceneReadResult result;
  result.seconds = in.seconds;
  if (!in.ok()) {
    result.error = std::move(in.error);
    return result;
  }
  result.scene = scene_from_mesh(std::move(in.mesh), path.stem().string());
  return result;
}

PolyMesh flatten_scene(const Scene& scene) {
  PolyMesh out;
  std::map<std::string, Index> material_of;
  std::vector<Index> face;
  bool normals = false, colours = false, materials = false;
  std::size_t uv_sets = 0;
  for (const SceneMesh& m : scene.meshes) {
    uv_sets = std::max(uv_sets, m.mesh.uv_sets.size());
    normals = normals || m.mesh.has_normals();
    colours = colours || !m.mesh.vertex_colors.empty();
    materials = materials || !m.mesh.face_material.empty();
  }
  out.uv_sets.resize(uv_sets);
  for (const SceneMesh& m : scene.meshes)
    for (std::size_t k = 0; k < m.mesh.uv_sets.size(); ++k)
      if (out.uv_sets[k].name.empty()) out.uv_sets[k].name = m.mesh.uv_sets[k].name;

  // (node, mesh) instances in node order; a scene without nodes has every mesh at the origin.
  std::vector<std::pair<Index, Index>> instances;
  for (Index n = 0; n < scene.nodes.size(); ++n)
    for (Index s : scene.nodes[n].meshes)
      if (s < scene.meshes.size()) instances.emplace_back(n, s);
  if (scene.nodes.empty())
    for (Index s = 0; s < scene.meshes.size(); ++s) instances.emplace_back(kInvalidIndex, s);

  for (const auto& [node, s] : instances) {
    const PolyMesh& mesh = scene.meshes[s].mesh;
    const Eigen::Matrix4d world = node == kInvalidIndex ? Eigen::Matrix4d::Identity() : scene.world_transform(node);
    const Eigen::Matrix3d linear = world.topLeftCorner<3, 3>();
    const Eigen::Matrix3d normal_matrix = linear.inverse().transpose();
    const Index vertex_base = out.num_vertices();
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      out.positions.push_back(linear * mesh.positions[v] + world.topRightCorner<3, 1>());
      if (colours) out.vertex_colors.push_back(mesh.vertex_colors.empty() ? Vec3(1, 1, 1) : mesh.vertex_colors[v]);
    }
    std::vector<Index> uv_base(uv_sets, 0);
    for (std::size_t k = 0; k < mesh.uv_sets.size(); ++k) {
      uv_base[k] = static_cast<Index>(out.uv_sets[k].values.size());
      out.uv_sets[k].values.insert(out.uv_sets[k].values.end(), mesh.uv_sets[k].values.begin(), mesh.uv_sets[k].values.end());
    }
    const Index normal_base = static_cast<Index>(out.normals.size());
    for (const Vec3& n : mesh.normals) {
      const Vec3 t = normal_matrix * n;
      out.normals.push_back(t.norm() > 0 ? Vec3(t.normalized()) : t);
    }
    const Index object = static_cast<Index>(out.object_names.size());
    out.object_names.push_back(node == kInvalidIndex ? scene.meshes[s].name : scene.nodes[node].name);
    for (Index f = 0; f < mesh.num_faces(); ++f) {
      for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) {
        out.corner_vertex.push_back(vertex_base + mesh.corner_vertex[c]);
        for (std::size_t k = 0; k < uv_sets; ++k) {
          const Index t = k < mesh.uv_sets.size() ? mesh.uv_sets[k].corner[c] : kInvalidIndex;
          out.uv_sets[k].corner.push_back(t == kInvalidIndex ? kInvalidIndex : uv_base[k] + t);
        }
        if (normals) {
          const Index n = mesh.has_normals() ? mesh.corner_normal[c] : kInvalidIndex;
          out.corner_normal.push_back(n == kInvalidIndex ? kInvalidIndex : normal_base + n);
        }
      }
      out.face_offsets.push_back(out.num_corners());
      out.face_object.push_back(object);
      if (materials) {
        Index material = kInvalidIndex;
        const Index local = mesh.face_material.empty() ? kInvalidIndex : mesh.face_material[f];
        if (local != kInvalidIndex && local < mesh.material_names.size()) {
          auto [it, inserted] = material_of.try_emplace(mesh.material_names[local], static_cast<Index>(out.material_names.size()));
          if (inserted) out.material_names.push_back(mesh.material_names[local]);
          material = it->second;
        }
        out.face_material.push_back(material);
      }
    }
  }
  return out;
}

WriteResult write_scene(const Scene& scene, const std::filesystem::path& path, const WriteOptions& options) {
  SceneFormat format;
  WriteResult result;
  if (!scene_format_from_path(path, format)) {
    result.error = path.string() + ": unknown output format (use .obj, .ply, .off, .glb, .fbx or .dae)";
    return result;
  }
  if (format == SceneFormat::Obj || format == SceneFormat::Ply || format == SceneFormat::Off) {
    const bool one_mesh = scene.meshes.size() == 1 && scene.nodes.size() <= 1 &&
                          (scene.nodes.empty() || scene.nodes[0].local.isIdentity(0.0));
    if (scene.meshes.empty()) {
      result.error = path.string() + ": the scene has no mesh to write";
      return result;
    }
    if (one_mesh) return write_mesh(scene.meshes[0].mesh, path, options);  // warns of its blend shapes
    WriteResult flat = write_mesh(flatten_scene(scene), path, options);
    std::size_t shapes = 0;  // issue 34: flatten_scene keeps none
    for (const SceneMesh& m : scene.meshes) shapes += m.mesh.morph_targets.size();
    if (flat.ok() && shapes > 0)
      flat.warnings.push_back(path.string() + ": " + std::to_string(shapes) +
                              " blend shape(s) dropped: OBJ, PLY and OFF hold none (write .glb or .fbx to keep them)");
    return flat;
  }
  // Issue 24: assimp's glTF exporter writes no skin; a skinned scene goes to quadlod's own.
  if (format == SceneFormat::Glb && io_detail::scene_is_skinned(scene)) return io_detail::write_skinned_scene(scene, path);
  const char* id = format == SceneFormat::Glb ? "glb2" : format == SceneFormat::Fbx ? "fbx" : "collada";
  std::string bytes, error;
  if (!io_detail::format_scene_with_assimp(scene, id, format == SceneFormat::Glb, bytes, error)) {
    result.error = path.string() + ": " + error;
    return result;
  }
  result = write_file_atomically(path, bytes);
  // Issue 34: assimp 5.2's Collada exporter writes no morph controllers.
  std::size_t shapes = 0;
  for (const SceneMesh& m : scene.meshes) shapes += m.mesh.morph_targets.size();
  if (result.ok() && format == SceneFormat::Collada && shapes > 0)
    result.warnings.push_back(path.string() + ": " + std::to_string(shapes) +
                              " blend shape(s) dropped: assimp's Collada exporter writes none (write .glb or .fbx to keep them)");
  return result;
}

}  // namespace quadlod
