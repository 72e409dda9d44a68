// quadlod — batch runs (include/quadlod/batch.h; docs/batch.md).
#include "quadlod/batch.h"
#include "quadlod/lod.h"
#include "quadlod/scene.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <fstream>
#include <set>

namespace quadlod {

namespace {

bool is_lod(const nlohmann::json& options) { return options.contains("levels") || options.contains("count"); }

/// The options of a job as SimplifyOptions / LodChainParams; "" or the error.
std::string apply_options(const nlohmann::json& options, SimplifyOptions& simplify, bool& per_mesh,
                          std::vector<double>& levels, std::string& format) {
  static const std::set<std::string> kKnown = {"ratio", "faces",     "levels", "count",  "format", "per_mesh",
                                               "objective", "time_limit", "threads", "seed", "features",
                                               "recover_quads", "seams"};
  if (!options.is_object()) return "options must be a JSON object";
  for (const auto& [key, value] : options.items())
    if (!kKnown.count(key)) return "unknown option '" + key + "'";
  try {
    if (options.contains("ratio")) simplify.ratio = options["ratio"].get<double>();
    if (options.contains("faces")) simplify.target_tri_equivalent = options["faces"].get<std::uint64_t>();
    if (options.contains("per_mesh")) per_mesh = options["per_mesh"].get<bool>();
    if (options.contains("objective")) simplify.objective = options["objective"].get<std::string>();
    if (options.contains("time_limit")) simplify.time_limit_seconds = options["time_limit"].get<double>();
    if (options.contains("threads")) simplify.threads = options["threads"].get<int>();
    if (options.contains("seed")) simplify.seed = options["seed"].get<std::uint32_t>();
    if (options.contains("features")) simplify.features = options["features"].get<bool>();
    if (options.contains("recover_quads")) simplify.recover_quads = options["recover_quads"].get<std::string>();
    if (options.contains("seams")) {
      const auto policy = parse_seam_policy(options["seams"].get<std::string>());
      if (!policy) return "seams must be auto or strict";
      simplify.seams = *policy;
    }
    if (options.contains("levels")) levels = options["levels"].get<std::vector<double>>();
    if (options.contains("count")) levels = lod_ratios_by_count(options["count"].get<int>());
    if (options.contains("format")) format = options["format"].get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    return std::string("bad option value: ") + e.what();
  }
  if (!(simplify.ratio > 0.0 && simplify.ratio <= 1.0)) return "ratio must be in (0, 1]";
  if (simplify.objective != "shape" && simplify.objective != "paper") return "objective must be shape or paper";
  if (simplify.recover_quads != "auto" && simplify.recover_quads != "on" && simplify.recover_quads != "off")
    return "recover_quads must be auto, on or off";
  if (!is_lod(options) && !options.contains("ratio") && !options.contains("faces"))
    return "no target: give ratio, faces, levels or count";
  if (!format.empty() && format[0] != '.') format = "." + format;
  return {};
}

std::filesystem::path resolve(const std::filesystem::path& base, const std::string& path) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? p : base / p;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

BatchPlan plan_batch_folder(const std::filesystem::path& folder, const std::filesystem::path& output_dir,
                            const std::string& extension, const nlohmann::json& options) {
  BatchPlan plan;
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) {
    plan.error = folder.string() + ": not a directory";
    return plan;
  }
  std::vector<std::filesystem::path> inputs;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec))
    if (entry.is_regular_file() && scene_readable_path(entry.path())) inputs.push_back(entry.path());
  if (ec) {
    plan.error = folder.string() + ": " + ec.message();
    return plan;
  }
  std::sort(inputs.begin(), inputs.end());
  std::string ext = extension;
  if (!ext.empty() && ext[0] != '.') ext = "." + ext;
  for (const auto& input : inputs) {
    BatchJob job;
    job.input = input;
    job.options = options;
    job.output = is_lod(options) ? output_dir / input.stem()
                                 : output_dir / (input.stem().string() + (ext.empty() ? default_output_extension(input) : ext));
    if (is_lod(options) && !ext.empty()) job.options["format"] = ext;
    plan.jobs.push_back(std::move(job));
  }
  return plan;
}

BatchPlan plan_batch_manifest(const std::filesystem::path& manifest, const nlohmann::json& defaults) {
  BatchPlan plan;
  std::ifstream in(manifest);
  if (!in) {
    plan.error = "cannot read " + manifest.string();
    return plan;
  }
  const std::filesystem::path base = manifest.parent_path();
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = manifest.string() + ":" + std::to_string(number) + ": ";
    nlohmann::json entry = nlohmann::json::parse(line, nullptr, false);
    if (entry.is_discarded() || !entry.is_object()) {
      plan.error = where + "not a JSON object";
      return plan;
    }
    if (!entry.contains("input") || !entry["input"].is_string() || !entry.contains("output") || !entry["output"].is_string()) {
      plan.error = where + "needs string fields \"input\" and \"output\"";
      return plan;
    }
    BatchJob job;
    job.input = resolve(base, entry["input"].get<std::string>());
    job.output = resolve(base, entry["output"].get<std::string>());
    job.options = defaults.is_object() ? defaults : nlohmann::json::object();
    nlohmann::json own = entry.contains("options") ? entry["options"] : nlohmann::json::object();
    for (const auto& [key, value] : entry.items())
      if (key != "input" && key != "output" && key != "options") own[key] = value;
    if (!own.is_object()) {
      plan.error = where + "\"options\" must be an object";
      return plan;
    }
    // A line's own target replaces the defaults' target of the other kind.
    if (own.contains("ratio") || own.contains("faces") || own.contains("levels") || own.contains("count"))
      for (const char* key : {"ratio", "faces", "levels", "count"}) job.options.erase(key);
    for (const auto& [key, value] : own.items()) job.options[key] = value;
    plan.jobs.push_back(std::move(job));
  }
  return plan;
}

