// `quadlod lod INPUT -o DIR [--levels 0.5,0.25,0.125 | --count 4] [--format glb|obj|fbx|dae|ply|off]`:
// a chain of LODs, each reduced from the previous one (include/quadlod/lod.h), one file per
// level plus DIR/lods.json (docs/lod.md).
#include "commands.h"
#include "symmetry_cli.h"

#include "protect_cli.h"
#include "quadlod/lod.h"
#include "quadlod/scene.h"
#include "util/progress.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <set>

namespace quadlod::cli {

namespace {

struct LodCliOptions {
  std::string input, output_dir, format;
  std::vector<double> levels;
  int count = 0;
  LodChainParams chain;
  bool no_features = false, no_hausdorff = false;
  std::string protect_file;  ///< issue 34: --protect FILE
};

}  // namespace

Command add_lod(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<LodCliOptions>();
  CLI::App* sub = app.add_subcommand("lod", "A chain of LODs, each reduced from the previous one, plus lods.json");
  sub->add_option("INPUT", opt->input, "Input mesh or scene (.obj .ply .off .fbx .glb .gltf .dae .3ds ...)")->required();
  sub->add_option("-o,--output", opt->output_dir, "Output directory (created if missing)")->required();
  auto* levels = sub->add_option("--levels", opt->levels, "Level sizes as fractions of the input, decreasing (default 0.5,0.25,0.125)")
                     ->delimiter(',')
                     ->check(CLI::Range(1e-6, 0.999999))
                     ->group("Levels (one of)");
  auto* count = sub->add_option("--count", opt->count, "Number of levels, each half the previous")
                    ->check(CLI::Range(1, 16))
                    ->group("Levels (one of)");
  levels->excludes(count);
  count->excludes(levels);
  sub->add_option("--format", opt->format, "Output format (default: the input's, .glb for formats quadlod does not write)")
      ->check(CLI::IsMember({"glb", "obj", "fbx", "dae", "ply", "off"}));
  SimplifyOptions& p = opt->chain.simplify;
  add_choice_option(sub, "--objective", p.objective, objective_names(), "shape or paper (as in simplify)")->group("Reduction");
  sub->add_option("--time-limit", p.time_limit_seconds, "MIP time budget per level in seconds (objective paper)")
      ->check(CLI::Range(0.0, 86400.0))->capture_default_str()->group("Reduction");
  sub->add_option("--threads", p.threads, "Threads (0 = all cores)")->check(CLI::Range(0, 256))->capture_default_str()->group("Reduction");
  add_choice_option(sub, "--recover-quads", p.recover_quads, quad_recovery_names(),
                    "All-triangle inputs: join triangle pairs into quads first (auto, on, off; as in simplify)")
      ->group("Reduction");
  add_choice_option(sub, "--seams", p.seams, seam_policy_names(),
                    "Strict lines below the budget they leave room for: auto or strict (as in simplify)")
      ->group("Reduction");
  sub->add_option("--bend-lines-below", p.bend_lines_below_ratio,
                  "Levels below this fraction of the input may bend lines (as in simplify; 0 = never)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str()->group("Reduction");
  sub->add_option("--seed", p.seed, "Solver seed")->capture_default_str()->group("Reduction");
  // --- symmetry (issue 34; docs/symmetry.md) ---
  add_choice_option(sub, "--symmetry", p.symmetry, symmetry_names(),
                    "Mirror-symmetric reduction: auto, x, y, z or off (as in simplify; each level about the plane of its input)")
      ->group("Reduction");
  sub->add_flag("--no-features", opt->no_features, "Do not protect UV seams, material borders, boundaries, hard edges")
      ->group("Reduction");
  add_protect_options(sub, opt->protect_file, p);  // issue 34
  // --- blend shapes (issue 34) ---
  sub->add_option("--morph-weight", p.morph_error_weight, "Blend shapes: weight of each shape's geometry in the error, against the base's 1 (0 = the base alone; docs/blend_shapes.md)")
      ->check(CLI::Range(0.0, 100.0))->capture_default_str()->group("Reduction");
  sub->add_flag("--no-hausdorff", opt->no_hausdorff, "Skip the Hausdorff measurement (and the screen sizes)")->group("Measurement");
  sub->add_option("--hausdorff-samples", opt->chain.hausdorff_samples, "Surface samples per direction of the Hausdorff measurement")
      ->check(CLI::Range(std::uint64_t{100}, std::uint64_t{100000000}))->capture_default_str()->group("Measurement");
  sub->add_option("--pixel-tolerance", opt->chain.pixel_tolerance, "Screen-size rule: largest error in pixels")
      ->check(CLI::Range(1e-3, 1e3))->capture_default_str()->group("Measurement");
  sub->add_option("--screen-height", opt->chain.screen_height_pixels, "Screen-size rule: screen height in pixels")
      ->check(CLI::Range(1.0, 1e6))->capture_default_str()->group("Measurement");
  return {sub, [opt, &global]() -> int {
            LodChainParams params = opt->chain;
            params.ratios = opt->count > 0 ? lod_ratios_by_count(opt->count)
                                           : (opt->levels.empty() ? std::vector<double>{0.5, 0.25, 0.125} : opt->levels);
            params.simplify.features = !opt->no_features;
            params.simplify.progress = !global.quiet;
            params.measure_hausdorff = !opt->no_hausdorff;
            for (std::size_t i = 1; i < params.ratios.size(); ++i)
              if (!(params.ratios[i] < params.ratios[i - 1])) {
                std::fprintf(stderr, "quadlod lod: --levels must decrease\n");
                return kExitUsage;
              }
            const std::string ext = "." + (opt->format.empty() ? default_output_extension(opt->input).substr(1) : opt->format);
            const std::filesystem::path dir = opt->output_dir;
            const std::string stem = std::filesystem::path(opt->input).stem().string();
            std::vector<std::filesystem::path> files;
            for (std::size_t l = 0; l < params.ratios.size(); ++l) {
              files.push_back(lod_file_path(dir, stem, l, ext));
              if (same_file(opt->input, files.back())) return fail(files.back().string() + ": refusing to overwrite the input");
            }
            if (same_file(opt->input, dir / "lods.json")) return fail("lods.json: refusing to overwrite the input");

            Stopwatch clock;
            const SceneReadResult in = read_scene(opt->input);
            if (!in.ok()) return fail(in.error);
            if (in.scene.meshes.empty())
              return fail(opt->input + ": the scene has no mesh to reduce (" + std::to_string(in.scene.cameras) +
                          " cameras, " + std::to_string(in.scene.lights) + " lights)");
            std::size_t vertices = 0;
            for (const SceneMesh& m : in.scene.meshes) vertices += m.mesh.num_vertices();
            if (std::string bad = load_protect_file(opt->protect_file, params.simplify, vertices); !bad.empty())
              return fail(bad);
            const double read_seconds = clock.seconds();
            SceneLodResult chain = lod_chain_scene(in.scene, params);
            if (!chain.ok()) return fail(opt->input + ": " + chain.error);
            const nlohmann::json extra = {
                {"input", opt->input},
                {"read_seconds", read_seconds},
                {"screen_size_formula",
                 "screen_size = clamp(pixel_tolerance / (hausdorff_over_diagonal * screen_height_pixels), 0, 1), "
                 "non-increasing along the chain; the smallest over the meshes (docs/lod.md)"}};
            const LodFilesResult written = write_lod_files(chain, opt->input, dir, ext, extra);
            for (const std::string& w : written.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
            if (!written.ok()) return fail(written.error);
            const auto num = [](const nlohmann::json& v) { return v.is_null() ? std::nan("") : v.get<double>(); };
            std::set<std::string> noted;  // meshes whose symmetry note was printed (issue 34)
            for (std::size_t l = 0; l < chain.levels.size(); ++l) {
              const nlohmann::json& level = written.report["levels"][l];
              std::printf("lod%zu: ratio %.4g, target %llu, achieved %llu, %llu quads, %llu tris, %llu n-gons, "
                          "hausdorff %.3g, screen size %.3g, %.2f s -> %s\n",
                          l + 1, level["ratio"].get<double>(), level["target"].get<unsigned long long>(),
                          level["achieved"].get<unsigned long long>(), level["quads"].get<unsigned long long>(),
                          level["triangles"].get<unsigned long long>(), level["ngons"].get<unsigned long long>(),
                          num(level["hausdorff"]), num(level["screen_size"]), level["seconds"].get<double>(),
                          files[l].string().c_str());
              // The plane of each mesh; a note once per mesh (the next level is reduced from this
              // one, and is not symmetric either).
              for (const nlohmann::json& mesh : level["meshes"]) {
                const bool note = mesh.contains("symmetry") && mesh["symmetry"].contains("note");
                if (note && !noted.insert(mesh.value("name", std::string())).second) continue;
                print_symmetry_line(mesh, "lod" + std::to_string(l + 1) + ": ");
              }
            }
            std::printf("lod: %zu levels, read %.2f s, chain %.2f s, write %.2f s\n", chain.levels.size(), read_seconds,
                        chain.seconds, written.report["write_seconds"].get<double>());
            return kExitOk;
          }};
}

}  // namespace quadlod::cli
