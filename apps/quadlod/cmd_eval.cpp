// `quadlod eval INPUT OUTPUT [--json] [--samples N] [--seed S]`: the §4.1 metrics of OUTPUT
// against INPUT, the feature / UV / material metrics (§6c), plus the output's validity counts
// (docs/metrics.md).
#include "commands.h"

#include "mesh/connectivity.h"
#include "mesh/validation.h"
#include "quadlod/animation_metrics.h"
#include "quadlod/io.h"
#include "skin_cli.h"
#include "symmetry_cli.h"
#include "quadlod/metrics.h"
#include "util/progress.h"

#include <cmath>
#include <cstdio>
#include <memory>

namespace quadlod::cli {

namespace {

struct EvalOptions {
  std::string input, output;
  bool json = false;
  std::uint64_t samples = EvalParams{}.samples;
  std::uint64_t seed = EvalParams{}.seed;
  double feature_tolerance = EvalParams{}.feature_tolerance;
  unsigned threads = 0;
  // issue 24: metrics under animation
  bool animation = false;
  std::string rig;
  Index animation_index = 0;
  Index frame_step = 1;
  bool samples_given = false;
  double hausdorff_tolerance = -1.0;  // < 0: the default (sampled; 1e-5 with --animation)
};

// `eval --animation`: both meshes posed by the same skeleton at every frame (docs/metrics.md §7).
int run_animation_eval(const EvalOptions& opt, bool quiet) {
  Stopwatch clock;
  SkinnedInput in = read_skinned_input(opt.input, opt.rig);
  if (!in.error.empty()) return fail(in.error);
  if (in.rig.empty() || in.mesh.skin.empty())
    return fail(opt.input + ": --animation needs a skinned input (a skinned glTF, or --rig FILE)");
  // OUTPUT's own weights when it is skinned (glTF, FBX, …; joints matched by name), else by the
  // same projection onto INPUT that quadlod's reduction uses.
  SkinnedInput out = read_skinned_input(opt.output, "");
  if (!out.error.empty()) return fail(out.error);
  PolyMesh output = std::move(out.mesh);
  std::string weights_from;
  if (!output.skin.empty() && !out.rig.empty()) {
    if (std::string e = remap_joints(output, out.rig.skeleton, in.rig.skeleton); !e.empty()) return fail(opt.output + ": " + e);
    weights_from = "its own";
  } else {
    output.skin = transfer_skin_weights(in.mesh, output).skin;
    weights_from = "projection onto the input";
  }
  if (!quiet) std::fprintf(stderr, "eval: read both meshes and the rig in %.2f s\n", clock.seconds());
  AnimationEvalParams params;
  if (opt.samples_given) {
    params.metrics.samples = opt.samples;
    params.metrics.curve_samples = opt.samples;
  }
  params.metrics.seed = opt.seed;
  if (opt.hausdorff_tolerance >= 0.0) params.metrics.hausdorff_tolerance = opt.hausdorff_tolerance;
  params.metrics.threads = opt.threads;
  params.metrics.feature_tolerance = opt.feature_tolerance;
  params.animation = opt.animation_index;
  params.frame_step = opt.frame_step;
  const AnimationEvalResult r = evaluate_animation(in.mesh, output, in.rig, params);
  if (!r.ok()) return fail(opt.output + ": " + r.error);
  if (!quiet) std::fprintf(stderr, "eval: %zu frames in %.2f s\n", r.frames.size(), r.seconds);
  if (opt.json) {
    nlohmann::json j = to_json(r, &in.rig.skeleton);
    j["input"] = opt.input;
    j["hausdorff_tolerance"] = params.metrics.hausdorff_tolerance;
    j["output"] = opt.output;
    j["rig"] = opt.rig;
    j["output_weights"] = weights_from;
    j["input_weights"] = in.projected ? "projection onto the rig's mesh" : "its own";
    j["samples"] = params.metrics.samples;
    j["seed"] = params.metrics.seed;
    std::printf("%s\n", j.dump(2).c_str());
    return kExitOk;
  }
  std::printf("%s vs %s, animation %s (%zu frames; output weights: %s)\n", opt.output.c_str(), opt.input.c_str(),
              r.animation.c_str(), r.frames.size(), weights_from.c_str());
  std::printf("  %8s  %11s  %11s  %11s  %9s\n", "time s", "pccd", "chamfer", "hausdorff", "flow deg");
  for (const AnimationFrame& f : r.frames)
    std::printf("  %8.4f  %11.4e  %11.4e  %11.4e  %9.2f\n", f.time, f.metrics.pccd_defined ? f.metrics.pccd : std::nan(""),
                f.metrics.chamfer, f.metrics.hausdorff, f.metrics.flow_deviation_deg);
  auto line = [&](const char* name, const FrameSummary& s) {
    std::printf("  %-15s median %.4e, worst %.4e (frame %d), mean %.4e\n", name, s.median, s.worst,
                s.worst_frame == kInvalidIndex ? -1 : int(s.worst_frame), s.mean);
  };
  line("pccd", r.pccd);
  line("chamfer", r.chamfer);
  line("hausdorff", r.hausdorff);
  line("flow deviation", r.flow_deviation_deg);
  return kExitOk;
}

}  // namespace

Command add_eval(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<EvalOptions>();
  CLI::App* sub = app.add_subcommand("eval", "Metrics of OUTPUT against INPUT (QPR, PCCD, Chamfer, Hausdorff, flow, seams, UVs, materials)");
  sub->add_option("INPUT", opt->input, "The original mesh")->required();
  sub->add_option("OUTPUT", opt->output, "The reduced mesh")->required();
  sub->add_flag("--json", opt->json, "Print one JSON object instead of text");
  sub->add_option("--samples", opt->samples, "Surface samples per direction")
      ->check(CLI::Range(std::uint64_t{1000}, std::uint64_t{100000000}))
      ->capture_default_str();
  sub->add_option("--seed", opt->seed, "Sampling seed (results are deterministic per seed)")->capture_default_str();
  sub->add_option("--hausdorff-tolerance", opt->hausdorff_tolerance,
                  "Hausdorff by branch and bound, to within this (normalised units; 0 = the maximum over the samples "
                  "and vertices; default 0, 1e-5 with --animation)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--feature-tolerance", opt->feature_tolerance,
                  "Torn seams: allowed distance from the input seam, as a fraction of the output edge's length")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  sub->add_option("--threads", opt->threads, "Worker threads (0 = all cores); results do not depend on it")
      ->capture_default_str();
  sub->add_flag("--animation", opt->animation,
                "Pose INPUT and OUTPUT with the same skeleton at every frame and report the metrics per frame "
                "(INPUT: a skinned glTF or --rig; OUTPUT: a skinned glTF, or any mesh that takes weights by projection)");
  sub->add_option("--rig", opt->rig, "With --animation: skinned glTF whose skeleton, animations and weights drive INPUT");
  sub->add_option("--animation-index", opt->animation_index, "With --animation: which animation of the rig")->capture_default_str();
  sub->add_option("--frame-step", opt->frame_step, "With --animation: every n-th frame")
      ->check(CLI::Range(Index{1}, Index{100000}))
      ->capture_default_str();
  return {sub, [opt, &global, sub]() -> int {
            if (!opt->animation && (!opt->rig.empty()))
              return fail("--rig needs --animation");
            opt->samples_given = sub->count("--samples") > 0;
            if (opt->animation) return run_animation_eval(*opt, global.quiet);
            Stopwatch clock;
            const ReadResult in = read_mesh(opt->input);
            if (!in.ok()) return fail(in.error);
            const ReadResult out = read_mesh(opt->output);
            if (!out.ok()) return fail(out.error);
            if (!global.quiet) std::fprintf(stderr, "eval: read both meshes in %.2f s\n", clock.seconds());
            EvalParams params;
            params.samples = opt->samples;
            params.seed = opt->seed;
            if (opt->hausdorff_tolerance >= 0.0) params.hausdorff_tolerance = opt->hausdorff_tolerance;
            params.threads = opt->threads;
            params.feature_tolerance = opt->feature_tolerance;
            const EvalResult r = evaluate(in.mesh, out.mesh, params);
            if (!r.ok()) return fail(opt->output + ": " + r.error);
            const MeshStats validity = compute_stats(out.mesh, build_connectivity(out.mesh));
            const MeshStats input_validity = compute_stats(in.mesh, build_connectivity(in.mesh));
            if (!global.quiet) std::fprintf(stderr, "eval: metrics in %.2f s\n", r.seconds);
            const nlohmann::json symmetry = symmetry_metric(in.mesh, out.mesh);  // issue 34
            if (opt->json) {
              nlohmann::json j = to_json(r);
              j["input"] = opt->input;
              j["output"] = opt->output;
              j["tri_equivalent_in"] = r.counts_in.tri_equivalent;
              j["tri_equivalent_out"] = r.counts_out.tri_equivalent;
              j["validity"] = validity_json(validity, input_validity);
              j["symmetry"] = symmetry;
              std::printf("%s\n", j.dump(2).c_str());
              return kExitOk;
            }
            auto num = [](double v) { return std::isfinite(v) ? v : std::nan(""); };
            std::printf("%s vs %s\n", opt->output.c_str(), opt->input.c_str());
            std::printf("  tri-equivalents     %llu -> %llu\n",
                        static_cast<unsigned long long>(r.counts_in.tri_equivalent),
                        static_cast<unsigned long long>(r.counts_out.tri_equivalent));
            std::printf("  faces (q/t/n)       %llu/%llu/%llu -> %llu/%llu/%llu\n",
                        (unsigned long long)r.counts_in.quads, (unsigned long long)r.counts_in.tris,
                        (unsigned long long)r.counts_in.ngons, (unsigned long long)r.counts_out.quads,
                        (unsigned long long)r.counts_out.tris, (unsigned long long)r.counts_out.ngons);
            std::printf("  qpr                 %.4f (%s)\n", num(r.qpr), r.qpr_rule.c_str());
            std::printf("  pccd                %.4e%s\n", num(r.pccd), r.pccd_defined ? "" : " (undefined: see docs/metrics.md)");
            std::printf("  chamfer             %.4e (squared %.4e)\n", num(r.chamfer), num(r.chamfer_sq));
            std::printf("  hausdorff           %.4e\n", num(r.hausdorff));
            std::printf("  flow deviation      %.2f deg mean, %.2f deg p90, coverage %.3f\n",
                        num(r.flow_deviation_deg), num(r.flow_deviation_p90_deg), num(r.flow_coverage));
            std::printf("  uv                  islands %llu -> %llu (%llu vanished, %llu merged, %llu split), %llu seams torn, error %.4e mean, %.4e max\n",
                        (unsigned long long)r.uv_islands_in, (unsigned long long)r.uv_islands_out,
                        (unsigned long long)r.uv_islands_vanished, (unsigned long long)r.uv_islands_merged,
                        (unsigned long long)r.uv_islands_split,
                        (unsigned long long)r.seams_torn, num(r.uv_error_mean), num(r.uv_error_max));
            std::printf("  uv stretch          median %.4f -> %.4f, p90 %.4f -> %.4f (L2, 1 = none)\n",
                        num(r.uv_stretch_median_in), num(r.uv_stretch_median_out), num(r.uv_stretch_p90_in),
                        num(r.uv_stretch_p90_out));
            if (std::isnan(r.material_mismatch_fraction))
              std::printf("  materials           none in either mesh\n");
            else
              std::printf("  materials           border error %.4e max, %.4e mean; mismatch %.4f\n",
                          num(r.material_border_error), num(r.material_border_error_mean),
                          num(r.material_mismatch_fraction));
            std::printf("  feature lines       deviation %.4e max, %.4e mean (%llu -> %llu edges)\n",
                        num(r.feature_deviation_max), num(r.feature_deviation_mean),
                        (unsigned long long)r.feature_edges_in, (unsigned long long)r.feature_edges_out);
            std::printf("  output validity     %u non-manifold edges (input %u), %u degenerate, %u duplicate, "
                        "%llu flipped faces (+%llu input faces kept as they were)\n",
                        validity.nonmanifold_edges, input_validity.nonmanifold_edges,
                        validity.degenerate_faces, validity.duplicate_faces,
                        static_cast<unsigned long long>(r.flipped_faces),
                        static_cast<unsigned long long>(r.flipped_faces_kept));
            if (symmetry.contains("output_mirrored_fraction"))
              std::printf("  symmetry            %s plane: %.2f %% of input vertices matched, %.2f %% of output vertices "
                          "mirrored (within %g of the input diagonal)\n",
                          symmetry["axis"].get<std::string>().c_str(), 100.0 * symmetry["input_matched_fraction"].get<double>(),
                          100.0 * symmetry["output_mirrored_fraction"].get<double>(), symmetry["tolerance"].get<double>());
            return kExitOk;
          }};
}

}  // namespace quadlod::cli
