// quadlod — LOD chains and scene reduction (issue 21; docs/lod.md).
//
// A chain reduces level ℓ from level ℓ − 1 (not from the input), so the edge loops of a coarse
// level are a subset of the finer level's and the cost of the chain is about that of one
// reduction to its smallest level (each reduction is split into passes anyway, simplify.h).
// Every level is measured against the input: counts, Hausdorff distance (as `quadlod eval`
// defines it, docs/metrics.md) and a screen-size switch threshold derived from it.
#pragma once

#include "quadlod/mesh.h"
#include "quadlod/scene.h"
#include "quadlod/simplify.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace quadlod {

struct LodChainParams {
  /// Each level's size as a fraction of the INPUT's triangle-equivalents; strictly decreasing,
  /// each in (0, 1).
  std::vector<double> ratios{0.5, 0.25, 0.125};
  /// The reduction's options; `ratio` and `target_tri_equivalent` are set per level.
  SimplifyOptions simplify;
  /// Measure each level's Hausdorff distance to the input — evaluate()'s `hausdorff`
  /// (metrics.h) for these samples and seed 1, without the rest of evaluate() — and derive the
  /// switch threshold. false: hausdorff and screen_size are NaN.
  bool measure_hausdorff = true;
  /// Surface samples per direction of that measurement (EvalParams::samples); every vertex of
  /// both meshes is measured too. 50000 as a compromise of time and the estimate's resolution
  /// (docs/lod.md has the measured cost).
  std::uint64_t hausdorff_samples = 50000;
  /// Screen-size rule (lod_screen_size): the level may be shown once its Hausdorff error
  /// projects to at most `pixel_tolerance` pixels on a screen `screen_height_pixels` tall.
  double pixel_tolerance = 1.0;
  double screen_height_pixels = 1080.0;
};

struct LodLevel {
  double ratio = 0.0;             ///< asked, of the input's triangle-equivalents
  std::uint64_t target = 0;       ///< triangle-equivalents asked
  std::uint64_t achieved = 0;     ///< triangle-equivalents of `mesh`
  Index quads = 0, triangles = 0, ngons = 0;
  /// Hausdorff distance to the input in units of the input's longest bbox side (metrics.h).
  double hausdorff = 0.0;
  /// The same over the input's bbox diagonal (what lod_screen_size takes).
  double hausdorff_over_diagonal = 0.0;
  /// Largest screen size (fraction of the screen height covered by the input's bounding-sphere
  /// diameter) at which this level may replace the finer ones; see lod_screen_size.
  double screen_size = 0.0;
  double seconds = 0.0;          ///< the reduction from the previous level
  double measure_seconds = 0.0;  ///< the Hausdorff measurement
  std::string note;              ///< SimplifyResult::note of the reduction
  PolyMesh mesh;
  nlohmann::json report;  ///< SimplifyResult::report of the reduction
};

struct LodChainResult {
  std::vector<LodLevel> levels;  ///< one per ratio, in order
  std::uint64_t input_tri_equivalent = 0;
  double seconds = 0.0;  ///< the whole chain (reductions and measurements)
  std::string error;     ///< non-empty: bad parameters or an input simplify() refuses
  bool ok() const { return error.empty(); }
};

/// Builds the chain. Never throws for bad input; `error` says what is wrong.
LodChainResult lod_chain(const PolyMesh& input, const LodChainParams& params);

/// The screen-size switch threshold of a level whose Hausdorff error is h (over the bbox
/// diagonal D, which is also the bounding-sphere diameter the screen size is measured by):
/// at screen size s the object spans s · H pixels, so the error spans h · s · H pixels; the
/// level is acceptable while that is at most the tolerance τ:
///     s ≤ τ / (h · H),  clamped to [0, 1]   (h = 0 gives 1: always acceptable).
double lod_screen_size(double hausdorff_over_diagonal, double pixel_tolerance, double screen_height_pixels);

/// The ratios of `count` levels, each `step` times the previous: step, step², …
std::vector<double> lod_ratios_by_count(int count, double step = 0.5);

// --- scenes -------------------------------------------------------------------------------------

struct SceneSimplifyParams {
  /// options.ratio / options.target_tri_equivalent are the target of the whole scene, split
  /// among its meshes by their triangle-equivalents (so each mesh gets the same ratio); with
  /// `per_mesh` they are the target of each mesh.
  SimplifyOptions options;
  bool per_mesh = false;
};

struct SceneSimplifyResult {
  Scene scene;  ///< the input's nodes and materials, every mesh reduced (instances once)
  std::string error;
  std::uint64_t input_tri_equivalent = 0, target = 0, achieved = 0;
  Index quads = 0, triangles = 0, ngons = 0;
  /// Per mesh: name, input/target/achieved, quads/tris/ngons, seconds, note, the simplify report.
  nlohmann::json report;
  bool ok() const { return error.empty(); }
};

/// Reduces every mesh of the scene. A scene without meshes is an error ("no mesh to reduce").
SceneSimplifyResult simplify_scene(const Scene& input, const SceneSimplifyParams& params);

struct SceneLodResult {
  std::vector<Scene> levels;  ///< one scene per ratio
  /// Per level: ratio, target, achieved, quads/tris/ngons, hausdorff (the largest over the
  /// meshes), screen_size (the smallest over the meshes, each by its own bounding sphere: the
  /// level switches in when every mesh may), seconds; and per mesh the LodLevel figures.
  nlohmann::json report;
  double seconds = 0.0;
  std::string error;
  bool ok() const { return error.empty(); }
};

/// lod_chain on every mesh of the scene; level ℓ's scene is the input's with each mesh replaced
/// by its level ℓ.
SceneLodResult lod_chain_scene(const Scene& input, const LodChainParams& params);

/// The file of level l (0-based) of a chain: `dir / (stem + ".lod" + (l + 1) + extension)`.
std::filesystem::path lod_file_path(const std::filesystem::path& dir, const std::string& stem, std::size_t level,
                                    const std::string& extension);

struct LodFilesResult {
  nlohmann::json report;  ///< chain.report plus per level "file" and "quad_fraction", write_seconds
  std::vector<std::string> warnings;
  std::string error;
  bool ok() const { return error.empty(); }
};

/// Writes every level of `chain` (write_scene, atomically) to lod_file_path(dir, input's stem, l,
/// extension), then `dir/lods.json` (the report, with `extra` merged in) last — so a present
/// lods.json means the whole chain is there. Creates `dir`. OBJ levels keep finding the input's
/// MTL files (rebase_material_libraries, io.h; its warnings are returned).
LodFilesResult write_lod_files(const SceneLodResult& chain, const std::filesystem::path& input,
                               const std::filesystem::path& dir, const std::string& extension,
                               const nlohmann::json& extra);

}  // namespace quadlod
