// Skinned glTF 2.0 read / write (issue 24; include/quadlod/skin_io.h). Spec references are to the
// glTF 2.0 specification: §3.6 buffers / accessors, §3.7.3 skins, §3.11 animations, §4.4 GLB.
#include "quadlod/skin_io.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <tuple>

namespace quadlod {

namespace {

using json = nlohmann::json;

struct Failure {
  std::string message;
};

std::string read_bytes(const std::filesystem::path& path, bool& ok) {
  std::ifstream in(path, std::ios::binary);
  ok = static_cast<bool>(in);
  if (!ok) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::uint32_t le32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}

std::string decode_base64(std::string_view text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::string out;
  int bits = 0, acc = 0;
  for (char c : text) {
    const int v = value(c);
    if (v < 0) continue;
    acc = (acc << 6) | v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((acc >> bits) & 0xff));
    }
  }
  return out;
}

// The document and its buffers, with typed accessor reads.
struct Document {
  json gltf;
  std::vector<std::string> buffers;
  std::string name;

  [[noreturn]] void fail(const std::string& what) const { throw Failure{name + ": " + what}; }

  const json& at(const char* array, std::size_t i) const {
    if (!gltf.contains(array) || !gltf[array].is_array() || i >= gltf[array].size())
      fail(std::string(array) + " " + std::to_string(i) + " does not exist");
    return gltf[array][i];
  }

  // Accessor `index` as rows of `width` doubles (normalised integers mapped to [0, 1]).
  std::vector<double> read(std::size_t index, int width) const {
    const json& a = at("accessors", index);
    const std::string where = "accessor " + std::to_string(index);
    if (a.contains("sparse")) fail(where + ": sparse accessors are not supported");
    static const std::map<std::string, int> widths = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}, {"MAT4", 16}};
    const auto w = widths.find(a.value("type", ""));
    if (w == widths.end() || w->second != width) fail(where + ": type " + a.value("type", "?") + " where " + std::to_string(width) + " components are needed");
    const int type = a.value("componentType", 0);
    const int size = type == 5126 || type == 5125 ? 4 : type == 5123 || type == 5122 ? 2 : type == 5121 || type == 5120 ? 1 : 0;
    if (size == 0) fail(where + ": component type " + std::to_string(type) + " is not supported");
    const std::size_t count = a.value("count", std::size_t{0});
    const bool normalized = a.value("normalized", false);
    std::vector<double> out(count * width, 0.0);
    if (!a.contains("bufferView")) return out;  // all zeros (§3.6.2.4)
    const json& view = at("bufferViews", a["bufferView"].get<std::size_t>());
    const std::size_t buffer = view.value("buffer", std::size_t{0});
    if (buffer >= buffers.size()) fail(where + ": buffer " + std::to_string(buffer) + " does not exist");
    const std::string& data = buffers[buffer];
    const std::size_t stride = view.value("byteStride", std::size_t(size * width));
    const std::size_t base = view.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
    const std::size_t view_end = view.value("byteOffset", std::size_t{0}) + view.value("byteLength", std::size_t{0});
    if (count > 0 && (base + (count - 1) * stride + std::size_t(size) * width > std::min(view_end, data.size())))
      fail(where + ": runs past the end of its buffer view");
    for (std::size_t i = 0; i < count; ++i)
      for (int k = 0; k < width; ++k) {
        const char* p = data.data() + base + i * stride + std::size_t(k) * size;
        double v = 0.0;
        switch (type) {
          case 5126: { float f; std::memcpy(&f, p, 4); v = f; break; }
          case 5125: { std::uint32_t u; std::memcpy(&u, p, 4); v = u; break; }
          case 5123: { std::uint16_t u; std::memcpy(&u, p, 2); v = normalized ? u / 65535.0 : u; break; }
          case 5122: { std::int16_t u; std::memcpy(&u, p, 2); v = normalized ? std::max(u / 32767.0, -1.0) : u; break; }
          case 5121: { std::uint8_t u; std::memcpy(&u, p, 1); v = normalized ? u / 255.0 : u; break; }
          case 5120: { std::int8_t u; std::memcpy(&u, p, 1); v = normalized ? std::max(u / 127.0, -1.0) : u; break; }
        }
        out[i * width + k] = v;
      }
    return out;
  }
};

