// quadlod — batch runs over many assets (issue 21; docs/batch.md): a folder or a JSON-lines
// manifest becomes a list of jobs, a deterministic shard of it is run, each job is skipped when
// its output is newer than its input (resumable), and each job reports one JSON object.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace quadlod {

/// One asset. `options` (JSON object) says what to do with it:
///   "ratio": R | "faces": N        → simplify (simplify_scene) to `output`, a file;
///   "levels": [r1, r2, …] | "count": K → a LOD chain (lod_chain_scene) into `output`, a
///                                     directory (files <stem>.lodI.<format> + lods.json);
///   "format": "glb" | "fbx" | …      → lod: file format (default: the input's, else glb);
///   "per_mesh": bool, "objective": "shape" | "paper", "time_limit": s, "threads": n,
///   "seed": n, "features": bool,
///   "recover_quads": "auto" | "on" | "off" → as the CLI's options of the same names.
/// Unknown keys are an error of that job (a typo must not silently change the run).
struct BatchJob {
  std::filesystem::path input;
  std::filesystem::path output;
  nlohmann::json options = nlohmann::json::object();
};

struct BatchPlan {
  std::vector<BatchJob> jobs;
  std::string error;  ///< the folder / manifest could not be read (one line naming it)
  bool ok() const { return error.empty(); }
};

/// Every file in `folder` (not recursive) that read_scene can read, sorted by name. Outputs go
/// to `output_dir`: `<stem><ext>` for a reduction (ext = `extension` if non-empty, else
/// default_output_extension of the input), `<stem>/` for a LOD chain. `options` is every job's.
BatchPlan plan_batch_folder(const std::filesystem::path& folder, const std::filesystem::path& output_dir,
                            const std::string& extension, const nlohmann::json& options);

/// One job per non-empty line of a JSON-lines manifest: {"input": …, "output": …, "options":
/// {…}} (or the option keys at the top level). Relative paths are relative to the manifest's
/// directory; a line's options override `defaults`. A malformed line is an error naming the
/// manifest and the line.
BatchPlan plan_batch_manifest(const std::filesystem::path& manifest, const nlohmann::json& defaults);

/// The jobs of shard `index` of `count`: job i belongs to shard i mod count. Shards are disjoint
/// and cover the plan whatever the order they run in (Slurm job arrays, Kubernetes indexed Jobs).
std::vector<BatchJob> shard_jobs(const std::vector<BatchJob>& jobs, unsigned index, unsigned count);

/// Parses "I/N" (0 <= I < N); false when malformed.
bool parse_shard(const std::string& text, unsigned& index, unsigned& count);

/// True when the job's output (a LOD chain: its lods.json, written last) exists and is not older
/// than its input: the job was done by an earlier run.
bool batch_output_is_current(const BatchJob& job);

struct BatchRunParams {
  bool force = false;     ///< run even when the output is current
  bool progress = false;  ///< the reductions' progress lines on stderr
};

/// Runs one job and returns its line: {"input", "output", "status": "done" | "skipped" |
/// "failed", "error" (failed), "seconds", and the metrics: input/target/achieved
/// triangle-equivalents, quads, triangles, ngons (a LOD chain: per level)}. Never throws.
nlohmann::json run_batch_job(const BatchJob& job, const BatchRunParams& params);

}  // namespace quadlod
