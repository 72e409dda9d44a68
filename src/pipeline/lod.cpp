// quadlod — LOD chains (include/quadlod/lod.h): level ℓ is simplify() of level ℓ − 1 aimed at
// ratio_ℓ × the input's size, measured against the input (HausdorffToInput: evaluate()'s
// Hausdorff distance, the input side built once).
#include "pipeline/lod_distance.h"
#include "quadlod/lod.h"
#include "quadlod/protect.h"
#include "quadlod/metrics.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

namespace quadlod {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string check_ratios(const std::vector<double>& ratios) {
  if (ratios.empty()) return "no LOD levels asked for";
  for (std::size_t i = 0; i < ratios.size(); ++i) {
    if (!(ratios[i] > 0.0 && ratios[i] < 1.0))
      return "LOD level " + std::to_string(i) + ": ratio " + std::to_string(ratios[i]) + " is not in (0, 1)";
    if (i > 0 && !(ratios[i] < ratios[i - 1]))
      return "LOD level " + std::to_string(i) + ": ratios must decrease";
  }
  return {};
}

nlohmann::json level_json(const LodLevel& level) {
  const auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"ratio", level.ratio},       {"target", level.target},
          {"achieved", level.achieved}, {"quads", level.quads},
          {"triangles", level.triangles}, {"ngons", level.ngons},
          {"hausdorff", num(level.hausdorff)}, {"hausdorff_over_diagonal", num(level.hausdorff_over_diagonal)},
          {"screen_size", num(level.screen_size)}, {"seconds", level.seconds},
          {"measure_seconds", level.measure_seconds}, {"note", level.note}};
}

}  // namespace

double lod_screen_size(double hausdorff_over_diagonal, double pixel_tolerance, double screen_height_pixels) {
  if (!(hausdorff_over_diagonal > 0.0)) return 1.0;
  return std::clamp(pixel_tolerance / (hausdorff_over_diagonal * screen_height_pixels), 0.0, 1.0);
}

std::vector<double> lod_ratios_by_count(int count, double step) {
  std::vector<double> ratios;
  double r = 1.0;
  for (int i = 0; i < count; ++i) ratios.push_back(r *= step);
  return ratios;
}

LodChainResult lod_chain(const PolyMesh& input, const LodChainParams& params) {
  const auto start = std::chrono::steady_clock::now();
  LodChainResult result;
  result.error = check_ratios(params.ratios);
  if (!result.ok()) return result;
  result.input_tri_equivalent = tri_equivalent_count(input);
  const double diagonal = bounding_box(input).diagonal();
  const double longest = bounding_box(input).longest_side();
  const PolyMesh* previous = &input;
  // Protect weights (issue 34) of `previous`'s vertices: level ℓ carries level ℓ − 1's.
  std::vector<double> protect = params.simplify.protect_weights;
  std::unique_ptr<lod_detail::HausdorffToInput> to_input;  // built at the first measurement
  for (double ratio : params.ratios) {
    LodLevel level;
    level.ratio = ratio;
    SimplifyOptions options = params.simplify;
    if (previous != &input) options.protect_weights = protect;
    options.ratio = 1.0;
    options.target_tri_equivalent =
        std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(ratio * double(result.input_tri_equivalent))));
    // Lines bend below a fraction of the chain's input, not of the previous level (issue 32).
    options.bend_lines_below_ratio = params.simplify.bend_lines_below_ratio * double(result.input_tri_equivalent) /
                                     double(std::max<std::uint64_t>(1, tri_equivalent_count(*previous)));
    const auto reduce_start = std::chrono::steady_clock::now();
    // A level already at or below its target (a tiny mesh) is the previous level unchanged.
    SimplifyResult reduced;
    if (tri_equivalent_count(*previous) <= options.target_tri_equivalent) {
      reduced.mesh = *previous;
      const FaceCounts counts = count_faces(reduced.mesh);
      reduced.achieved = counts.tri_equivalent;
      reduced.quads = static_cast<Index>(counts.quads);
      reduced.triangles = static_cast<Index>(counts.tris);
      reduced.ngons = static_cast<Index>(counts.ngons);
      reduced.note = "already at or below the target";
    } else {
      reduced = simplify(*previous, options);
      protect = reduced.protect_weights;
      if (!reduced.ok()) {
        result.error = reduced.error;
        result.levels.clear();
        return result;
      }
    }
    level.seconds = seconds_since(reduce_start);
    level.target = options.target_tri_equivalent;
    level.achieved = reduced.achieved;
    level.quads = reduced.quads;
    level.triangles = reduced.triangles;
    level.ngons = reduced.ngons;
    level.note = reduced.note;
    level.report = std::move(reduced.report);
    level.mesh = std::move(reduced.mesh);
    level.hausdorff = level.hausdorff_over_diagonal = level.screen_size = std::numeric_limits<double>::quiet_NaN();
    if (params.measure_hausdorff) {
      const auto measure_start = std::chrono::steady_clock::now();
      if (!to_input) to_input = std::make_unique<lod_detail::HausdorffToInput>(input, params.hausdorff_samples);
      const double h = to_input->measure(level.mesh);
      if (std::isfinite(h) && diagonal > 0) {
        level.hausdorff = h;
        level.hausdorff_over_diagonal = h * longest / diagonal;
        level.screen_size = lod_screen_size(level.hausdorff_over_diagonal, params.pixel_tolerance, params.screen_height_pixels);
        // A coarser level never switches in at a larger size than a finer one.
        if (!result.levels.empty() && std::isfinite(result.levels.back().screen_size))
          level.screen_size = std::min(level.screen_size, result.levels.back().screen_size);
      }
      level.measure_seconds = seconds_since(measure_start);
    }
    result.levels.push_back(std::move(level));
    previous = &result.levels.back().mesh;
  }
  result.seconds = seconds_since(start);
  return result;
}

