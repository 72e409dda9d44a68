// `quadlod simplify INPUT -o OUTPUT (--ratio R | --faces N) ...`: the whole pipeline.
#include "commands.h"
#include "symmetry_cli.h"

#include "quadlod/io.h"
#include "quadlod/scene.h"
#include "skin_cli.h"
#include "protect_cli.h"
#include "quadlod/simplify.h"
#include "util/progress.h"
#ifdef QUADLOD_HTML_REPORT
#include "report_html.h"
#endif

#include <cstdio>
#include <memory>

namespace quadlod::cli {

namespace {

struct SimplifyCliOptions {
  std::string input, output, report, report_html;
  double ratio = 0.0;
  std::uint64_t faces = 0;
  SimplifyOptions pipeline;
  std::string formulation = "fast";
  bool no_consistency = false, no_segmentation = false, no_geometry = false, no_dual = false;
  bool no_features = false, no_greedy_fallback = false, decide_on_doubles = false;
  bool per_mesh = false;
  std::string rig, glb;  // issue 24: skinned input / skinned .glb output
  std::string skin_border_bones = "any";
  // Issue 24: poses the quadrics are measured in besides the bind pose (docs/skinning.md,
  // "Poses": 16 meets Fig. 10's bar at 0.2 and 0.4 from the walk's frames; 4 does not at 0.2).
  SkinPoseChoice poses;
  std::uint64_t max_memory = 0;  ///< bytes; 0 = no bound
  std::string protect_file;  ///< issue 34: --protect FILE
};

std::string format_bytes(std::uint64_t bytes) {
  char buf[64];
  if (bytes >= (std::uint64_t{1} << 30)) std::snprintf(buf, sizeof buf, "%.2f GiB", double(bytes) / double(1 << 30));
  else std::snprintf(buf, sizeof buf, "%.0f MiB", double(bytes) / double(1 << 20));
  return buf;
}

}  // namespace

Command add_simplify(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<SimplifyCliOptions>();
  CLI::App* sub = app.add_subcommand("simplify", "Reduce a quad-dominant mesh, keeping its edge loops");
  sub->add_option("INPUT", opt->input, "Input mesh (.obj, .ply, .off) or scene (.fbx, .glb, .gltf, .dae, .3ds, ...)")->required();
  sub->add_option("-o,--output", opt->output, "Output mesh (.obj, .ply, .off) or scene (.glb, .fbx, .dae)")->required();
  auto* ratio = sub->add_option("--ratio", opt->ratio, "Target as a fraction of the input's triangle-equivalents")
                    ->check(CLI::Range(1e-6, 1.0))
                    ->group("Target (one of)");
  auto* faces = sub->add_option("--faces", opt->faces, "Target triangle-equivalents (quad = 2, k-gon = k-2)")
                    ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 40))
                    ->group("Target (one of)");
  ratio->excludes(faces);
  faces->excludes(ratio);
  sub->add_flag("--per-mesh", opt->per_mesh,
                "Scenes: the target applies to each mesh (default: the scene's target, split by triangle-equivalents)")
      ->group("Target (one of)");
  SimplifyOptions& p = opt->pipeline;
  add_choice_option(sub, "--objective", p.objective, objective_names(),
                    "shape (the geometric error of the output, deterministic greedy) or paper (Eq. 9 with the MIP search)")
      ->group("Objective");
  sub->add_option("--lambda-shape", p.lambda_shape, "Weight of the quad-shape term of the shape objective (0 = error only)")
      ->check(CLI::Range(0.0, 1e6))->default_str(std::to_string(default_lambda_shape()))->group("Objective");
  sub->add_option("--triangle-collapse-factor", p.triangle_collapse_factor,
                  "Single edge collapses (they make triangles) compete at this multiple of their error (0 = none)")
      ->check(CLI::Range(0.0, 1e6))->default_str("3 at ratio <= 0.4 to 6 at >= 0.6")->group("Objective");
  sub->add_option("--max-triangle-share", p.max_triangle_share,
                  "Largest share of the reduction that single collapses may make")
      ->check(CLI::Range(0.0, 1.0))->default_str(std::to_string(default_max_triangle_share()))->group("Objective");
  sub->add_option("--triangle-penalty", p.triangle_penalty,
                  "Shape greedy: handicap of a segment collapse per triangle it leaves at its ends, relative to the quads it removes")
      ->check(CLI::Range(0.0, 1e6))->default_str("0 at ratio <= 0.4 to 1 at >= 0.6")->group("Objective");
  sub->add_option("--swap-rounds", p.swap_rounds,
                  "Exchange rounds after the shape greedy: undo a collapsed move, take a cheaper one (0 = greedy alone)")
      ->check(CLI::Range(0, 64))->default_str(std::to_string(default_swap_rounds()))->group("Objective");
  sub->add_option("--shape-flip-angle", p.shape_flip_angle_deg,
                  "Shape greedy: skip moves that flip a face by more than this angle, degrees (0 = off)")
      ->check(CLI::Range(0.0, 180.0))->capture_default_str()->group("Objective");
  sub->add_option("--effort", p.effort,
                  "Work to spend (1 = default): shape plans effort x the passes (same output on any machine); paper scales its MIP budget")
      ->check(CLI::Range(0.05, 20.0))->capture_default_str()->group("Solver");
  auto* time_limit = sub->add_option("--time-limit", p.time_limit_seconds,
                  "paper: MIP time budget in seconds (0 = greedy selection only); shape: an upper bound on the run (none unless given)")
      ->check(CLI::Range(0.0, 86400.0))->capture_default_str()->group("Solver");
  sub->add_option("--threads", p.threads,
                  "Threads (0 = all cores): speed only for shape; CBC's tree search and the annealing runs for paper")
      ->check(CLI::Range(0, 256))->capture_default_str()->group("Solver");
  sub->add_option("--seed", p.seed, "Solver seed")->capture_default_str()->group("Solver");
  sub->add_option("--formulation", opt->formulation, "fast, or exact (the paper's model as written)")
      ->check(CLI::IsMember({"fast", "exact"}))->capture_default_str()->group("Solver");
  add_choice_option(sub, "--strategy", p.strategy, selection_strategy_names(),
                    "auto, whole (one MIP) or neighbourhoods (large-neighbourhood search); fast formulation only")
      ->group("Solver");
  sub->add_option("--neighbourhood-groups", p.neighbourhood_groups,
                  "Groups freed per neighbourhood MIP (strategy neighbourhoods)")
      ->check(CLI::Range(1, 1000000))->capture_default_str()->group("Solver");
  sub->add_option("--stall-seconds", p.stall_seconds,
                  "Stop a whole-model MIP after this many seconds without a better selection (0 = never)")
      ->check(CLI::Range(0.0, 86400.0))->default_str(std::to_string(default_stall_seconds()))->group("Solver");
  sub->add_option("--epsilon-n", p.epsilon_n, "Eq. 2 slack on the target")
      ->check(CLI::Range(0.0, 0.5))->capture_default_str()->group("Paper parameters");
  sub->add_option("--epsilon-theta", p.epsilon_theta_deg, "Segmentation breakpoint angle, degrees (§3.2.2)")
      ->check(CLI::Range(1.0, 180.0))->capture_default_str()->group("Paper parameters");
  sub->add_option("--lambda-geo", p.lambda_geo, "Eq. 9 weight of collapsed geometric clusters")
      ->check(CLI::Range(0.0, 1e6))->default_str(std::to_string(default_lambda_geo()))->group("Paper parameters");
  sub->add_option("--lambda-edge", p.lambda_edge, "Eq. 9 weight of edge importance")
      ->check(CLI::Range(0.0, 1e6))->default_str(std::to_string(default_lambda_edge()))->group("Paper parameters");
  sub->add_option("--lambda-tri", p.lambda_tri,
                  "Cost of a quad turned into a triangle (beyond the paper; 0 = the paper's Eq. 9)")
      ->check(CLI::Range(0.0, 1e6))->default_str(std::to_string(default_lambda_tri()))->group("Paper parameters");
  sub->add_option("--max-hausdorff", p.max_hausdorff, "Bound on moved vertices' distance, relative to the bbox diagonal (0 = off)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str()->group("Guarantees");
  sub->add_option("--max-rounds", p.max_rounds,
                  "Selection/collapse rounds: later rounds pin refused collapses and re-aim at the target")
      ->check(CLI::Range(1, 64))->capture_default_str()->group("Guarantees");
  sub->add_option("--pass-ratio", p.pass_ratio,
                  "Split reductions below this ratio into passes of equal ratio, each at most this")
      ->check(CLI::Range(0.05, 0.95))
      ->default_str(std::to_string(default_pass_ratio(SimplifyOptions::Objective::Shape)) + " (shape), " +
                    std::to_string(default_pass_ratio(SimplifyOptions::Objective::Paper)) + " (paper)")
      ->group("Guarantees");
  sub->add_option("--max-passes", p.max_passes, "Most passes (1 = one global selection, as in the paper)")
      ->check(CLI::Range(1, 64))
      ->default_str(std::to_string(default_max_passes(SimplifyOptions::Objective::Shape)) + " (shape), " +
                    std::to_string(default_max_passes(SimplifyOptions::Objective::Paper)) + " (paper)")
      ->group("Guarantees");
  sub->add_flag("--no-greedy-fallback", opt->no_greedy_fallback,
                "Keep the optimised selection's output even when a greedy selection's run gets closer to the target")
      ->group("Guarantees");
  sub->add_flag("--decide-on-doubles", opt->decide_on_doubles,
                "Decide on the coordinates as read, not rounded to float32 (then an OBJ and its FBX may reduce differently)")
      ->group("Guarantees");
  sub->add_flag("--no-features", opt->no_features,
                "Do not protect UV seams, material borders, boundaries and hard edges; keep each corner's input UV")
      ->group("Features");
  add_choice_option(sub, "--seams", p.seams, seam_policy_names(),
                    "Strict lines (UV seams, material borders, boundaries) below the budget they leave room for: auto (the "
                    "lines around the smallest islands may merge through them when a pass stalls, counted in the report), "
                    "strict (never; the note says how far from the target that stopped)")
      ->group("Features");
  sub->add_option("--bend-lines-below", p.bend_lines_below_ratio,
                  "With --seams auto, below this fraction of the input the lines may also bend when a pass stalls: fewer, "
                  "longer edges cut their curves, counted as seams torn (0 = never)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str()->group("Features");
  sub->add_option("--max-line-tolerance", p.max_line_tolerance,
                  "How far a bent line may leave its input line, in output edge lengths (0.2 = not at all)")
      ->check(CLI::Range(0.2, 10.0))->capture_default_str()->group("Features");
  sub->add_flag("--place-on-hard-edges", p.place_on_hard_edges,
                "Keep merged vertices on hard edges (else they follow their quadric, which weighs sharp edges heavily)")
      ->group("Features");
  sub->add_option("--surface-fit", p.surface_fit_iterations,
                  "Steps of the final fit of the output's vertices to the input surface (lower Chamfer; 0 = keep the collapse's placements)")
      ->check(CLI::Range(0, 100))->capture_default_str()->group("Features");
  add_choice_option(sub, "--recover-quads", p.recover_quads, quad_recovery_names(),
                    "Join triangle pairs back into quads before the reduction: auto (when every face is a triangle, as in glTF), on, off")
      ->group("Features");
  sub->add_option("--surface-fit-vertex-weight", p.surface_fit_vertex_weight,
                  "Weight of peak vertices (farther from the input than their faces' samples) in the fit: lower Hausdorff, higher Chamfer (0.25 measured; 0 = off)")
      ->check(CLI::Range(0.0, 100.0))->capture_default_str()->group("Features");
  sub->add_option("--hard-angle", p.hard_angle_deg, "Dihedral angle (degrees) from which an edge is a hard edge")
      ->check(CLI::Range(0.0, 180.0))->capture_default_str()->group("Features");
  sub->add_flag("--no-consistency", opt->no_consistency, "Ablation: drop Eq. 4")->group("Ablations");
  sub->add_flag("--no-segmentation", opt->no_segmentation, "Ablation: whole poly-chords (§3.2.2 off)")->group("Ablations");
  sub->add_flag("--no-geometry", opt->no_geometry, "Ablation: drop Eqs. 6-8")->group("Ablations");
  sub->add_flag("--no-dual", opt->no_dual, "Ablation: skip the dual-graph repair (§3.3.1)")->group("Ablations");
  sub->add_option("--rig", opt->rig,
                  "Skinned glTF whose skeleton and animations drive the mesh; an INPUT without weights takes "
                  "them from its mesh by projection (docs/skinning.md)");
  sub->add_option("--glb", opt->glb, "Also write the LOD as a skinned .glb with the rig's skeleton and animations");
  sub->add_option("--skin-border", p.skin_border_distance,
                  "Keep edges whose endpoints' weights differ by more than this and follow unrelated bones (> 1 = off)")
      ->check(CLI::Range(0.0, 2.0))
      ->capture_default_str();
  sub->add_option("--skin-poses", opt->poses.count,
                  "Measure the reduction's error in this many poses of the rig besides the bind "
                  "pose (deformation-sensitive quadrics, docs/skinning.md); 0 = the bind pose only")
      ->capture_default_str();
  sub->add_option("--skin-pose-source", opt->poses.source,
                  "Where --skin-poses come from: frames of the rig's animations, range-of-motion poses that "
                  "turn every joint by --skin-pose-angle about evenly spread axes, or auto (the animations "
                  "when the rig has any, else range)")
      ->check(CLI::IsMember({"auto", "animation", "range"}))
      ->capture_default_str();
  sub->add_option("--skin-pose-angle", opt->poses.angle_deg, "Joint turn of the range-of-motion poses (degrees)")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  sub->add_option("--skin-border-bones", opt->skin_border_bones,
                  "Which bones --skin-border separates: any two dominant joints, or unrelated ones only (parent and child may merge)")
      ->check(CLI::IsMember({"any", "unrelated"}))
      ->capture_default_str();
  // --- blend shapes (issue 34) ---
  sub->add_option("--morph-weight", p.morph_error_weight,
                  "Blend shapes: weight of each shape's geometry in the error, against the base's 1 (0 = the base alone; docs/blend_shapes.md)")
      ->check(CLI::Range(0.0, 100.0))->capture_default_str();
  sub->add_option("--max-memory", opt->max_memory,
                  "Refuse (exit 2) an input whose estimated peak memory exceeds this (e.g. 2GiB, 512MB; 0 = no bound)")
      ->transform(CLI::AsSizeValue(false))->group("Guarantees");
  // --- symmetry (issue 34; docs/symmetry.md) ---
  add_choice_option(sub, "--symmetry", p.symmetry, symmetry_names(),
                    "Mirror-symmetric reduction about a bbox-centred axis plane: auto (the plane the input is symmetric "
                    "about, if any), x, y, z, or off; an input not symmetric within the tolerance gets a note and is "
                    "reduced without symmetry")
      ->group("Features");
  sub->add_option("--symmetry-tolerance", p.symmetry_tolerance,
                  "Largest distance of a vertex's mirror partner from its reflection, relative to the bbox diagonal")
      ->check(CLI::Range(1e-9, 0.1))->capture_default_str()->group("Features");
  sub->add_option("--report", opt->report, "Write a JSON report (per-stage times, solver statistics)");
  add_protect_options(sub, opt->protect_file, p);  // issue 34
#ifdef QUADLOD_HTML_REPORT
  sub->add_option("--report-html", opt->report_html,
                  "Write the visual report of this run (as `quadlod report INPUT OUTPUT`)");
#endif
  return {sub, [opt, ratio, faces, time_limit, &global]() -> int {
            if (ratio->count() == 0 && faces->count() == 0) {
              std::fprintf(stderr, "quadlod simplify: give a target: --ratio R or --faces N\n");
              return kExitUsage;
            }
            // The shape objective has no time budget: a given --time-limit bounds its run.
            if (time_limit->count() > 0 && opt->pipeline.objective == SimplifyOptions::Objective::Shape)
              opt->pipeline.time_bound_seconds = opt->pipeline.time_limit_seconds;
            for (const std::string& out : {opt->output, opt->report, opt->report_html})
              if (!out.empty() && same_file(opt->input, out))
                return fail(out + ": refusing to overwrite the input");
            if (!opt->report.empty() && same_file(opt->output, opt->report))
              return fail(opt->report + ": the report and the output are the same file");
            if (!opt->report_html.empty() &&
                (same_file(opt->output, opt->report_html) || (!opt->report.empty() && same_file(opt->report, opt->report_html))))
              return fail(opt->report_html + ": the HTML report and another output are the same file");
            for (const std::string& out : {opt->glb})
              if (!out.empty() && (same_file(opt->input, out) || same_file(opt->rig, out)))
                return fail(out + ": refusing to overwrite an input");
            if (MeshFormat native; opt->max_memory > 0 && format_from_path(opt->input, native)) {
              // Before anything is allocated for the input (issue 23): counts from the header or
              // one streaming pass, against the measured cost per triangle-equivalent.
              const InputSizeEstimate size = estimate_input_size(opt->input);
              if (!size.error.empty()) return fail(size.error);
              const std::uint64_t need = estimate_simplify_peak_bytes(size);
              if (need > opt->max_memory)
                return fail(opt->input + ": simplify would need about " + format_bytes(need) + " (" +
                            std::to_string(size.faces) + " faces, " + std::to_string(size.corners) +
                            " corners claimed), more than --max-memory " + format_bytes(opt->max_memory));
            }
            SimplifyOptions p = opt->pipeline;
            p.ratio = opt->ratio > 0 ? opt->ratio : 1.0;
            p.target_tri_equivalent = opt->faces;
            p.exact_formulation = opt->formulation == "exact";
            p.consistency = !opt->no_consistency;
            p.segmentation = !opt->no_segmentation;
            p.geometry = !opt->no_geometry;
            p.dual_repair = !opt->no_dual;
            p.greedy_fallback = !opt->no_greedy_fallback;
            p.float32_decisions = !opt->decide_on_doubles;
            p.features = !opt->no_features;
            p.progress = !global.quiet;
            // Skinned meshes (issue 24) take their own path: --rig / --glb, or a skinned glTF input
            // (its skin, skeleton and animations carried through; a .glb output is written skinned).
            Stopwatch clock;
            SkinnedInput in;
            bool skinned = !opt->rig.empty() || !opt->glb.empty();
            MeshFormat native_in;
            if (!skinned && is_gltf_path(opt->input)) {
              // A glTF of several meshes takes the scene path below, which writes a .glb with
              // every mesh's skin (docs/skinning.md, "Scenes").
              in = read_skinned_input(opt->input, "");
              skinned = in.error.empty() && in.file_meshes == 1;
            } else if (!skinned && is_gltf_path(opt->output) && !format_from_path(opt->input, native_in) &&
                       scene_readable_path(opt->input)) {
              // A skinned FBX / Collada of one mesh to .glb: its skin, skeleton and animations
              // through assimp (docs/skinning.md); other scenes take the scene path below.
              in = read_skinned_input(opt->input, "");
              skinned = in.error.empty() && in.file_meshes == 1 && !in.mesh.skin.empty() && !in.rig.empty();
            } else if (skinned) {
              in = read_skinned_input(opt->input, opt->rig);
              if (!in.error.empty()) return fail(in.error);
            }
            MeshFormat format, input_format;
            const bool native_out = format_from_path(opt->output, format);
            const bool glb_out = skinned && is_gltf_path(opt->output);
            // Scenes (FBX, glTF, Collada, … on either side) go mesh by mesh (cmd_scene.cpp).
            if (!skinned && (!native_out || !format_from_path(opt->input, input_format))) {
              if (!opt->report_html.empty())
                return fail(opt->report_html + ": --report-html takes an OBJ, PLY or OFF input and output (use `quadlod report` on the meshes)");
              return simplify_scene_file(opt->input, opt->output, opt->report, p, opt->per_mesh, opt->poses,
                                         opt->protect_file);
            }
            if (skinned && !native_out && !glb_out)
              return fail(opt->output + ": a skinned mesh is written as .glb (or .obj / .ply / .off without its skin)");
            if ((!opt->glb.empty() || glb_out) && (in.rig.empty() || in.mesh.skin.empty()))
              return fail(opt->input + ": a skinned .glb output needs a skinned input (a skinned glTF, or --rig)");
            if (!skinned) {
              ReadResult plain = read_mesh(opt->input);
              if (!plain.ok()) return fail(plain.error);
              in.mesh = std::move(plain.mesh);
            }
            if (opt->skin_border_bones == "unrelated")
              for (const Joint& j : in.rig.skeleton.joints) p.skin_joint_parents.push_back(j.parent);
            if (!in.mesh.skin.empty())
              p.skin_poses = chosen_poses(in.rig, opt->poses);
            if (std::string bad = load_protect_file(opt->protect_file, p, in.mesh.num_vertices()); !bad.empty())
              return fail(bad);
            const double read_seconds = clock.seconds();
            SimplifyResult r = simplify_in_place(in.mesh, p);  // the input is ours: no copy of it
            if (!r.ok()) return fail(opt->input + ": " + r.error);
            // The output may live elsewhere: keep its `mtllib` lines pointing at the input's MTL.
            for (const std::string& w : rebase_material_libraries(r.mesh, opt->input, opt->output))
              std::fprintf(stderr, "warning: %s\n", w.c_str());
            clock = Stopwatch();
            const WriteResult written = glb_out ? write_skinned_glb(r.mesh, in.rig, opt->output, in.material_colors)
                                                : write_mesh(r.mesh, opt->output);
            if (!written.ok()) return fail(written.error);
            for (const std::string& w : written.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
            if (!opt->glb.empty()) {
              const WriteResult glb = write_skinned_glb(r.mesh, in.rig, opt->glb, in.material_colors);
              if (!glb.ok()) return fail(glb.error);
              r.report["glb"] = opt->glb;
            }
            const double write_seconds = clock.seconds();
            r.report["input"] = opt->input;
            r.report["output"] = opt->output;
            r.report["read_seconds"] = read_seconds;
            r.report["write_seconds"] = write_seconds;
            if (!opt->report.empty()) {
              const WriteResult rep = write_file_atomically(opt->report, r.report.dump(2) + "\n");
              if (!rep.ok()) return fail(rep.error);
            }
#ifdef QUADLOD_HTML_REPORT
            if (!opt->report_html.empty()) {
              HtmlReportParams html;
              html.title = "quadlod simplify: " + file_label(opt->input) + " → " + file_label(opt->output);
              html.progress = !global.quiet;
              if (int code = write_html_report(opt->report_html, {file_label(opt->input), &in.mesh},
                                               {{file_label(opt->output), &r.mesh}}, html);
                  code != kExitOk)
                return code;
            }
#endif
            const auto& rep = r.report;
            std::printf(
                "simplify: target %llu, achieved %llu (%+.1f%%), %u quads, %u tris, %u n-gons; "
                "analysis %.2f s, select %.2f s, dual %.2f s, collapse %.2f s (%d pass%s, %zu rounds in the last), "
                "fit %.2f s, total %.2f s\n",
                static_cast<unsigned long long>(r.target), static_cast<unsigned long long>(r.achieved),
                100.0 * rep["deviation"].get<double>(), r.quads, r.triangles, r.ngons,
                rep["stage_seconds"]["analysis"].get<double>(), rep["stage_seconds"]["select"].get<double>(),
                rep["stage_seconds"]["dual"].get<double>(), rep["stage_seconds"]["collapse"].get<double>(),
                r.passes_used, r.passes_used == 1 ? "" : "es", rep["rounds"].size(),
                rep["stage_seconds"].value("fit", 0.0), read_seconds + rep["seconds"].get<double>() + write_seconds);
            if (rep.contains("quad_recovery"))
              std::printf("quads: the input is all triangles; %llu pairs were joined into quads first (--recover-quads off keeps them)\n",
                          static_cast<unsigned long long>(rep["quad_recovery"]["quads_made"].get<std::uint64_t>()));
            if (rep.contains("seams") && rep["seams"]["line_crossings"].get<std::uint64_t>() > 0) {
              const auto& seams = rep["seams"];
              const double faces = seams["crossing_island_area"].get<double>() / seams["one_output_face_area"].get<double>();
              std::printf("seams: %llu line crossings through UV islands of up to %.0f output faces%s (--seams strict keeps every line)\n",
                          static_cast<unsigned long long>(seams["line_crossings"].get<std::uint64_t>()), faces,
                          seams["vanishing_part_area"].get<double>() > 0.0 ? "; parts that small may vanish" : "");
            }
            if (rep.contains("seams") && rep["seams"].value("line_tolerance", 0.2) > 0.2 + 1e-9)
              std::printf("seams: lines bent up to %.1f output edge lengths off their input lines to reach the budget; "
                          "eval counts those edges as seams torn (--bend-lines-below 0 keeps them)\n",
                          rep["seams"]["line_tolerance"].get<double>());
            print_symmetry_line(rep);
            if (!r.note.empty()) std::printf("note: %s\n", r.note.c_str());
            return kExitOk;
          }};
}

}  // namespace quadlod::cli
