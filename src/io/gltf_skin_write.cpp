// Skinned .glb writer (issue 24; include/quadlod/skin_io.h). Layout of the file:
//
//   scene ── node 0 "rig" (matrix = Skeleton::root_transform)
//              ├── joint nodes (TRS rest pose, the skeleton's hierarchy)
//              └── one node per skinned mesh (mesh k, skin k; no transform: glTF ignores it for
//                  skinned meshes; every skin lists the same joints and inverse bind matrices)
//   scene ── one node per placement of an unskinned mesh (matrix = its transform)
//
// One primitive per material; a glTF vertex per distinct (vertex, UV, normal) corner of that
// material's faces; polygons as fans (glTF has triangles only, §3.7.2.1). Every array goes into
// one BIN chunk, each buffer view 4-byte aligned (§3.6.2.4).
#include "quadlod/skin_io.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

namespace quadlod {

namespace {

using json = nlohmann::json;

class BinaryBuilder {
 public:
  json buffer_views = json::array();
  json accessors = json::array();
  std::string bin;

  // Appends raw bytes as a buffer view (target 0 = none); returns the view index.
  std::size_t view(const void* data, std::size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back('\0');
    json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    bin.append(static_cast<const char*>(data), bytes);
    buffer_views.push_back(v);
    return buffer_views.size() - 1;
  }
  std::size_t floats(const std::vector<float>& values, int width, const char* type, int target, bool bounds) {
    json a = {{"bufferView", view(values.data(), values.size() * 4, target)},
              {"componentType", 5126},
              {"count", values.size() / width},
              {"type", type}};
    if (bounds && !values.empty()) {
      std::vector<float> lo(values.begin(), values.begin() + width), hi = lo;
      for (std::size_t i = 0; i < values.size(); ++i) {
        lo[i % width] = std::min(lo[i % width], values[i]);
        hi[i % width] = std::max(hi[i % width], values[i]);
      }
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors.push_back(a);
    return accessors.size() - 1;
  }
  std::size_t u16(const std::vector<std::uint16_t>& values, int width, const char* type) {
    accessors.push_back({{"bufferView", view(values.data(), values.size() * 2, 34962)},
                         {"componentType", 5123},
                         {"count", values.size() / width},
                         {"type", type}});
    return accessors.size() - 1;
  }
  std::size_t u32(const std::vector<std::uint32_t>& values, int target = 34963) {
    accessors.push_back({{"bufferView", view(values.data(), values.size() * 4, target)},
                         {"componentType", 5125},
                         {"count", values.size()},
                         {"type", "SCALAR"}});
    return accessors.size() - 1;
  }
};

void put_u32(std::string& s, std::uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  s.append(b, 4);
}

/// Materials of the file, shared by name between the meshes (slots in order of first use).
struct MaterialTable {
  json materials = json::array();
  std::map<std::string, std::size_t> slot;
  std::size_t of(const std::string& mname, const std::vector<std::pair<std::string, Eigen::Vector4d>>& material_colors) {
    if (const auto it = slot.find(mname); it != slot.end()) return it->second;
    Eigen::Vector4d color(0.8, 0.8, 0.8, 1.0);
    for (const auto& [n, c] : material_colors)
      if (n == mname) color = c;
    materials.push_back({{"name", mname},
                         {"doubleSided", true},
                         {"pbrMetallicRoughness",
                          {{"baseColorFactor", {color[0], color[1], color[2], color[3]}},
                           {"metallicFactor", 0.0},
                           {"roughnessFactor", 1.0}}}});
    return slot[mname] = materials.size() - 1;
  }
};

/// The glTF primitives of one mesh: one per material; JOINTS_n / WEIGHTS_n when it has weights.
json mesh_primitives(const PolyMesh& mesh, BinaryBuilder& b, MaterialTable& table,
                     const std::vector<std::pair<std::string, Eigen::Vector4d>>& material_colors) {
  const bool skinned = !mesh.skin.empty();
  const Index sets = skinned ? std::max<Index>(1, (mesh.skin.max_influences() + 3) / 4) : 0;
  const bool uvs = mesh.has_uvs();
  const bool normals = mesh.has_normals();
  // Faces by material (kInvalidIndex = none), in the order materials are named.
  std::map<Index, std::vector<Index>> faces_of;
  for (Index f = 0; f < mesh.num_faces(); ++f)
    faces_of[mesh.face_material.empty() ? kInvalidIndex : mesh.face_material[f]].push_back(f);

  json primitives = json::array();
  for (const auto& [material, faces] : faces_of) {
    std::map<std::tuple<Index, Index, Index>, std::uint32_t> vertex_of;
    std::vector<float> pos, nor, tex;
    std::vector<std::vector<float>> shapes(mesh.morph_targets.size());  // issue 34: per target, xyz per vertex
    std::vector<std::uint16_t> joints;
    std::vector<float> weights;
    std::vector<std::uint32_t> indices, polygon_sizes;
    bool all_normals = normals;
    auto corner_vertex = [&](Index c) {
      const Index v = mesh.corner_vertex[c];
      const Index uv = uvs ? mesh.uv_sets[0].corner[c] : kInvalidIndex;
      const Index n = normals ? mesh.corner_normal[c] : kInvalidIndex;
      auto [it, fresh] = vertex_of.try_emplace({v, uv, n}, static_cast<std::uint32_t>(pos.size() / 3));
      if (fresh) {
        for (int k = 0; k < 3; ++k) pos.push_back(static_cast<float>(mesh.positions[v][k]));
        for (std::size_t t = 0; t < shapes.size(); ++t)
          for (int k = 0; k < 3; ++k) shapes[t].push_back(static_cast<float>(mesh.morph_targets[t].displacement[v][k]));
        if (normals) {
          const Vec3 nv = n != kInvalidIndex ? mesh.normals[n].normalized() : Vec3::UnitZ();
          all_normals &= n != kInvalidIndex;
          for (int k = 0; k < 3; ++k) nor.push_back(static_cast<float>(nv[k]));
        }
        if (uvs) {
          const Vec2 t = uv != kInvalidIndex ? mesh.uv_sets[0].values[uv] : Vec2::Zero();
          tex.push_back(static_cast<float>(t.x()));
          tex.push_back(static_cast<float>(1.0 - t.y()));  // glTF's origin is the top left
        }
        // Influences in sets of four, renormalised in float (the glTF validator's tolerance).
        if (!skinned) return it->second;
        std::vector<float> w(4 * sets, 0.0f);
        std::vector<std::uint16_t> j(4 * sets, 0);
        float sum = 0.0f;
        for (Index i = mesh.skin.offsets[v], k = 0; i < mesh.skin.offsets[v + 1]; ++i, ++k) {
          w[k] = static_cast<float>(mesh.skin.weight[i]);
          j[k] = static_cast<std::uint16_t>(mesh.skin.joint[i]);
          sum += w[k];
        }
        if (sum > 0.0f)
          for (float& x : w) x /= sum;
        weights.insert(weights.end(), w.begin(), w.end());
        joints.insert(joints.end(), j.begin(), j.end());
      }
      return it->second;
    };
    for (Index f : faces) {
      polygon_sizes.push_back(mesh.face_size(f));
      const Index c0 = mesh.face_begin(f);
      for (Index c = c0 + 1; c + 1 < mesh.face_end(f); ++c) {
        indices.push_back(corner_vertex(c0));
        indices.push_back(corner_vertex(c));
        indices.push_back(corner_vertex(c + 1));
      }
    }
    json attributes = {{"POSITION", b.floats(pos, 3, "VEC3", 34962, true)}};
    if (normals && all_normals) attributes["NORMAL"] = b.floats(nor, 3, "VEC3", 34962, false);
    if (uvs) attributes["TEXCOORD_0"] = b.floats(tex, 2, "VEC2", 34962, false);
    const std::size_t count = pos.size() / 3;
    for (Index s = 0; s < sets; ++s) {
      std::vector<std::uint16_t> js;
      std::vector<float> ws;
      for (std::size_t v = 0; v < count; ++v)
        for (int k = 0; k < 4; ++k) {
          js.push_back(joints[v * 4 * sets + 4 * s + k]);
          ws.push_back(weights[v * 4 * sets + 4 * s + k]);
        }
      attributes["JOINTS_" + std::to_string(s)] = b.u16(js, 4, "VEC4");
      attributes["WEIGHTS_" + std::to_string(s)] = b.floats(ws, 4, "VEC4", 34962, false);
    }
    json prim = {{"attributes", attributes}, {"indices", b.u32(indices)}, {"mode", 4}};
    // Blend shapes (issue 34): glTF morph targets, POSITION displacements (with min / max, which
    // the specification requires of them as of POSITION).
    if (!shapes.empty()) {
      json targets = json::array();
      for (const std::vector<float>& d : shapes) targets.push_back({{"POSITION", b.floats(d, 3, "VEC3", 34962, true)}});
      prim["targets"] = std::move(targets);
    }
    // The polygons behind the fans, so that quadlod reads its quads back (read_skinned_gltf);
    // viewers ignore extras.
    prim["extras"] = {{"quadlod_polygon_sizes", b.u32(polygon_sizes, 0)}};
    if (material != kInvalidIndex) {
      const std::string mname = material < mesh.material_names.size() ? mesh.material_names[material] : "material";
      prim["material"] = table.of(mname, material_colors);
    }
    primitives.push_back(prim);
  }
  return primitives;
}

std::string check_skinned_mesh(const PolyMesh& mesh, Index num_joints) {
  if (std::string p = mesh.check_layout(); !p.empty()) return p;
  for (Index j : mesh.skin.joint)
    if (j >= num_joints) return "a weight names joint " + std::to_string(j) + " of " + std::to_string(num_joints);
  return {};
}

}  // namespace

WriteResult write_skinned_glb(const PolyMesh& mesh, const Rig& rig, const std::filesystem::path& path,
                              const std::vector<std::pair<std::string, Eigen::Vector4d>>& material_colors) {
  if (mesh.skin.empty()) return {path.string() + ": the mesh has no skin weights", {}};
  return write_skinned_scene_glb({SkinnedGlbMesh{"lod", &mesh, {}}}, rig, path, material_colors);
}

WriteResult write_skinned_scene_glb(const std::vector<SkinnedGlbMesh>& meshes, const Rig& rig,
                                    const std::filesystem::path& path,
                                    const std::vector<std::pair<std::string, Eigen::Vector4d>>& material_colors) {
  const std::string name = path.string();
  if (std::string p = rig.skeleton.check(); !p.empty()) return {name + ": " + p, {}};
  const Index num_joints = rig.skeleton.num_joints();
  if (num_joints > 65535) return {name + ": more than 65535 joints", {}};
  bool any_skin = false;
  for (const SkinnedGlbMesh& m : meshes) {
    if (!m.mesh) return {name + ": mesh '" + m.name + "' is missing", {}};
    if (std::string p = check_skinned_mesh(*m.mesh, num_joints); !p.empty())
      return {name + ": mesh '" + m.name + "': " + p, {}};
    any_skin |= !m.mesh->skin.empty();
  }
  if (!any_skin) return {name + ": no mesh has skin weights", {}};

  BinaryBuilder b;
  MaterialTable table;
  json gltf_meshes = json::array();
  for (const SkinnedGlbMesh& m : meshes) {
    json gm = {{"name", m.name}, {"primitives", mesh_primitives(*m.mesh, b, table, material_colors)}};
    if (!m.mesh->morph_targets.empty()) {  // issue 34: default weights, and names as Blender reads them
      json weights = json::array(), names = json::array();
      for (const MorphTarget& t : m.mesh->morph_targets) {
        weights.push_back(t.default_weight);
        names.push_back(t.name);
      }
      gm["weights"] = std::move(weights);
      gm["extras"] = {{"targetNames", std::move(names)}};
    }
    gltf_meshes.push_back(std::move(gm));
  }

  // Nodes: 0 the rig root, 1 + j the joints, then the skinned meshes' nodes, then the others.
  const Skeleton& sk = rig.skeleton;
  json nodes = json::array();
  json root = {{"name", "rig"}, {"children", json::array()}};
  if (!sk.root_transform.isIdentity(0.0)) {
    std::vector<double> m(16);
    for (int k = 0; k < 16; ++k) m[k] = sk.root_transform(k % 4, k / 4);
    root["matrix"] = m;
  }
  nodes.push_back(root);
  std::vector<float> ibm;
  for (Index j = 0; j < num_joints; ++j) {
    const Joint& joint = sk.joints[j];
    const Quat q = joint.rest.rotation.normalized();
    json node = {{"name", joint.name.empty() ? "joint" + std::to_string(j) : joint.name},
                 {"translation", {joint.rest.translation.x(), joint.rest.translation.y(), joint.rest.translation.z()}},
                 {"rotation", {q.x(), q.y(), q.z(), q.w()}},
                 {"scale", {joint.rest.scale.x(), joint.rest.scale.y(), joint.rest.scale.z()}}};
    nodes.push_back(node);
    for (int k = 0; k < 16; ++k) ibm.push_back(static_cast<float>(joint.inverse_bind(k % 4, k / 4)));
  }
  Index first_root = kInvalidIndex;
  for (Index j = 0; j < num_joints; ++j) {
    const Index p = sk.joints[j].parent;
    if (p == kInvalidIndex) {
      nodes[0]["children"].push_back(1 + j);
      if (first_root == kInvalidIndex) first_root = j;
    } else {
      if (!nodes[1 + p].contains("children")) nodes[1 + p]["children"] = json::array();
      nodes[1 + p]["children"].push_back(1 + j);
    }
  }
  json joint_nodes = json::array();
  for (Index j = 0; j < num_joints; ++j) joint_nodes.push_back(1 + j);
  json skin = {{"joints", joint_nodes}, {"inverseBindMatrices", b.floats(ibm, 16, "MAT4", 0, false)}};
  if (first_root != kInvalidIndex) skin["skeleton"] = 1 + first_root;
  json skins = json::array();
  json scene_nodes = json::array({0});
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    if (meshes[k].mesh->skin.empty()) continue;
    // Each skinned mesh its own skin (glTF: one skin per skinned mesh node is what importers
    // expect), all on the same joints and inverse bind matrices.
    nodes[0]["children"].push_back(nodes.size());
    nodes.push_back({{"name", meshes[k].name}, {"mesh", k}, {"skin", skins.size()}});
    skins.push_back(skin);
  }
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    if (!meshes[k].mesh->skin.empty()) continue;
    const std::vector<Eigen::Matrix4d> placements =
        meshes[k].placements.empty() ? std::vector<Eigen::Matrix4d>{Eigen::Matrix4d::Identity()} : meshes[k].placements;
    for (const Eigen::Matrix4d& m : placements) {
      json node = {{"name", meshes[k].name}, {"mesh", k}};
      if (!m.isIdentity(0.0)) {
        std::vector<double> v(16);
        for (int i = 0; i < 16; ++i) v[i] = m(i % 4, i / 4);
        node["matrix"] = v;
      }
      scene_nodes.push_back(nodes.size());
      nodes.push_back(node);
    }
  }

