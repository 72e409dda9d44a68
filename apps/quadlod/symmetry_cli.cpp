// The symmetry line of `simplify` and `lod`: see symmetry_cli.h.
#include "symmetry_cli.h"

#include "mesh/symmetry.h"

#include <cstdio>

namespace quadlod::cli {

void print_symmetry_line(const nlohmann::json& report, const std::string& prefix) {
  if (!report.contains("symmetry")) return;
  const nlohmann::json& s = report["symmetry"];
  if (s.contains("note")) {
    std::printf("%snote: %s\n", prefix.c_str(), s["note"].get<std::string>().c_str());
    return;
  }
  const std::string axis = s.value("axis", "none");
  if (axis == "none") return;
  std::printf("%ssymmetry: mirror about the %s plane (%s = %.6g): %.2f %% of the input's vertices matched "
              "(%llu on the plane, %llu unmatched)",
              prefix.c_str(), axis.c_str(), axis.c_str(), s.value("centre", 0.0), 100.0 * s.value("matched_fraction", 0.0),
              static_cast<unsigned long long>(s.value("on_plane_vertices", 0ull)),
              static_cast<unsigned long long>(s.value("unmatched_vertices", 0ull)));
  if (s.value("strict_edges_mirrored_fraction", 1.0) < 1.0)
    std::printf("; %.1f %% of the strict lines' edges mirrored", 100.0 * s["strict_edges_mirrored_fraction"].get<double>());
  if (s.contains("output_paired_vertices"))
    std::printf("; output: %llu paired, %llu on the plane, %llu unmatched",
                static_cast<unsigned long long>(s.value("output_paired_vertices", 0ull)),
                static_cast<unsigned long long>(s.value("output_on_plane_vertices", 0ull)),
                static_cast<unsigned long long>(s.value("output_unmatched_vertices", 0ull)));
  std::printf("\n");
}

nlohmann::json symmetry_metric(const PolyMesh& input, const PolyMesh& output) {
  SymmetryDetectParams params;
  params.min_matched_fraction = 0.0;  // the best plane, whatever its share
  const SymmetryDetection d = detect_symmetry(input, -1, params);
  nlohmann::json j = {{"tolerance", params.tolerance}, {"axis", axis_name(d.best_axis)}};
  if (!d.symmetric()) return j;
  j["centre"] = d.mirror.plane.centre;
  j["input_matched_fraction"] = d.mirror.matched_fraction();
  j["output_mirrored_fraction"] = mirrored_vertex_fraction(output.positions, d.mirror.plane, d.tolerance);
  j["output_vertices"] = output.positions.size();
  return j;
}

}  // namespace quadlod::cli