Document load_document(const std::filesystem::path& path) {
  Document doc;
  doc.name = path.string();
  bool ok = false;
  const std::string bytes = read_bytes(path, ok);
  if (!ok) throw Failure{doc.name + ": cannot open the file"};
  std::string bin;
  std::string text;
  if (bytes.size() >= 12 && bytes.compare(0, 4, "glTF") == 0) {
    // GLB (§4.4): header, a JSON chunk, an optional BIN chunk.
    if (le32(bytes, 4) != 2) doc.fail("GLB version " + std::to_string(le32(bytes, 4)) + " is not 2");
    std::size_t at = 12;
    while (at + 8 <= bytes.size()) {
      const std::uint32_t length = le32(bytes, at), type = le32(bytes, at + 4);
      if (at + 8 + std::size_t(length) > bytes.size()) doc.fail("GLB chunk at byte " + std::to_string(at) + " is truncated");
      if (type == 0x4E4F534A) text = bytes.substr(at + 8, length);
      else if (type == 0x004E4942 && bin.empty()) bin = bytes.substr(at + 8, length);
      at += 8 + length;
    }
    if (text.empty()) doc.fail("GLB has no JSON chunk");
  } else {
    text = bytes;
  }
  try {
    doc.gltf = json::parse(text);
  } catch (const std::exception& e) {
    doc.fail(std::string("malformed JSON: ") + e.what());
  }
  if (!doc.gltf.is_object()) doc.fail("the JSON is not an object");
  if (doc.gltf.contains("buffers"))
    for (std::size_t i = 0; i < doc.gltf["buffers"].size(); ++i) {
      const json& b = doc.gltf["buffers"][i];
      if (!b.contains("uri")) {
        doc.buffers.push_back(bin);
        continue;
      }
      const std::string uri = b["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0) {
        const std::size_t comma = uri.find(',');
        doc.buffers.push_back(decode_base64(comma == std::string::npos ? "" : std::string_view(uri).substr(comma + 1)));
      } else {
        bool found = false;
        doc.buffers.push_back(read_bytes(path.parent_path() / uri, found));
        if (!found) doc.fail("buffer " + std::to_string(i) + ": cannot open " + uri);
      }
    }
  return doc;
}

JointTransform node_transform(const json& node) {
  JointTransform t;
  if (node.contains("matrix")) {
    Mat4 m;
    for (int k = 0; k < 16; ++k) m(k % 4, k / 4) = node["matrix"][k].get<double>();  // column-major
    Eigen::Matrix3d linear = m.topLeftCorner<3, 3>();
    t.translation = m.topRightCorner<3, 1>();
    for (int k = 0; k < 3; ++k) t.scale[k] = linear.col(k).norm();
    if (linear.determinant() < 0) t.scale[0] = -t.scale[0];
    for (int k = 0; k < 3; ++k) linear.col(k) /= t.scale[k] != 0.0 ? t.scale[k] : 1.0;
    t.rotation = Quat(linear).normalized();
    return t;
  }
  if (node.contains("translation"))
    for (int k = 0; k < 3; ++k) t.translation[k] = node["translation"][k].get<double>();
  if (node.contains("rotation")) {
    const json& r = node["rotation"];
    t.rotation = Quat(r[3].get<double>(), r[0].get<double>(), r[1].get<double>(), r[2].get<double>()).normalized();
  }
  if (node.contains("scale"))
    for (int k = 0; k < 3; ++k) t.scale[k] = node["scale"][k].get<double>();
  return t;
}

