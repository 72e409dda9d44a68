// quadlod — the binary FBX reader's fuzz check (src/io/fbx_binary.h, fbx_control_points.h):
// no assimp in the loop, so the fuzzer spends its time on our parser.
#include "fuzz_checks.h"

#include "io/fbx_control_points.h"

#include <algorithm>

namespace quadlod::fuzz {

std::string check_fbx_binary(std::string_view bytes) {
  const fbx::GeometryRead r = fbx::read_mesh_geometries(bytes);
  if (!r.ok()) {
    if (r.error.rfind("FBX ", 0) != 0) return "fbx: error does not start with \"FBX \": " + r.error;
    if (r.error.find('\n') != std::string::npos) return "fbx: error message spans lines: " + r.error;
    if (!r.geometries.empty()) return "fbx: geometries kept after an error";
    return {};
  }
  for (std::size_t g = 0; g < r.geometries.size(); ++g) {
    const fbx::MeshGeometry& m = r.geometries[g];
    const std::string where = "fbx: geometry " + std::to_string(g) + ": ";
    if (m.polygon_offsets.empty() || m.polygon_offsets.front() != 0 || m.polygon_offsets.back() != m.polygon_corners.size())
      return where + "polygon offsets do not cover the corners";
    if (!std::is_sorted(m.polygon_offsets.begin(), m.polygon_offsets.end())) return where + "polygon offsets decrease";
    for (Index c : m.polygon_corners)
      if (c >= m.control_points.size()) return where + "a corner names a missing control point";
    for (const Vec3& p : m.control_points)
      if (!p.allFinite()) return where + "a control point is not finite";
    if (!m.polygon_material.empty() && m.polygon_material.size() != m.num_polygons())
      return where + "material slots are not one per polygon";
  }
  return {};
}

}  // namespace quadlod::fuzz