  json animations = json::array();
  for (const Animation& anim : rig.animations) {
    json samplers = json::array(), channels = json::array();
    for (const AnimationChannel& c : anim.channels) {
      if (c.joint >= num_joints || c.times.empty()) continue;
      const int width = c.path == AnimationChannel::Path::Rotation ? 4 : 3;
      std::vector<float> times(c.times.begin(), c.times.end()), values;
      for (const Eigen::Vector4d& v : c.values)
        for (int k = 0; k < width; ++k) values.push_back(static_cast<float>(v[k]));
      const std::size_t input = b.floats(times, 1, "SCALAR", 0, true);
      const std::size_t output = b.floats(values, width, width == 4 ? "VEC4" : "VEC3", 0, false);
      samplers.push_back({{"input", input},
                          {"output", output},
                          {"interpolation", c.interpolation == AnimationChannel::Interpolation::Step ? "STEP" : "LINEAR"}});
      const char* target = c.path == AnimationChannel::Path::Translation ? "translation"
                           : c.path == AnimationChannel::Path::Rotation  ? "rotation"
                                                                         : "scale";
      channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", 1 + c.joint}, {"path", target}}}});
    }
    if (!channels.empty()) animations.push_back({{"name", anim.name}, {"samplers", samplers}, {"channels", channels}});
  }

  while (b.bin.size() % 4) b.bin.push_back('\0');
  json gltf = {{"asset", {{"version", "2.0"}, {"generator", "quadlod"}}},
               {"scene", 0},
               {"scenes", {{{"nodes", scene_nodes}}}},
               {"nodes", nodes},
               {"meshes", gltf_meshes},
               {"skins", skins},
               {"accessors", b.accessors},
               {"bufferViews", b.buffer_views},
               {"buffers", {{{"byteLength", b.bin.size()}}}}};
  if (!table.materials.empty()) gltf["materials"] = table.materials;
  if (!animations.empty()) gltf["animations"] = animations;
  std::string text = gltf.dump();
  while (text.size() % 4) text.push_back(' ');
  std::string file = "glTF";
  put_u32(file, 2);
  put_u32(file, static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + b.bin.size()));
  put_u32(file, static_cast<std::uint32_t>(text.size()));
  put_u32(file, 0x4E4F534A);  // JSON
  file += text;
  put_u32(file, static_cast<std::uint32_t>(b.bin.size()));
  put_u32(file, 0x004E4942);  // BIN
  file += b.bin;
  return write_file_atomically(path, file);
}

}  // namespace quadlod
