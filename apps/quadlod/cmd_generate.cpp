// `quadlod generate KIND -o FILE`: writes one of the project's procedural meshes (tests, demo).
#include "commands.h"

#include "quadlod/generators.h"
#include "quadlod/io.h"

#include <cstdio>
#include <map>
#include <memory>

namespace quadlod::cli {

namespace {

struct GenerateOptions {
  std::string kind = "vase";
  std::string output;
  Index n = 0;  // 0 = the generator's default resolution
  Index m = 0;
};

}  // namespace

Command add_generate(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<GenerateOptions>();
  CLI::App* sub = app.add_subcommand("generate", "Write a procedural mesh (demo asset, test shapes)");
  sub->add_option("KIND", opt->kind, "vase (the demo asset), grid, torus, cylinder, cube")
      ->check(CLI::IsMember({"vase", "grid", "torus", "cylinder", "cube"}))
      ->capture_default_str();
  sub->add_option("-o,--output", opt->output, "Output mesh (.obj, .ply, .off)")->required();
  sub->add_option("--n", opt->n, "Resolution along the first direction (quads)")
      ->check(CLI::Range(1u, 4096u));
  sub->add_option("--m", opt->m, "Resolution along the second direction (quads)")
      ->check(CLI::Range(1u, 4096u));
  return {sub, [opt, &global]() -> int {
            auto pick = [](Index value, Index fallback) { return value ? value : fallback; };
            PolyMesh mesh;
            if (opt->kind == "vase") mesh = make_demo_vase(pick(opt->n, 48), pick(opt->m, 40));
            else if (opt->kind == "grid") mesh = make_grid(pick(opt->n, 16), pick(opt->m, 16));
            else if (opt->kind == "torus")
              mesh = make_torus(std::max<Index>(3, pick(opt->n, 48)), std::max<Index>(3, pick(opt->m, 24)));
            else if (opt->kind == "cylinder")
              mesh = make_cylinder(std::max<Index>(3, pick(opt->n, 32)), pick(opt->m, 16));
            else mesh = make_cube(pick(opt->n, 8));
            const WriteResult written = write_mesh(mesh, opt->output);
            if (!written.ok()) return fail(written.error);
            for (const std::string& w : written.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
            if (!global.quiet)
              std::fprintf(stderr, "generate: %s with %u vertices, %u faces -> %s\n", opt->kind.c_str(),
                           mesh.num_vertices(), mesh.num_faces(), opt->output.c_str());
            return kExitOk;
          }};
}

}  // namespace quadlod::cli
