// `quadlod batch (FOLDER -o OUTDIR | MANIFEST.jsonl) [--ratio R | --faces N | --levels … | --count K]
// [--format EXT] [--shard I/N] [--force]`: many assets, one JSON line each (docs/batch.md).
#include "commands.h"

#include "quadlod/batch.h"

#include <cstdio>
#include <memory>

namespace quadlod::cli {

namespace {

struct BatchCliOptions {
  std::string source, output_dir, format, shard = "0/1";
  double ratio = 0.0;
  std::uint64_t faces = 0;
  std::vector<double> levels;
  int count = 0;
  bool per_mesh = false, force = false, no_features = false;
  std::string objective;
  std::string recover_quads;
  std::string seams;
  double bend_lines_below = -1.0;  // < 0: the manifest's or the default
  std::string protect_from;  // issue 34
  int threads = -1;
  std::string symmetry;  // issue 34
  double morph_weight = -1.0;  // issue 34: blend shapes (< 0 = the default)
};

}  // namespace

Command add_batch(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<BatchCliOptions>();
  CLI::App* sub = app.add_subcommand("batch", "Reduce many assets (a folder or a JSON-lines manifest); one JSON line per asset");
  sub->add_option("SOURCE", opt->source, "A folder of assets, or a manifest (.jsonl: input, output, options per line)")->required();
  sub->add_option("-o,--output", opt->output_dir, "Output folder (folder mode)");
  auto* ratio = sub->add_option("--ratio", opt->ratio, "Default target ratio")->check(CLI::Range(1e-6, 1.0))->group("Default target (one of)");
  auto* faces = sub->add_option("--faces", opt->faces, "Default target triangle-equivalents")->group("Default target (one of)");
  auto* levels = sub->add_option("--levels", opt->levels, "Default: a LOD chain with these ratios")
                     ->delimiter(',')->check(CLI::Range(1e-6, 0.999999))->group("Default target (one of)");
  auto* count = sub->add_option("--count", opt->count, "Default: a LOD chain of this many levels, each half the previous")
                    ->check(CLI::Range(1, 16))->group("Default target (one of)");
  for (CLI::Option* a : {ratio, faces, levels, count})
    for (CLI::Option* b : {ratio, faces, levels, count})
      if (a != b) a->excludes(b);
  sub->add_option("--format", opt->format, "Output format of folder mode / LOD files (default: the input's, else glb)")
      ->check(CLI::IsMember({"glb", "obj", "fbx", "dae", "ply", "off"}));
  sub->add_flag("--per-mesh", opt->per_mesh, "Scenes: the target applies to each mesh");
  sub->add_option("--objective", opt->objective, "shape or paper")->check(CLI::IsMember({"shape", "paper"}));
  sub->add_option("--recover-quads", opt->recover_quads, "All-triangle inputs: join triangle pairs into quads first (auto, on, off; as in simplify)")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  sub->add_option("--seams", opt->seams, "Strict lines below the budget they leave room for: auto or strict (as in simplify)")
      ->check(CLI::IsMember({"auto", "strict"}));
  sub->add_option("--bend-lines-below", opt->bend_lines_below,
                  "Below this fraction of the input, lines may bend when a pass stalls (as in simplify)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--threads", opt->threads, "Threads per asset (0 = all cores)")->check(CLI::Range(0, 256));
  // --- symmetry (issue 34; docs/symmetry.md) ---
  sub->add_option("--symmetry", opt->symmetry, "Mirror-symmetric reduction: auto, x, y, z or off (as in simplify)")
      ->check(CLI::IsMember({"auto", "x", "y", "z", "off"}));
  sub->add_flag("--no-features", opt->no_features, "Do not protect UV seams, material borders, boundaries, hard edges");
  sub->add_option("--protect-from", opt->protect_from,
                  "Protect weights from a vertex colour channel (as in simplify; a manifest line's \"protect\": FILE names a weight file)")
      ->check(CLI::IsMember({"none", "color:r", "color:g", "color:b"}));  // issue 34
  sub->add_option("--morph-weight", opt->morph_weight, "Blend shapes: weight of each shape's geometry in the error, against the base's 1 (0 = the base alone; docs/blend_shapes.md)")
      ->check(CLI::Range(0.0, 100.0));
  sub->add_option("--shard", opt->shard,
                  "Run shard I of N (0 <= I < N): asset i belongs to shard i mod N, e.g. "
                  "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT or $JOB_COMPLETION_INDEX/N")
      ->capture_default_str();
  sub->add_flag("--force", opt->force, "Redo assets whose outputs are current (recorded by an earlier run, input and options unchanged)");
  return {sub, [opt, ratio, faces, levels, count, &global]() -> int {
            unsigned shard = 0, shards = 1;
            if (!parse_shard(opt->shard, shard, shards)) {
              std::fprintf(stderr, "quadlod batch: --shard wants I/N with 0 <= I < N, got '%s'\n", opt->shard.c_str());
              return kExitUsage;
            }
            nlohmann::json defaults = nlohmann::json::object();
            if (ratio->count()) defaults["ratio"] = opt->ratio;
            if (faces->count()) defaults["faces"] = opt->faces;
            if (levels->count()) defaults["levels"] = opt->levels;
            if (count->count()) defaults["count"] = opt->count;
            if (opt->per_mesh) defaults["per_mesh"] = true;
            if (!opt->objective.empty()) defaults["objective"] = opt->objective;
            if (!opt->recover_quads.empty()) defaults["recover_quads"] = opt->recover_quads;
            if (!opt->seams.empty()) defaults["seams"] = opt->seams;
            if (opt->bend_lines_below >= 0.0) defaults["bend_lines_below"] = opt->bend_lines_below;
            if (opt->threads >= 0) defaults["threads"] = opt->threads;
            if (opt->no_features) defaults["features"] = false;
            if (!opt->protect_from.empty()) defaults["protect_from"] = opt->protect_from;  // issue 34
            if (!opt->symmetry.empty()) defaults["symmetry"] = opt->symmetry;
            if (opt->morph_weight >= 0.0) defaults["morph_weight"] = opt->morph_weight;  // issue 34
            const bool folder = std::filesystem::is_directory(opt->source);
            if (folder && opt->output_dir.empty()) {
              std::fprintf(stderr, "quadlod batch: folder mode needs -o OUTDIR\n");
              return kExitUsage;
            }
            if (folder && defaults.size() == 0) {
              std::fprintf(stderr, "quadlod batch: give a target: --ratio, --faces, --levels or --count\n");
              return kExitUsage;
            }
            if (!opt->format.empty() && !folder) defaults["format"] = opt->format;
            const BatchPlan plan = folder ? plan_batch_folder(opt->source, opt->output_dir, opt->format, defaults)
                                          : plan_batch_manifest(opt->source, defaults);
            if (!plan.ok()) return fail(plan.error);
            BatchRunParams params;
            params.force = opt->force;
            params.progress = false;
            (void)global;
            std::size_t failures = 0, done = 0, skipped = 0;
            const std::vector<BatchJob> jobs = shard_jobs(plan.jobs, shard, shards);
            for (const BatchJob& job : jobs) {
              const nlohmann::json line = run_batch_job(job, params);
              const std::string status = line["status"].get<std::string>();
              failures += status == "failed";
              done += status == "done";
              skipped += status == "skipped";
              std::printf("%s\n", line.dump().c_str());
              std::fflush(stdout);
            }
            if (!global.quiet)
              std::fprintf(stderr, "batch: shard %u/%u, %zu of %zu assets: %zu done, %zu skipped, %zu failed\n", shard,
                           shards, jobs.size(), plan.jobs.size(), done, skipped, failures);
            return failures > 0 ? kExitBadInput : kExitOk;
          }};
}

}  // namespace quadlod::cli
