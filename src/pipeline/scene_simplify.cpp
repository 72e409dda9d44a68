// quadlod — simplify_scene (include/quadlod/lod.h): every mesh of a scene reduced on its own,
// the scene's target split among the meshes by their triangle-equivalents. Meshes are stored
// once however many nodes reference them, so instances are reduced once.
#include "quadlod/lod.h"
#include "quadlod/metrics.h"
#include "quadlod/protect.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace quadlod {

SceneSimplifyResult simplify_scene(const Scene& input, const SceneSimplifyParams& params) {
  SceneSimplifyResult result;
  if (input.meshes.empty()) {
    result.error = "the scene has no mesh to reduce";
    return result;
  }
  result.scene = input;
  result.input_tri_equivalent = input.tri_equivalent_count();
  const SimplifyOptions& base = params.options;
  const bool absolute = base.target_tri_equivalent > 0;
  // Protect weights (issue 34) index the scene's vertices mesh after mesh (docs/protect.md).
  std::vector<std::vector<double>> protect;
  if (!base.protect_weights.empty()) {
    std::vector<Index> sizes;
    for (const SceneMesh& m : input.meshes) sizes.push_back(m.mesh.num_vertices());
    if (std::string bad = split_protect_weights(base.protect_weights, sizes, protect); !bad.empty()) {
      result.error = bad;
      return result;
    }
  }
  result.report = {{"per_mesh", params.per_mesh}, {"meshes", nlohmann::json::array()}};
  // Weights from a colour channel (issue 34): meshes without vertex colours are not protected; a
  // scene where none has them is an error, as for one mesh.
  const bool by_colour = base.protect_weights.empty() && base.protect_channel != SimplifyOptions::ProtectChannel::None;
  if (by_colour && std::none_of(input.meshes.begin(), input.meshes.end(),
                                [](const SceneMesh& m) { return !m.mesh.vertex_colors.empty(); })) {
    result.error = std::string("protect from ") + to_string(base.protect_channel) + ": no mesh of the scene has vertex colours";
    return result;
  }
  for (std::size_t m = 0; m < input.meshes.size(); ++m) {
    const SceneMesh& mesh = input.meshes[m];
    const std::uint64_t te = tri_equivalent_count(mesh.mesh);
    SimplifyOptions options = base;
    if (!protect.empty()) options.protect_weights = std::move(protect[m]);
    if (by_colour && mesh.mesh.vertex_colors.empty()) options.protect_channel = SimplifyOptions::ProtectChannel::None;
    if (absolute && !params.per_mesh) {
      // The scene's target N split by size: mesh i gets N · te_i / Σ te (at least 1).
      const double share = result.input_tri_equivalent > 0 ? double(te) / double(result.input_tri_equivalent) : 0.0;
      options.target_tri_equivalent = std::max<std::uint64_t>(1, std::llround(share * double(base.target_tri_equivalent)));
    }
    const std::uint64_t target =
        options.target_tri_equivalent > 0 ? options.target_tri_equivalent
                                           : std::max<std::uint64_t>(1, std::llround(options.ratio * double(te)));
    const auto start = std::chrono::steady_clock::now();
    SimplifyResult reduced;
    if (te <= target) {
      // Already small enough (e.g. --faces per mesh above a small mesh's size): unchanged.
      reduced.mesh = mesh.mesh;
      reduced.achieved = te;
      const FaceCounts counts = count_faces(mesh.mesh);
      reduced.quads = static_cast<Index>(counts.quads);
      reduced.triangles = static_cast<Index>(counts.tris);
      reduced.ngons = static_cast<Index>(counts.ngons);
      reduced.note = "already at or below the target";
    } else {
      reduced = simplify(mesh.mesh, options);
      if (!reduced.ok()) {
        result.error = "mesh '" + mesh.name + "': " + reduced.error;
        return result;
      }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.target += target;
    result.achieved += reduced.achieved;
    result.quads += reduced.quads;
    result.triangles += reduced.triangles;
    result.ngons += reduced.ngons;
    result.report["meshes"].push_back({{"name", mesh.name},
                                       {"input_tri_equivalent", te},
                                       {"target", target},
                                       {"achieved", reduced.achieved},
                                       {"quads", reduced.quads},
                                       {"triangles", reduced.triangles},
                                       {"ngons", reduced.ngons},
                                       {"seconds", seconds},
                                       {"note", reduced.note},
                                       {"simplify", std::move(reduced.report)}});
    result.scene.meshes[m].mesh = std::move(reduced.mesh);
  }
  result.report["input_tri_equivalent"] = result.input_tri_equivalent;
  result.report["target"] = result.target;
  result.report["achieved"] = result.achieved;
  result.report["quads"] = result.quads;
  result.report["triangles"] = result.triangles;
  result.report["ngons"] = result.ngons;
  return result;
}

}  // namespace quadlod
