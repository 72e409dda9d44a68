// `quadlod analyze MESH --export DIR`: poly-chords, segments and clusters as coloured geometry.
#include "commands.h"

#include "mesh/connectivity.h"
#include "quadlod/io.h"
#include "topology/analysis.h"

#include <cstdio>
#include <memory>

namespace quadlod::cli {

namespace {

struct AnalyzeOptions {
  std::string mesh, dir;
};

}  // namespace

Command add_analyze(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<AnalyzeOptions>();
  CLI::App* sub = app.add_subcommand("analyze", "Export poly-chords, segments and clusters for viewing in Blender or MeshLab");
  sub->add_option("MESH", opt->mesh, "Input mesh")->required();
  sub->add_option("--export", opt->dir, "Directory for the coloured PLY/OBJ files (created)")->required();
  return {sub, [opt, &global]() -> int {
            const ReadResult in = read_mesh(opt->mesh);
            if (!in.ok()) return fail(in.error);
            const Connectivity conn = build_connectivity(in.mesh);
            const AnalysisResult analysis = analyze(in.mesh, conn);
            std::printf("%s\n", analysis_summary(in.mesh, analysis).c_str());
            const std::string error = write_analysis_export(in.mesh, conn, analysis, opt->dir);
            if (!error.empty()) return fail(error);
            if (!global.quiet) std::fprintf(stderr, "analyze: wrote %s\n", opt->dir.c_str());
            return kExitOk;
          }};
}

}  // namespace quadlod::cli
