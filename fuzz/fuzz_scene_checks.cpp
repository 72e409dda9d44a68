// quadlod — the assimp front end's fuzz check (issue 21's read_scene_from_memory; issue 23).
// Compiled only where include/quadlod/scene.h exists (fuzz/CMakeLists.txt, tests/CMake glue):
// on a tree without the scene reader this file is not built.
#include "fuzz_checks.h"

#include "quadlod/scene.h"

namespace quadlod::fuzz {

std::string check_scene(std::string_view hint, std::string_view bytes) {
  const std::string name = "fuzz." + std::string(hint);
  const SceneReadResult r = read_scene_from_memory(bytes.data(), bytes.size(), hint, name);
  if (!r.ok()) {
    if (r.error.empty()) return "read_scene: failed without a message";
    if (r.error.find('\n') != std::string::npos) return "read_scene: error message spans lines: " + r.error;
    return {};
  }
  for (std::size_t i = 0; i < r.scene.meshes.size(); ++i)
    if (std::string layout = r.scene.meshes[i].mesh.check_layout(); !layout.empty())
      return "read_scene: mesh " + std::to_string(i) + ": invalid layout: " + layout;
  for (std::size_t n = 0; n < r.scene.nodes.size(); ++n) {
    const SceneNode& node = r.scene.nodes[n];
    if (node.parent != kInvalidIndex && node.parent >= n)
      return "read_scene: node " + std::to_string(n) + " has parent " + std::to_string(node.parent) +
             " (parents must precede children)";
    for (Index m : node.meshes)
      if (m >= r.scene.meshes.size()) return "read_scene: node " + std::to_string(n) + " names mesh " + std::to_string(m);
  }
  return {};
}

}  // namespace quadlod::fuzz
