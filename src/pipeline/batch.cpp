// quadlod — batch runs (include/quadlod/batch.h; docs/batch.md).
//
// Resuming after a kill at any moment (issue 36). A job's state on disk moves through
//
//   (old outputs, old record) ─► remove old record ─► write outputs, each temp + rename ─►
//   write new record (temp + rename) ─► print the line
//
// and a run may die between any two steps, or inside a write (SIGKILL leaves the temp file).
// The record vouches for exactly the bytes it saw (size + mtime of the input and of every
// output), so whatever step a run died at, the next run either finds a record that still matches
// (the job was complete: skip, and repeat the recorded metrics) or redoes the job; and it first
// removes the job's leftover temp files, so none survives a completed rerun.
#include "quadlod/batch.h"
#include "quadlod/io.h"
#include "quadlod/lod.h"
#include "quadlod/protect.h"
#include "quadlod/scene.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/stat.h>

namespace quadlod {

namespace {

bool is_lod(const nlohmann::json& options) { return options.contains("levels") || options.contains("count"); }

/// The options of a job as SimplifyOptions / LodChainParams; "" or the error.
std::string apply_options(const nlohmann::json& options, SimplifyOptions& simplify, bool& per_mesh,
                          std::vector<double>& levels, std::string& format) {
  static const std::set<std::string> kKnown = {"ratio", "faces",     "levels", "count",  "format", "per_mesh",
                                               "objective", "time_limit", "threads", "seed", "features",
                                               "recover_quads", "seams", "bend_lines_below",
                                               "protect", "protect_from",
                                               "symmetry", "morph_weight"};  // issue 34
  if (!options.is_object()) return "options must be a JSON object";
  for (const auto& [key, value] : options.items())
    if (!kKnown.count(key)) return "unknown option '" + key + "'";
  try {
    if (options.contains("ratio")) simplify.ratio = options["ratio"].get<double>();
    if (options.contains("faces")) simplify.target_tri_equivalent = options["faces"].get<std::uint64_t>();
    if (options.contains("per_mesh")) per_mesh = options["per_mesh"].get<bool>();
    if (options.contains("objective")) {
      const auto objective = parse_objective(options["objective"].get<std::string>());
      if (!objective) return "objective must be shape or paper";
      simplify.objective = *objective;
    }
    if (options.contains("time_limit")) simplify.time_limit_seconds = options["time_limit"].get<double>();
    if (options.contains("threads")) simplify.threads = options["threads"].get<int>();
    if (options.contains("seed")) simplify.seed = options["seed"].get<std::uint32_t>();
    if (options.contains("features")) simplify.features = options["features"].get<bool>();
    if (options.contains("recover_quads")) {
      const auto recovery = parse_quad_recovery(options["recover_quads"].get<std::string>());
      if (!recovery) return "recover_quads must be auto, on or off";
      simplify.recover_quads = *recovery;
    }
    if (options.contains("seams")) {
      const auto policy = parse_seam_policy(options["seams"].get<std::string>());
      if (!policy) return "seams must be auto or strict";
      simplify.seams = *policy;
    }
    if (options.contains("bend_lines_below")) {  // issue 32: far LODs
      simplify.bend_lines_below_ratio = options["bend_lines_below"].get<double>();
      if (!(simplify.bend_lines_below_ratio >= 0.0 && simplify.bend_lines_below_ratio <= 1.0))
        return "bend_lines_below must be in [0, 1]";
    }
    if (options.contains("protect_from")) {  // issue 34; "protect" (a file) is read with the input
      const auto channel = parse_protect_channel(options["protect_from"].get<std::string>());
      if (!channel) return "protect_from must be none, color:r, color:g or color:b";
      simplify.protect_channel = *channel;
    }
    if (options.contains("protect") && !options["protect"].is_string()) return "protect must be a file name";
    if (options.contains("protect") && options.contains("protect_from")) return "give protect or protect_from, not both";
    // Symmetry (issue 34; docs/symmetry.md).
    if (options.contains("symmetry")) {
      const auto symmetry = parse_symmetry(options["symmetry"].get<std::string>());
      if (!symmetry) return "symmetry must be auto, x, y, z or off";
      simplify.symmetry = *symmetry;
    }
    if (options.contains("morph_weight")) {  // issue 34: blend shapes
      simplify.morph_error_weight = options["morph_weight"].get<double>();
      if (!(simplify.morph_error_weight >= 0.0)) return "morph_weight must be >= 0";
    }
    if (options.contains("levels")) levels = options["levels"].get<std::vector<double>>();
    if (options.contains("count")) levels = lod_ratios_by_count(options["count"].get<int>());
    if (options.contains("format")) format = options["format"].get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    return std::string("bad option value: ") + e.what();
  }
  if (!(simplify.ratio > 0.0 && simplify.ratio <= 1.0)) return "ratio must be in (0, 1]";
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

namespace fs = std::filesystem;

constexpr int kRecordVersion = 1;

/// The output path without trailing separators ("out/a/" → "out/a"), so that it has a filename.
fs::path output_path(const BatchJob& job) {
  fs::path out = job.output;
  while (!out.has_filename() && out.has_parent_path() && out != out.parent_path()) out = out.parent_path();
  return out;
}

/// The directory the record's file names are relative to: a chain's own directory, else the
/// output's directory.
fs::path files_base(const BatchJob& job) {
  const fs::path out = output_path(job);
  if (is_lod(job.options)) return out;
  return out.parent_path().empty() ? fs::path(".") : out.parent_path();
}

/// {"size", "mtime_ns"} of a regular file (mtime in ns since the Unix epoch, as stat(2) and
/// Python's os.stat give it: std::filesystem's file clock has another epoch); null when it is
/// missing or not a regular file.
nlohmann::json file_stamp(const fs::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return nullptr;
  const std::int64_t ns = std::int64_t{st.st_mtim.tv_sec} * 1000000000 + st.st_mtim.tv_nsec;
  return {{"size", static_cast<std::uint64_t>(st.st_size)}, {"mtime_ns", ns}};
}

/// The options the record compares: all but "threads" (the output does not depend on it).
nlohmann::json recorded_options(const nlohmann::json& options) {
  nlohmann::json kept = options.is_object() ? options : nlohmann::json::object();
  kept.erase("threads");
  return kept;
}

/// The record of an earlier run when it still vouches for the outputs (see
/// batch_output_is_current), else null.
nlohmann::json current_record(const BatchJob& job) {
  std::ifstream in(batch_record_path(job), std::ios::binary);
  if (!in) return nullptr;
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json record = nlohmann::json::parse(text.str(), nullptr, false);
  if (record.is_discarded() || !record.is_object() || record.value("quadlod_batch_record", 0) != kRecordVersion)
    return nullptr;
  if (!record.contains("options") || record["options"] != recorded_options(job.options)) return nullptr;
  const nlohmann::json input = file_stamp(job.input);
  if (input.is_null() || !record.contains("input") || record["input"] != input) return nullptr;
  if (!record.contains("files") || !record["files"].is_array() || record["files"].empty()) return nullptr;
  if (!record.contains("result") || !record["result"].is_object()) return nullptr;
  const fs::path base = files_base(job);
  for (const nlohmann::json& file : record["files"]) {
    if (!file.is_object() || !file.contains("name") || !file["name"].is_string()) return nullptr;
    const std::string name = file["name"].get<std::string>();
    // Names are plain file names in `base`: a record cannot vouch for files elsewhere.
    if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos) return nullptr;
    nlohmann::json seen = file_stamp(base / name);
    if (seen.is_null()) return nullptr;
    seen["name"] = name;
    if (seen != file) return nullptr;
  }
  return record;
}

/// True for `.NAME.tmp-PID-HEX`, as write_file_atomically names the temporary of NAME, with
/// NAME = `target` (any NAME when `target` is empty).
bool is_temporary_of(const std::string& name, const std::string& target) {
  if (name.size() < 2 || name[0] != '.') return false;
  const std::size_t mark = name.rfind(".tmp-");
  if (mark == std::string::npos || mark < 2) return false;
  if (!target.empty() && name.compare(1, mark - 1, target) != 0) return false;
  if (!target.empty() && mark - 1 != target.size()) return false;
  const std::string tail = name.substr(mark + 5);  // PID-HEX
  const std::size_t dash = tail.find('-');
  if (dash == std::string::npos || dash == 0 || dash + 1 == tail.size()) return false;
  for (std::size_t i = 0; i < tail.size(); ++i) {
    const char c = tail[i];
    const bool ok = i < dash ? (c >= '0' && c <= '9') : i == dash || (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
    if (!ok) return false;
  }
  return true;
}

/// Removes the entries of `dir` that are temporaries of one of `targets` (any, when `targets`
/// holds ""). Returns how many.
std::size_t remove_temporaries_in(const fs::path& dir, const std::vector<std::string>& targets) {
  std::size_t removed = 0;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  std::vector<fs::path> doomed;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    for (const std::string& target : targets)
      if (is_temporary_of(name, target)) {
        doomed.push_back(entry.path());
        break;
      }
  }
  for (const fs::path& p : doomed) removed += fs::remove(p, ec) ? 1 : 0;
  return removed;
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
    // A protect file is named relative to the manifest, like input and output (issue 34).
    if (job.options.contains("protect") && job.options["protect"].is_string())
      job.options["protect"] = resolve(base, job.options["protect"].get<std::string>()).string();
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

std::filesystem::path batch_record_path(const BatchJob& job) {
  const fs::path out = output_path(job);
  std::string name(1, '.');  // not "." + string: GCC 12 warns of a bogus overflow (-Wstringop-overflow)
  name += out.filename().string();
  name += ".batch.json";
  return out.parent_path() / name;
}

bool batch_output_is_current(const BatchJob& job) { return !current_record(job).is_null(); }

std::size_t remove_batch_temporaries(const BatchJob& job) {
  const fs::path out = output_path(job);
  const fs::path dir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  std::size_t removed = remove_temporaries_in(dir, {out.filename().string(), batch_record_path(job).filename().string()});
  if (is_lod(job.options)) removed += remove_temporaries_in(out, {""});  // the chain's own directory
  return removed;
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
    // A temp file of an earlier run killed by SIGKILL (nothing else leaves one): whatever this
    // run does with the job, it must not survive it.
    remove_batch_temporaries(job);
    if (!params.force) {
      const nlohmann::json record = current_record(job);
      if (!record.is_null()) {
        for (const auto& [key, value] : record["result"].items()) line[key] = value;
        line["status"] = "skipped";
        line["seconds"] = seconds_since(start);
        return line;
      }
    }
    // From here on the old outputs are being replaced: nothing may vouch for them any more
    // (a chain killed after its first level would otherwise keep the old lods.json's word).
    const fs::path record_path = batch_record_path(job);
    fs::remove(record_path, ec);
    if (fs::exists(fs::symlink_status(record_path, ec))) return failed(record_path.string() + ": cannot remove the old record");

    // The input's stamp before it is read and again after the work (below): an input changed
    // meanwhile gets no record.
    const nlohmann::json input_stamp = file_stamp(job.input);
    const SceneReadResult in = read_scene(job.input);
    if (!in.ok()) return failed(in.error);
    if (in.scene.meshes.empty()) return failed(job.input.string() + ": the scene has no mesh to reduce");
    if (job.options.contains("protect")) {  // issue 34: one weight per vertex of the scene, mesh after mesh
      std::size_t vertices = 0;
      for (const SceneMesh& m : in.scene.meshes) vertices += m.mesh.num_vertices();
      ProtectWeightsRead weights = read_protect_weights(job.options["protect"].get<std::string>(), vertices);
      if (!weights.ok()) return failed(weights.error);
      simplify.protect_weights = std::move(weights.weights);
    }
    nlohmann::json result = nlohmann::json::object();
    std::vector<std::string> written_files;
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
      result["input_tri_equivalent"] = files.report["input_tri_equivalent"];
      result["levels"] = nlohmann::json::array();
      for (const auto& level : files.report["levels"]) {
        nlohmann::json l = level;
        l.erase("meshes");
        if (l.contains("file") && l["file"].is_string()) written_files.push_back(l["file"].get<std::string>());
        result["levels"].push_back(std::move(l));
      }
      written_files.push_back("lods.json");  // written last by write_lod_files
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
      result["input_tri_equivalent"] = r.input_tri_equivalent;
      result["target"] = r.target;
      result["achieved"] = r.achieved;
      result["quads"] = r.quads;
      result["triangles"] = r.triangles;
      result["ngons"] = r.ngons;
      result["meshes"] = r.scene.meshes.size();
      written_files.push_back(output_path(job).filename().string());
    }

    // The record, last: the stamps of what was just written, and of the input as it was read.
    // An input changed during the run gets no record: the line says done (this run's outputs
    // are complete) and the next run redoes the job.
    nlohmann::json record = {{"quadlod_batch_record", kRecordVersion},
                             {"options", recorded_options(job.options)},
                             {"input", input_stamp},
                             {"files", nlohmann::json::array()},
                             {"result", result}};
    const fs::path base = files_base(job);
    for (const std::string& name : written_files) {
      nlohmann::json stamp = file_stamp(base / name);
      if (stamp.is_null()) return failed((base / name).string() + ": missing right after it was written");
      stamp["name"] = name;
      record["files"].push_back(std::move(stamp));
    }
    if (!input_stamp.is_null() && file_stamp(job.input) == input_stamp) {
      const WriteResult saved = write_file_atomically(record_path, record.dump() + "\n");
      if (!saved.ok()) return failed(saved.error);
    }
    for (const auto& [key, value] : result.items()) line[key] = value;
    line["status"] = "done";
    line["seconds"] = seconds_since(start);
    return line;
  } catch (const std::exception& e) {
    return failed(job.input.string() + ": internal error: " + e.what());
  }
}

}  // namespace quadlod