SceneLodResult lod_chain_scene(const Scene& input, const LodChainParams& params) {
  const auto start = std::chrono::steady_clock::now();
  SceneLodResult result;
  if (input.meshes.empty()) {
    result.error = "the scene has no mesh to reduce";
    return result;
  }
  result.error = check_ratios(params.ratios);
  if (!result.ok()) return result;
  result.levels.assign(params.ratios.size(), input);
  std::vector<nlohmann::json> levels(params.ratios.size());
  for (std::size_t l = 0; l < params.ratios.size(); ++l) {
    levels[l] = {{"ratio", params.ratios[l]}, {"target", 0}, {"achieved", 0}, {"quads", 0}, {"triangles", 0},
                 {"ngons", 0}, {"hausdorff", nullptr}, {"screen_size", nullptr}, {"seconds", 0.0},
                 {"measure_seconds", 0.0}, {"meshes", nlohmann::json::array()}};
  }
  // Protect weights (issue 34) index the scene's vertices mesh after mesh (docs/protect.md).
  std::vector<std::vector<double>> protect;
  if (!params.simplify.protect_weights.empty()) {
    std::vector<Index> sizes;
    for (const SceneMesh& m : input.meshes) sizes.push_back(m.mesh.num_vertices());
    if (std::string bad = split_protect_weights(params.simplify.protect_weights, sizes, protect); !bad.empty()) {
      result.error = bad;
      result.levels.clear();
      return result;
    }
  }
  // Weights from a colour channel: meshes without vertex colours are not protected (as simplify_scene).
  const bool by_colour = params.simplify.protect_weights.empty() &&
                         params.simplify.protect_channel != SimplifyOptions::ProtectChannel::None;
  if (by_colour && std::none_of(input.meshes.begin(), input.meshes.end(),
                                [](const SceneMesh& m) { return !m.mesh.vertex_colors.empty(); })) {
    result.error = std::string("protect from ") + to_string(params.simplify.protect_channel) +
                   ": no mesh of the scene has vertex colours";
    result.levels.clear();
    return result;
  }
  std::uint64_t input_te = 0;
  for (std::size_t m = 0; m < input.meshes.size(); ++m) {
    const bool own = !protect.empty() || (by_colour && input.meshes[m].mesh.vertex_colors.empty());
    LodChainParams mesh_params;
    if (own) {
      mesh_params = params;
      if (!protect.empty()) mesh_params.simplify.protect_weights = std::move(protect[m]);
      if (by_colour && input.meshes[m].mesh.vertex_colors.empty())
        mesh_params.simplify.protect_channel = SimplifyOptions::ProtectChannel::None;
    }
    const LodChainResult chain = lod_chain(input.meshes[m].mesh, own ? mesh_params : params);
    if (!chain.ok()) {
      result.error = "mesh '" + input.meshes[m].name + "': " + chain.error;
      result.levels.clear();
      return result;
    }
    input_te += chain.input_tri_equivalent;
    for (std::size_t l = 0; l < chain.levels.size(); ++l) {
      const LodLevel& level = chain.levels[l];
      nlohmann::json& j = levels[l];
      j["target"] = j["target"].get<std::uint64_t>() + level.target;
      j["achieved"] = j["achieved"].get<std::uint64_t>() + level.achieved;
      j["quads"] = j["quads"].get<std::uint64_t>() + level.quads;
      j["triangles"] = j["triangles"].get<std::uint64_t>() + level.triangles;
      j["ngons"] = j["ngons"].get<std::uint64_t>() + level.ngons;
      j["seconds"] = j["seconds"].get<double>() + level.seconds;
      j["measure_seconds"] = j["measure_seconds"].get<double>() + level.measure_seconds;
      if (std::isfinite(level.hausdorff) &&
          (j["hausdorff"].is_null() || level.hausdorff > j["hausdorff"].get<double>()))
        j["hausdorff"] = level.hausdorff;
      if (std::isfinite(level.screen_size) &&
          (j["screen_size"].is_null() || level.screen_size < j["screen_size"].get<double>()))
        j["screen_size"] = level.screen_size;
      nlohmann::json mesh_json = level_json(level);
      // Symmetry (issue 34): the plane each level was reduced about, when it was asked for.
      if (level.report.contains("symmetry") && level.report["symmetry"].value("requested", "off") != "off")
        mesh_json["symmetry"] = level.report["symmetry"];
      mesh_json["name"] = input.meshes[m].name;
      mesh_json["input_tri_equivalent"] = chain.input_tri_equivalent;
      j["meshes"].push_back(std::move(mesh_json));
      result.levels[l].meshes[m].mesh = level.mesh;
    }
  }
  result.report = {{"input_tri_equivalent", input_te},
                   {"pixel_tolerance", params.pixel_tolerance},
                   {"screen_height_pixels", params.screen_height_pixels},
                   {"levels", levels}};
  result.seconds = seconds_since(start);
  result.report["seconds"] = result.seconds;
  return result;
}

}  // namespace quadlod
