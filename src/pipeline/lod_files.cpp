// quadlod — the files of a LOD chain (include/quadlod/lod.h): one scene file per level, then
// lods.json (docs/lod.md).
#include "quadlod/lod.h"

#include <chrono>

namespace quadlod {

std::filesystem::path lod_file_path(const std::filesystem::path& dir, const std::string& stem, std::size_t level,
                                    const std::string& extension) {
  return dir / (stem + ".lod" + std::to_string(level + 1) + extension);
}

LodFilesResult write_lod_files(const SceneLodResult& chain, const std::filesystem::path& input,
                               const std::filesystem::path& dir, const std::string& extension,
                               const nlohmann::json& extra) {
  const std::string stem = input.stem().string();
  LodFilesResult result;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir)) {
    result.error = dir.string() + ": cannot create the output directory";
    return result;
  }
  result.report = chain.report;
  for (const auto& [key, value] : extra.items()) result.report[key] = value;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t l = 0; l < chain.levels.size(); ++l) {
    const std::filesystem::path file = lod_file_path(dir, stem, l, extension);
    Scene level_scene = chain.levels[l];
    for (SceneMesh& mesh : level_scene.meshes)
      if (!mesh.mesh.material_libraries.empty())
        for (std::string& w : rebase_material_libraries(mesh.mesh, input, file)) result.warnings.push_back(std::move(w));
    const WriteResult written = write_scene(level_scene, file);
    if (!written.ok()) {
      result.error = written.error;
      return result;
    }
    result.warnings.insert(result.warnings.end(), written.warnings.begin(), written.warnings.end());
    nlohmann::json& level = result.report["levels"][l];
    level["file"] = file.filename().string();
    const double faces = level["quads"].get<double>() + level["triangles"].get<double>() + level["ngons"].get<double>();
    level["quad_fraction"] = faces > 0 ? level["quads"].get<double>() / faces : 0.0;
  }
  result.report["write_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const WriteResult report = write_file_atomically(dir / "lods.json", result.report.dump(2) + "\n");
  if (!report.ok()) result.error = report.error;
  return result;
}

}  // namespace quadlod
