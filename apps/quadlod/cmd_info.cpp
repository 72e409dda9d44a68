// `quadlod info MESH [--json]`: counts, validity and (later) topology of one mesh.
#include "commands.h"

#include "mesh/connectivity.h"
#include "mesh/validation.h"
#include "quadlod/io.h"
#include "topology/analysis.h"
#include "util/progress.h"

#include <cstdio>
#include <memory>

namespace quadlod::cli {

namespace {

struct InfoOptions {
  std::string mesh;
  bool json = false;
  bool topology = false;
};

void print_text(const std::string& path, const MeshStats& s, double read_seconds) {
  std::printf("%s\n", path.c_str());
  std::printf("  vertices            %u (%u unused)\n", s.vertices, s.unused_vertices);
  std::printf("  faces               %u: %u triangles, %u quads, %u n-gons (largest %u corners)\n",
              s.faces, s.triangles, s.quads, s.ngons, s.max_face_degree);
  std::printf("  tri-equivalent      %llu (quad = 2, k-gon = k-2)\n",
              static_cast<unsigned long long>(s.tri_equivalent));
  std::printf("  edges               %u: %u boundary in %u loops, %u non-manifold\n", s.edges,
              s.boundary_edges, s.boundary_loops, s.nonmanifold_edges);
  std::printf("  non-manifold verts  %u\n", s.nonmanifold_vertices);
  std::printf("  degenerate faces    %u (%u repeated index, %u zero area)\n", s.degenerate_faces,
              s.repeated_index_faces, s.zero_area_faces);
  std::printf("  duplicate faces     %u\n", s.duplicate_faces);
  std::printf("  components          %u\n", s.components);
  std::printf("  uvs / normals       %s / %s\n",
              s.has_uvs ? "yes" : (s.has_partial_uvs ? "partial" : "no"), s.has_normals ? "yes" : "no");
  std::printf("  materials / groups  %u / %u\n", s.materials, s.groups);
  if (!s.bbox.empty())
    std::printf("  bbox                [%g %g %g] .. [%g %g %g], diagonal %g\n", s.bbox.min.x(),
                s.bbox.min.y(), s.bbox.min.z(), s.bbox.max.x(), s.bbox.max.y(), s.bbox.max.z(),
                s.bbox.diagonal());
  std::printf("  read time           %.3f s\n", read_seconds);
}

}  // namespace

Command add_info(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<InfoOptions>();
  CLI::App* sub = app.add_subcommand("info", "Counts, validity and topology of a mesh");
  sub->add_option("MESH", opt->mesh, "Input mesh (.obj, .ply, .off)")->required();
  sub->add_flag("--json", opt->json, "Print one JSON object instead of text");
  sub->add_flag("--topology", opt->topology,
                "Also poly-chords, segments and clusters (paper §3.1-§3.2.4)");
  return {sub, [opt, &global]() -> int {
            ReadOptions read_options;
            read_options.allow_repeated_vertex = true;  // info counts them instead of refusing
            ReadResult read = read_mesh(opt->mesh, read_options);
            if (!read.ok()) return fail(read.error);
            Stopwatch clock;
            const Connectivity conn = build_connectivity(read.mesh);
            const MeshStats stats = compute_stats(read.mesh, conn);
            nlohmann::json topology;
            if (opt->topology) {
              if (stats.repeated_index_faces > 0)
                return fail(opt->mesh + ": --topology needs faces without repeated vertices (" +
                            std::to_string(stats.repeated_index_faces) + " found)");
              const AnalysisResult a = analyze(read.mesh, conn);
              topology = {
                  {"polychords", a.polychords.chords.size()},
                  {"polychords_closed", a.polychords.num_closed},
                  {"polychords_self_crossing", a.polychords.num_self_crossing},
                  {"segments", a.segmentation.segments.size()},
                  {"breakpoints", a.segmentation.stats.num_breakpoints},
                  {"quad_clusters", a.medial.clusters.size()},
                  {"triangle_clusters", a.triangles.clusters.size()},
                  {"topology_seconds", a.timings.total_ms / 1000.0},
              };
            }
            if (opt->json) {
              nlohmann::json j = to_json(stats);
              if (opt->topology) j.update(topology);
              j["file"] = opt->mesh;
              j["read_seconds"] = read.seconds;
              j["analysis_seconds"] = clock.seconds();
              std::printf("%s\n", j.dump(2).c_str());
            } else {
              print_text(opt->mesh, stats, read.seconds);
              if (opt->topology)
                std::printf("  poly-chords         %s (%s closed, %s self-crossing)\n"
                            "  segments            %s (%s breakpoints)\n"
                            "  clusters            %s quad, %s triangle\n"
                            "  topology time       %.3f s\n",
                            topology["polychords"].dump().c_str(), topology["polychords_closed"].dump().c_str(),
                            topology["polychords_self_crossing"].dump().c_str(), topology["segments"].dump().c_str(),
                            topology["breakpoints"].dump().c_str(), topology["quad_clusters"].dump().c_str(),
                            topology["triangle_clusters"].dump().c_str(), topology["topology_seconds"].get<double>());
            }
            (void)global;
            return kExitOk;
          }};
}

}  // namespace quadlod::cli
