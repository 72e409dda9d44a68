// quadlod — batch runs over many assets (issue 21; docs/batch.md): a folder or a JSON-lines
// manifest becomes a list of jobs, a deterministic shard of it is run, each job is skipped when
// the record of an earlier run still vouches for its outputs (resumable after a kill at any
// moment, issue 36), and each job reports one JSON object.
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
///   "recover_quads": "auto" | "on" | "off" → as the CLI's options of the same names;
///   "protect": FILE (relative to the manifest), "protect_from": "color:r" | … → as the CLI's
///                                     --protect / --protect-from (issue 34, docs/protect.md);
///   "morph_weight": w (issue 34: blend shapes) → as the CLI's --morph-weight.
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

/// Where run_batch_job records a finished job (issue 36): a dot-named JSON file beside the
/// output, `DIR/.NAME.batch.json` for the output `DIR/NAME` (a file, or a LOD chain's directory).
/// Written atomically after every output file, it holds the job's options, the input's size and
/// modification time (ns), the size and modification time of every file the job wrote (a chain:
/// each level and lods.json) and the job's result (its line without status and seconds).
std::filesystem::path batch_record_path(const BatchJob& job);

/// True when the job was done by an earlier run and nothing changed since: its record exists and
/// names the same options (all but "threads", which does not change the output), the input has
/// the recorded size and modification time, and every recorded output file has its recorded size
/// and modification time. So an output without its record (a run killed between the output's
/// rename and the record's), an output replaced or edited afterwards, a LOD chain rewritten in
/// part, an input replaced (even by an older file) or changed options all make it false.
bool batch_output_is_current(const BatchJob& job);

/// Removes the temporary files a killed write left beside the job's outputs (SIGKILL cannot be
/// caught: write_file_atomically leaves `.NAME.tmp-PID-HEX`): those of the output and of the
/// record in the output's directory and, for a LOD chain, every one in the chain's directory.
/// Other jobs' temporaries in a shared directory are left alone. Returns how many were removed.
/// Two runs must not write the same job's output at once (shards are disjoint).
std::size_t remove_batch_temporaries(const BatchJob& job);

struct BatchRunParams {
  bool force = false;     ///< run even when the output is current
  bool progress = false;  ///< the reductions' progress lines on stderr
};

/// Runs one job and returns its line: {"input", "output", "status": "done" | "skipped" |
/// "failed", "error" (failed), "seconds", and the metrics: input/target/achieved
/// triangle-equivalents, quads, triangles, ngons (a LOD chain: per level)}. Never throws.
/// Resumable after a kill at any moment (issue 36): the job first removes its leftover
/// temporaries; a job whose output is current (batch_output_is_current) is "skipped" and its line
/// carries the recorded metrics, so a resumed run's lines equal an uninterrupted run's but for
/// status and seconds; otherwise the old record is removed before anything is written, the
/// outputs are written (atomically), then the new record, then the line says "done".
nlohmann::json run_batch_job(const BatchJob& job, const BatchRunParams& params);

}  // namespace quadlod
