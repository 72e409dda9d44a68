// Symmetric reduction: see symmetric_reduction.h (issue 34, docs/symmetry.md).
#include "pipeline/symmetric_reduction.h"

#include <cstdio>

namespace quadlod {

namespace {
int requested_axis(SimplifyOptions::Symmetry s) {
  switch (s) {
    case SimplifyOptions::Symmetry::X: return 0;
    case SimplifyOptions::Symmetry::Y: return 1;
    case SimplifyOptions::Symmetry::Z: return 2;
    default: return -1;
  }
}
}  // namespace

SymmetrySetup setup_symmetry(const PolyMesh& input, const SimplifyOptions& options) {
  SymmetrySetup out;
  out.report = {{"requested", to_string(options.symmetry)}, {"axis", "none"}};
  if (options.symmetry == SimplifyOptions::Symmetry::Off) return out;
  SymmetryDetectParams dp;
  dp.tolerance = options.symmetry_tolerance;
  dp.min_matched_fraction = options.symmetry_min_matched;
  const int axis = requested_axis(options.symmetry);
  SymmetryDetection d = detect_symmetry(input, axis, dp);
  out.tolerance = d.tolerance;
  out.report["tolerance"] = options.symmetry_tolerance;
  out.report["min_matched"] = options.symmetry_min_matched;
  out.report["best_axis"] = axis_name(d.best_axis);
  out.report["best_matched_fraction"] = d.best_fraction;
  if (d.symmetric()) {
    const VertexMirror& m = d.mirror;
    out.plane = m.plane;
    out.report["axis"] = axis_name(m.plane.axis);
    out.report["centre"] = m.plane.centre;
    out.report["matched_fraction"] = m.matched_fraction();
    out.report["paired_vertices"] = m.pairs;
    out.report["on_plane_vertices"] = m.on_plane;
    out.report["unmatched_vertices"] = m.unmatched;
    return out;
  }
  char text[256];
  const std::string where = axis >= 0 ? std::string("about the ") + axis_name(axis) + " plane"
                                      : std::string("about any bbox-centred axis plane");
  std::snprintf(text, sizeof text,
                "not mirror-symmetric %s within %g of the diagonal (best: %s, %.1f %% of the vertices matched, %.1f %% needed); "
                "reduced without symmetry",
                where.c_str(), options.symmetry_tolerance, axis_name(d.best_axis), 100.0 * d.best_fraction,
                100.0 * options.symmetry_min_matched);
  out.note = text;
  out.report["note"] = out.note;
  return out;
}

PassMirror pass_mirror(const PolyMesh& mesh, const Connectivity& conn, const SymmetrySetup& setup) {
  PassMirror out;
  if (!setup.active()) return out;
  out.vertices = match_mirror_vertices(mesh.positions, setup.plane, setup.tolerance);
  out.edges = mirror_edges(conn, out.vertices);
  return out;
}

void keep_mirrored(std::vector<std::uint8_t>& edge_kept, const PassMirror& mirror) {
  symmetrize_flags_union(edge_kept, mirror.edges);
}

ClusterCollapseResult collapse_symmetric(const PolyMesh& mesh, const Connectivity& conn,
                                         const std::vector<std::uint8_t>& edge_kept, const ClusterCollapseParams& params,
                                         const PassMirror& mirror, int max_reruns, int& reruns) {
  reruns = 0;
  ClusterCollapseResult result = collapse_clusters(mesh, conn, edge_kept, params);
  while (result.status == ClusterCollapseStatus::Ok && reruns < max_reruns) {
    std::vector<std::uint8_t> kept(conn.num_edges);
    bool symmetric = true;
    for (Index e = 0; e < conn.num_edges; ++e) {
      kept[e] = result.edge_collapsed_final[e] ? 0 : 1;
      const Index m = mirror.edges[e];
      if (m != kInvalidIndex && result.edge_collapsed_final[e] != result.edge_collapsed_final[m]) symmetric = false;
    }
    if (symmetric) break;
    keep_mirrored(kept, mirror);
    ++reruns;
    result = collapse_clusters(mesh, conn, kept, params);
  }
  return result;
}

}  // namespace quadlod