SkinnedReadResult read_impl(const std::filesystem::path& path) {
  SkinnedReadResult result;
  const Document doc = load_document(path);
  const json& g = doc.gltf;
  const std::size_t num_nodes = g.contains("nodes") ? g["nodes"].size() : 0;
  std::vector<std::size_t> parent(num_nodes, SIZE_MAX);
  for (std::size_t n = 0; n < num_nodes; ++n)
    if (g["nodes"][n].contains("children"))
      for (const json& c : g["nodes"][n]["children"]) {
        const std::size_t child = c.get<std::size_t>();
        if (child >= num_nodes) doc.fail("node " + std::to_string(n) + ": child " + std::to_string(child) + " does not exist");
        parent[child] = n;
      }
  // The skinned mesh node: first in the default scene's tree order, else in the node list.
  std::vector<std::size_t> order;
  if (g.contains("scenes") && !g["scenes"].empty()) {
    const json& scene = doc.at("scenes", g.value("scene", std::size_t{0}));
    std::function<void(std::size_t, int)> walk = [&](std::size_t n, int depth) {
      if (n >= num_nodes || depth > 1000) return;
      order.push_back(n);
      if (g["nodes"][n].contains("children"))
        for (const json& c : g["nodes"][n]["children"]) walk(c.get<std::size_t>(), depth + 1);
    };
    if (scene.contains("nodes"))
      for (const json& n : scene["nodes"]) walk(n.get<std::size_t>(), 0);
  }
  for (std::size_t n = 0; n < num_nodes; ++n) order.push_back(n);
  std::size_t mesh_node = SIZE_MAX;
  for (std::size_t n : order)
    if (g["nodes"][n].contains("mesh") && g["nodes"][n].contains("skin")) {
      mesh_node = n;
      break;
    }
  if (mesh_node == SIZE_MAX) doc.fail("no node has both a mesh and a skin");
  for (std::size_t n = 0; n < num_nodes; ++n) result.mesh_nodes += g["nodes"][n].contains("mesh") ? 1 : 0;
  const json& skin = doc.at("skins", g["nodes"][mesh_node]["skin"].get<std::size_t>());
  const json& gmesh = doc.at("meshes", g["nodes"][mesh_node]["mesh"].get<std::size_t>());

  // --- skeleton -------------------------------------------------------------------------------
  Skeleton& skeleton = result.skinned.rig.skeleton;
  std::map<std::size_t, Index> joint_of_node;
  for (const json& j : skin["joints"]) {
    const std::size_t n = j.get<std::size_t>();
    if (n >= num_nodes) doc.fail("skin joint node " + std::to_string(n) + " does not exist");
    joint_of_node[n] = static_cast<Index>(joint_of_node.size());
  }
  skeleton.joints.resize(joint_of_node.size());
  std::vector<double> ibm;
  if (skin.contains("inverseBindMatrices")) {
    ibm = doc.read(skin["inverseBindMatrices"].get<std::size_t>(), 16);
    if (ibm.size() < 16 * skeleton.joints.size()) doc.fail("skin: fewer inverse bind matrices than joints");
  }
  auto world = [&](std::size_t n) {
    Mat4 m = Mat4::Identity();
    for (std::size_t p = n; p != SIZE_MAX; p = parent[p]) m = node_transform(g["nodes"][p]).matrix() * m;
    return m;
  };
  bool root_set = false;
  for (const auto& [node, j] : joint_of_node) {
    Joint& joint = skeleton.joints[j];
    joint.name = g["nodes"][node].value("name", "joint" + std::to_string(j));
    joint.rest = node_transform(g["nodes"][node]);
    if (!ibm.empty())
      for (int k = 0; k < 16; ++k) joint.inverse_bind(k % 4, k / 4) = ibm[16 * j + k];
    std::size_t p = parent[node];
    while (p != SIZE_MAX && !joint_of_node.count(p)) p = parent[p];
    if (p != SIZE_MAX) {
      joint.parent = joint_of_node[p];
      if (parent[node] != p) doc.fail("joint " + joint.name + ": a non-joint node lies between it and its parent joint");
    } else {
      const Mat4 root = parent[node] == SIZE_MAX ? Mat4::Identity() : world(parent[node]);
      if (root_set && !root.isApprox(skeleton.root_transform, 1e-9))
        doc.fail("skin: root joints hang from differently placed nodes");
      skeleton.root_transform = root;
      root_set = true;
    }
  }
  if (std::string problem = skeleton.check(); !problem.empty()) doc.fail(problem);

  // --- mesh -----------------------------------------------------------------------------------
  PolyMesh& mesh = result.skinned.mesh;
  std::map<std::tuple<double, double, double, std::vector<std::pair<Index, double>>>, Index> weld;
  std::map<std::pair<double, double>, Index> uv_pool;
  std::map<std::tuple<double, double, double>, Index> normal_pool;
  std::vector<std::vector<Influence>> influences;
  std::map<std::string, Index> material_index;
  bool any_uv = false, any_normal = false;
  struct Corner { Index vertex, uv, normal; };
  std::vector<std::vector<Corner>> polygons;
  std::vector<Index> polygon_material;
  // Blend shapes (issue 34): glTF morph targets' POSITION displacements, target k of every
  // primitive being the mesh's shape k; a welded vertex keeps the first displacement it was
  // given (the glTF vertices of one welded vertex, split at UV / normal seams, carry the same).
  std::size_t num_targets = 0;
  for (const json& prim : gmesh["primitives"])
    if (prim.contains("targets") && prim["targets"].is_array()) num_targets = std::max(num_targets, prim["targets"].size());
  std::vector<std::vector<Vec3>> shapes(num_targets);
  for (std::size_t pi = 0; pi < gmesh["primitives"].size(); ++pi) {
    const json& prim = gmesh["primitives"][pi];
    const std::string where = "mesh primitive " + std::to_string(pi);
    if (prim.value("mode", 4) != 4) doc.fail(where + ": mode " + std::to_string(prim.value("mode", 4)) + " is not triangles");
    const json& attr = prim["attributes"];
    if (!attr.contains("POSITION")) doc.fail(where + ": no POSITION");
    const std::vector<double> pos = doc.read(attr["POSITION"].get<std::size_t>(), 3);
    const std::size_t nv = pos.size() / 3;
    std::vector<double> uv, nor;
    if (attr.contains("TEXCOORD_0")) uv = doc.read(attr["TEXCOORD_0"].get<std::size_t>(), 2);
    if (attr.contains("NORMAL")) nor = doc.read(attr["NORMAL"].get<std::size_t>(), 3);
    if ((!uv.empty() && uv.size() != 2 * nv) || (!nor.empty() && nor.size() != 3 * nv)) doc.fail(where + ": attribute counts differ");
    std::vector<std::vector<double>> shape_of(num_targets);  // this primitive's targets (empty: none)
    for (std::size_t k = 0; k < num_targets && prim.contains("targets") && k < prim["targets"].size(); ++k) {
      const json& target = prim["targets"][k];
      if (!target.contains("POSITION")) continue;
      shape_of[k] = doc.read(target["POSITION"].get<std::size_t>(), 3);
      if (shape_of[k].size() != 3 * nv) doc.fail(where + ": morph target " + std::to_string(k) + " count differs from POSITION");
    }
    std::vector<std::vector<Influence>> vertex_influences(nv);
    for (int set = 0;; ++set) {
      const std::string js = "JOINTS_" + std::to_string(set), ws = "WEIGHTS_" + std::to_string(set);
      if (!attr.contains(js) || !attr.contains(ws)) break;
      const std::vector<double> jv = doc.read(attr[js].get<std::size_t>(), 4), wv = doc.read(attr[ws].get<std::size_t>(), 4);
      if (jv.size() != 4 * nv || wv.size() != 4 * nv) doc.fail(where + ": " + js + " / " + ws + " counts differ from POSITION");
      for (std::size_t v = 0; v < nv; ++v)
        for (int k = 0; k < 4; ++k)
          if (wv[4 * v + k] > 0.0) {
            if (jv[4 * v + k] >= skeleton.joints.size())
              doc.fail(where + ": vertex " + std::to_string(v) + " names joint " + std::to_string(int(jv[4 * v + k])) + " of " + std::to_string(skeleton.joints.size()));
            vertex_influences[v].push_back({static_cast<Index>(jv[4 * v + k]), wv[4 * v + k]});
          }
    }
    std::vector<Index> vertex_id(nv), uv_id(nv, kInvalidIndex), normal_id(nv, kInvalidIndex);
    for (std::size_t v = 0; v < nv; ++v) {
      const std::vector<Influence> canon = canonical_influences(vertex_influences[v]);
      std::vector<std::pair<Index, double>> key_weights;
      for (const Influence& i : canon) key_weights.emplace_back(i.joint, i.weight);
      auto [it, fresh] = weld.try_emplace({pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], key_weights}, mesh.num_vertices());
      if (fresh) {
        mesh.add_vertex(Vec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]));
        influences.push_back(canon);
        for (std::size_t k = 0; k < num_targets; ++k)
          shapes[k].push_back(shape_of[k].empty() ? Vec3::Zero()
                                                  : Vec3(shape_of[k][3 * v], shape_of[k][3 * v + 1], shape_of[k][3 * v + 2]));
      }
      vertex_id[v] = it->second;
      if (!uv.empty()) {
        // glTF's UV origin is the top left; OBJ's (and PolyMesh's) the bottom left.
        auto [u, f] = uv_pool.try_emplace({uv[2 * v], 1.0 - uv[2 * v + 1]}, static_cast<Index>(uv_pool.size()));
        uv_id[v] = u->second;
        any_uv = true;
      }
      if (!nor.empty()) {
        auto [n, f] = normal_pool.try_emplace({nor[3 * v], nor[3 * v + 1], nor[3 * v + 2]}, static_cast<Index>(normal_pool.size()));
        normal_id[v] = n->second;
        any_normal = true;
      }
    }
    std::vector<double> idx;
    if (prim.contains("indices")) idx = doc.read(prim["indices"].get<std::size_t>(), 1);
    else for (std::size_t v = 0; v < nv; ++v) idx.push_back(double(v));
    if (idx.size() % 3) doc.fail(where + ": " + std::to_string(idx.size()) + " indices is not a multiple of 3");
    Index material = kInvalidIndex;
    if (prim.contains("material")) {
      const std::size_t m = prim["material"].get<std::size_t>();
      const json& mat = doc.at("materials", m);
      const std::string name = mat.value("name", "material" + std::to_string(m));
      auto [it, fresh] = material_index.try_emplace(name, static_cast<Index>(mesh.material_names.size()));
      if (fresh) {
        mesh.material_names.push_back(name);
        Eigen::Vector4d color(1, 1, 1, 1);
        if (mat.contains("pbrMetallicRoughness") && mat["pbrMetallicRoughness"].contains("baseColorFactor"))
          for (int k = 0; k < 4; ++k) color[k] = mat["pbrMetallicRoughness"]["baseColorFactor"][k].get<double>();
        result.material_colors.emplace_back(name, color);
      }
      material = it->second;
    }
    // Polygons written by quadlod (extras.quadlod_polygon_sizes): each a fan of size − 2
    // consecutive triangles (a, b_i, b_i+1); anything else reads as triangles.
    std::vector<double> sizes;
    if (prim.contains("extras") && prim["extras"].is_object() && prim["extras"].contains("quadlod_polygon_sizes")) {
      sizes = doc.read(prim["extras"]["quadlod_polygon_sizes"].get<std::size_t>(), 1);
      std::size_t fan = 0;
      for (double k : sizes) fan += k >= 3 ? std::size_t(k) - 2 : SIZE_MAX / 4;
      if (fan != idx.size() / 3) sizes.clear();
    }
    if (sizes.empty()) sizes.assign(idx.size() / 3, 3.0);
    for (std::size_t t = 0, p = 0; p < sizes.size(); ++p) {
      const std::size_t k = static_cast<std::size_t>(sizes[p]);
      std::vector<Corner> poly;
      bool fan_ok = true;
      for (std::size_t i = 0; i + 2 < k; ++i, t += 3) {
        std::array<Corner, 3> tri;
        for (int c = 0; c < 3; ++c) {
          const std::size_t v = static_cast<std::size_t>(idx[t + c]);
          if (v >= nv) doc.fail(where + ": index " + std::to_string(v) + " out of range (" + std::to_string(nv) + " vertices)");
          tri[c] = {vertex_id[v], uv_id[v], normal_id[v]};
        }
        if (i == 0) poly = {tri[0], tri[1], tri[2]};
        else if (idx[t] != idx[t - 3 * i] || idx[t + 1] != idx[t - 1]) fan_ok = false;
        else poly.push_back(tri[2]);
      }
      if (!fan_ok) doc.fail(where + ": polygon " + std::to_string(p) + " of extras.quadlod_polygon_sizes is not a fan");
      bool repeated = false;
      for (std::size_t a = 0; a < poly.size(); ++a)
        for (std::size_t b = a + 1; b < poly.size(); ++b) repeated |= poly[a].vertex == poly[b].vertex;
      if (repeated) {
        ++result.dropped_triangles;
        continue;
      }
      polygons.push_back(std::move(poly));
      polygon_material.push_back(material);
    }
  }
  if (polygons.empty()) doc.fail("the skinned mesh has no triangles");
  if (any_uv) {
    mesh.uv_sets.resize(1);
    mesh.uv_sets[0].values.resize(uv_pool.size());
    for (const auto& [uv, i] : uv_pool) mesh.uv_sets[0].values[i] = Vec2(uv.first, uv.second);
  }
  if (any_normal) {
    mesh.normals.resize(normal_pool.size());
    for (const auto& [n, i] : normal_pool) mesh.normals[i] = Vec3(std::get<0>(n), std::get<1>(n), std::get<2>(n));
  }
  for (std::size_t t = 0; t < polygons.size(); ++t) {
    std::vector<Index> vs;
    for (const Corner& c : polygons[t]) vs.push_back(c.vertex);
    const Index f = mesh.add_face(vs);
    for (std::size_t k = 0; k < vs.size(); ++k) {
      if (any_uv) mesh.uv_sets[0].corner[mesh.face_begin(f) + k] = polygons[t][k].uv;
      if (any_normal) {
        if (mesh.corner_normal.size() < mesh.num_corners()) mesh.corner_normal.resize(mesh.num_corners(), kInvalidIndex);
        mesh.corner_normal[mesh.face_begin(f) + k] = polygons[t][k].normal;
      }
    }
    if (!material_index.empty()) {
      mesh.face_material.resize(mesh.num_faces(), kInvalidIndex);
      mesh.face_material[f] = polygon_material[t];
    }
  }
  mesh.skin = make_skin_weights(influences);
  for (std::size_t k = 0; k < num_targets; ++k) {
    MorphTarget t;
    if (gmesh.contains("extras") && gmesh["extras"].is_object() && gmesh["extras"].contains("targetNames") &&
        gmesh["extras"]["targetNames"].is_array() && k < gmesh["extras"]["targetNames"].size() &&
        gmesh["extras"]["targetNames"][k].is_string())
      t.name = gmesh["extras"]["targetNames"][k].get<std::string>();
    if (gmesh.contains("weights") && gmesh["weights"].is_array() && k < gmesh["weights"].size() && gmesh["weights"][k].is_number())
      t.default_weight = gmesh["weights"][k].get<double>();
    t.displacement = std::move(shapes[k]);
    mesh.morph_targets.push_back(std::move(t));
  }

  // --- animations -------------------------------------------------------------------------------
  if (g.contains("animations"))
    for (std::size_t ai = 0; ai < g["animations"].size(); ++ai) {
      const json& ga = g["animations"][ai];
      Animation anim;
      anim.name = ga.value("name", "animation" + std::to_string(ai));
      for (const json& ch : ga["channels"]) {
        const json& target = ch["target"];
        const std::string path_name = target.value("path", "");
        if (!target.contains("node") || !joint_of_node.count(target["node"].get<std::size_t>()) ||
            (path_name != "translation" && path_name != "rotation" && path_name != "scale")) {
          ++result.ignored_channels;
          continue;
        }
        const std::size_t si = ch["sampler"].get<std::size_t>();
        if (si >= ga["samplers"].size()) doc.fail("animation " + anim.name + ": sampler " + std::to_string(si) + " does not exist");
        const json& sampler = ga["samplers"][si];
        AnimationChannel c;
        c.joint = joint_of_node[target["node"].get<std::size_t>()];
        c.path = path_name == "translation" ? AnimationChannel::Path::Translation
                 : path_name == "rotation"  ? AnimationChannel::Path::Rotation
                                            : AnimationChannel::Path::Scale;
        const std::string interp = sampler.value("interpolation", "LINEAR");
        c.interpolation = interp == "STEP" ? AnimationChannel::Interpolation::Step : AnimationChannel::Interpolation::Linear;
        c.times = doc.read(sampler["input"].get<std::size_t>(), 1);
        const int width = c.path == AnimationChannel::Path::Rotation ? 4 : 3;
        const std::vector<double> values = doc.read(sampler["output"].get<std::size_t>(), width);
        const std::size_t per_key = interp == "CUBICSPLINE" ? 3 : 1;  // in-tangent, value, out-tangent
        if (values.size() != c.times.size() * width * per_key)
          doc.fail("animation " + anim.name + ": sampler " + std::to_string(si) + " has " + std::to_string(values.size() / width) + " values for " + std::to_string(c.times.size()) + " keys");
        for (std::size_t k = 0; k < c.times.size(); ++k) {
          const std::size_t at = (k * per_key + (per_key == 3 ? 1 : 0)) * width;
          Eigen::Vector4d v = Eigen::Vector4d::Zero();
          for (int i = 0; i < width; ++i) v[i] = values[at + i];
          c.values.push_back(v);
        }
        if (!std::is_sorted(c.times.begin(), c.times.end())) doc.fail("animation " + anim.name + ": key times are not increasing");
        anim.channels.push_back(std::move(c));
      }
      if (!anim.channels.empty()) result.skinned.rig.animations.push_back(std::move(anim));
    }
  if (std::string problem = mesh.check_layout(); !problem.empty()) doc.fail(problem);
  return result;
}

}  // namespace

SkinnedReadResult read_skinned_gltf(const std::filesystem::path& path) {
  try {
    return read_impl(path);
  } catch (const Failure& f) {
    SkinnedReadResult r;
    r.error = f.message;
    return r;
  } catch (const json::exception& e) {
    SkinnedReadResult r;
    r.error = path.string() + ": malformed glTF: " + e.what();
    return r;
  }
}

}  // namespace quadlod
