// Issue 34: the default weights of blend shapes in a .glb written by assimp 5.2's glTF 2
// exporter, which writes the targets (and, asked to, their names in mesh.extras.targetNames) but
// not glTF's `mesh.weights` (glTF 2.0 §3.7.2.2 "Morph Targets": the default weights, which
// Blender's importer takes as the shape keys' values). The JSON chunk is parsed, `weights` added
// to every mesh with targets, and the GLB rebuilt around the same BIN chunk:
//
//   header   "glTF" u32 version 2, u32 total length
//   chunk 0  u32 length, "JSON", UTF-8 padded with spaces to 4 bytes
//   chunk 1  u32 length, "BIN\0", the buffer (untouched)
#include "io/assimp_detail.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>

namespace quadlod::io_detail {

namespace {

std::uint32_t read_u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, s.data() + at, 4);  // little endian, as every platform quadlod builds on
  return v;
}

void append_u32(std::string& s, std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

}  // namespace

bool add_gltf_morph_weights(const Scene& scene, std::string& glb) {
  // The scene's meshes with shapes, in order: the exporter writes one glTF mesh per aiMesh in the
  // same order (several per scene mesh when it has several materials), each with the scene
  // mesh's target names; a glTF mesh takes the weights of the next scene mesh with those names.
  std::vector<const PolyMesh*> shaped;
  for (const SceneMesh& m : scene.meshes)
    if (!m.mesh.morph_targets.empty()) shaped.push_back(&m.mesh);
  if (shaped.empty()) return true;
  if (glb.size() < 20 || glb.compare(0, 4, "glTF") != 0 || glb.compare(16, 4, "JSON") != 0) return false;
  const std::uint32_t json_length = read_u32(glb, 12);
  if (20 + std::size_t(json_length) > glb.size()) return false;
  nlohmann::json doc = nlohmann::json::parse(glb.substr(20, json_length), nullptr, false);
  if (doc.is_discarded() || !doc.contains("meshes") || !doc["meshes"].is_array()) return false;
  std::size_t cursor = 0;
  for (nlohmann::json& mesh : doc["meshes"]) {
    if (!mesh.contains("extras") || !mesh["extras"].contains("targetNames")) continue;
    const nlohmann::json& names = mesh["extras"]["targetNames"];
    auto same_names = [&](const PolyMesh* m) {
      if (!names.is_array() || names.size() != m->morph_targets.size()) return false;
      for (std::size_t k = 0; k < names.size(); ++k)
        if (!names[k].is_string() || names[k].get<std::string>() != m->morph_targets[k].name) return false;
      return true;
    };
    // A mesh split by material gives several glTF meshes in a row: stay on the current scene mesh
    // while it matches, else move on to the next that does.
    std::size_t at = cursor;
    while (at < shaped.size() && !same_names(shaped[at])) ++at;
    if (at == shaped.size()) continue;
    cursor = at;
    nlohmann::json weights = nlohmann::json::array();
    for (const MorphTarget& t : shaped[at]->morph_targets) weights.push_back(t.default_weight);
    mesh["weights"] = std::move(weights);
  }
  std::string text = doc.dump();
  while (text.size() % 4 != 0) text.push_back(' ');
  const std::string rest = glb.substr(20 + std::size_t(json_length));  // the BIN chunk, if any
  std::string out = glb.substr(0, 8);
  append_u32(out, static_cast<std::uint32_t>(12 + 8 + text.size() + rest.size()));
  append_u32(out, static_cast<std::uint32_t>(text.size()));
  out += "JSON";
  out += text;
  out += rest;
  glb = std::move(out);
  return true;
}

}  // namespace quadlod::io_detail