std::vector<BatchJob> shard_jobs(const std::vector<BatchJob>& jobs, unsigned index, unsigned count) {
  std::vector<BatchJob> share;
  if (count == 0) return share;
  for (std::size_t i = index; i < jobs.size(); i += count) share.push_back(jobs[i]);
  return share;
}

bool parse_shard(const std::string& text, unsigned& index, unsigned& count) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) return false;
  const char* begin = text.data();
  const auto a = std::from_chars(begin, begin + slash, index);
  const auto b = std::from_chars(begin + slash + 1, begin + text.size(), count);
  return a.ec == std::errc() && a.ptr == begin + slash && b.ec == std::errc() && b.ptr == begin + text.size() &&
         count > 0 && index < count;
}

bool batch_output_is_current(const BatchJob& job) {
  std::error_code ec;
  const std::filesystem::path done = is_lod(job.options) ? job.output / "lods.json" : job.output;
  if (!std::filesystem::is_regular_file(done, ec)) return false;
  const auto out_time = std::filesystem::last_write_time(done, ec);
  if (ec) return false;
  const auto in_time = std::filesystem::last_write_time(job.input, ec);
  return !ec && out_time >= in_time;
}

nlohmann::json run_batch_job(const BatchJob& job, const BatchRunParams& params) {
  const auto start = std::chrono::steady_clock::now();
  nlohmann::json line = {{"input", job.input.string()}, {"output", job.output.string()}};
  const auto failed = [&](const std::string& error) {
    line["status"] = "failed";
    line["error"] = error;
    line["seconds"] = seconds_since(start);
    return line;
  };
  try {
    SimplifyOptions simplify;
    simplify.progress = params.progress;
    bool per_mesh = false;
    std::vector<double> levels;
    std::string format;
    const std::string bad = apply_options(job.options, simplify, per_mesh, levels, format);
    if (!bad.empty()) return failed(job.input.string() + ": " + bad);
    std::error_code ec;
    if (std::filesystem::equivalent(job.input, job.output, ec)) return failed(job.output.string() + ": refusing to overwrite the input");
    if (!params.force && batch_output_is_current(job)) {
      line["status"] = "skipped";
      line["seconds"] = seconds_since(start);
      return line;
    }
    const SceneReadResult in = read_scene(job.input);
    if (!in.ok()) return failed(in.error);
    if (in.scene.meshes.empty()) return failed(job.input.string() + ": the scene has no mesh to reduce");
    if (is_lod(job.options)) {
      LodChainParams chain_params;
      chain_params.ratios = levels;
      chain_params.simplify = simplify;
      const SceneLodResult chain = lod_chain_scene(in.scene, chain_params);
      if (!chain.ok()) return failed(job.input.string() + ": " + chain.error);
      const std::string ext = format.empty() ? default_output_extension(job.input) : format;
      const LodFilesResult files =
          write_lod_files(chain, job.input, job.output, ext, {{"input", job.input.string()}});
      if (!files.ok()) return failed(files.error);
      line["input_tri_equivalent"] = files.report["input_tri_equivalent"];
      line["levels"] = nlohmann::json::array();
      for (const auto& level : files.report["levels"]) {
        nlohmann::json l = level;
        l.erase("meshes");
        line["levels"].push_back(std::move(l));
      }
    } else {
      SceneSimplifyParams scene_params;
      scene_params.options = simplify;
      scene_params.per_mesh = per_mesh;
      SceneSimplifyResult r = simplify_scene(in.scene, scene_params);
      if (!r.ok()) return failed(job.input.string() + ": " + r.error);
      // OBJ outputs elsewhere keep finding the input's MTL files.
      for (SceneMesh& mesh : r.scene.meshes)
        if (!mesh.mesh.material_libraries.empty()) rebase_material_libraries(mesh.mesh, job.input, job.output);
      std::filesystem::create_directories(job.output.parent_path().empty() ? "." : job.output.parent_path(), ec);
      const WriteResult written = write_scene(r.scene, job.output);
      if (!written.ok()) return failed(written.error);
      line["input_tri_equivalent"] = r.input_tri_equivalent;
      line["target"] = r.target;
      line["achieved"] = r.achieved;
      line["quads"] = r.quads;
      line["triangles"] = r.triangles;
      line["ngons"] = r.ngons;
      line["meshes"] = r.scene.meshes.size();
    }
    line["status"] = "done";
    line["seconds"] = seconds_since(start);
    return line;
  } catch (const std::exception& e) {
    return failed(job.input.string() + ": internal error: " + e.what());
  }
}

}  // namespace quadlod
