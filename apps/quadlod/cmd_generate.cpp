// `quadlod generate KIND -o FILE`: writes one of the project's procedural meshes (tests, demo).
#include "commands.h"

#include "quadlod/generators.h"
#include "quadlod/io.h"
#include "quadlod/skin_io.h"

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
  Index bones = 2;
};

}  // namespace

Command add_generate(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<GenerateOptions>();
  CLI::App* sub = app.add_subcommand("generate", "Write a procedural mesh (demo asset, test shapes)");
  sub->add_option("KIND", opt->kind, "vase (the demo asset), grid, torus, cylinder, cube, bending-tube (skinned, .glb)")
      ->check(CLI::IsMember({"vase", "grid", "torus", "cylinder", "cube", "bending-tube"}))
      ->capture_default_str();
  sub->add_option("-o,--output", opt->output, "Output mesh (.obj, .ply, .off)")->required();
  sub->add_option("--n", opt->n, "Resolution along the first direction (quads)")
      ->check(CLI::Range(1u, 4096u));
  sub->add_option("--m", opt->m, "Resolution along the second direction (quads)")
      ->check(CLI::Range(1u, 4096u));
  sub->add_option("--bones", opt->bones, "bending-tube: joints along the tube")->check(CLI::Range(2u, 3u))->capture_default_str();
  return {sub, [opt, &global]() -> int {
            auto pick = [](Index value, Index fallback) { return value ? value : fallback; };
            if (opt->kind == "bending-tube") {
              // The skinned test rig (issue 24): a .glb with its skeleton and the "bend" animation.
              const SkinnedMesh tube = make_bending_tube(std::max<Index>(3, pick(opt->n, 16)), pick(opt->m, 24), opt->bones);
              const WriteResult written = write_skinned_glb(tube.mesh, tube.rig, opt->output);
              if (!written.ok()) return fail(written.error);
              if (!global.quiet)
                std::fprintf(stderr, "generate: bending-tube with %u vertices, %u faces, %u bones -> %s\n",
                             tube.mesh.num_vertices(), tube.mesh.num_faces(), tube.rig.skeleton.num_joints(), opt->output.c_str());
              return kExitOk;
            }
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
