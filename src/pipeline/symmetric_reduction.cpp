// Symmetric reduction: see symmetric_reduction.h (issue 34, docs/symmetry.md).
#include "pipeline/symmetric_reduction.h"

#include "mesh/features.h"

#include <cmath>
#include <cstdio>
#include <optional>
#include <tuple>

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

namespace {
// The share of the strict lines' edges (UV seams, material borders, boundaries) whose mirror edge
// is strict too; `strict` gets their count.
double mirrored_line_fraction(const PolyMesh& input, const Connectivity& conn, const FeatureEdges& feat,
                              const VertexMirror& m, Index& strict) {
  const std::vector<Index> em = mirror_edges(conn, m);
  Index mirrored = 0;
  strict = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    if (!feat.is_strict(e)) continue;
    ++strict;
    mirrored += em[e] != kInvalidIndex && feat.is_strict(em[e]);
  }
  (void)input;
  return strict ? double(mirrored) / double(strict) : 1.0;
}

// The share of the vertices with a protect weight > 0 whose partner carries the same weight
// (within kSameWeight); `weighted` gets their count. 1 without weights.
double mirrored_protect_fraction(const std::vector<double>& protect, const VertexMirror& m, Index& weighted) {
  constexpr double kSameWeight = 1e-3;
  weighted = 0;
  if (protect.size() != m.partner.size()) return 1.0;
  Index mirrored = 0;
  for (Index v = 0; v < Index(protect.size()); ++v) {
    if (!(protect[v] > 0.0)) continue;
    ++weighted;
    const Index w = m.partner[v];
    mirrored += w != kInvalidIndex && std::abs(protect[w] - protect[v]) <= kSameWeight;
  }
  return weighted ? double(mirrored) / double(weighted) : 1.0;
}
}  // namespace

// The plane: each axis asked for (auto: all three) is matched (detect_symmetry); among those that
// reach min_matched, auto keeps the one whose strict lines are mirrored (at least
// min_mirrored_lines), then the most matched vertices, then the most mirrored lines, then the
// fewest vertices on the plane, then x, y, z. A cylinder with one UV seam is symmetric about two
// planes through its axis; only the one through the seam mirrors the seam.
SymmetrySetup setup_symmetry(const PolyMesh& input, const SimplifyOptions& options,
                             const std::vector<double>& protect) {
  SymmetrySetup out;
  out.report = {{"requested", to_string(options.symmetry)}, {"axis", "none"}};
  if (options.symmetry == SimplifyOptions::Symmetry::Off) return out;
  SymmetryDetectParams dp;
  dp.tolerance = options.symmetry_tolerance;
  dp.min_matched_fraction = options.symmetry_min_matched;
  const int axis = requested_axis(options.symmetry);
  out.report["tolerance"] = options.symmetry_tolerance;
  out.report["min_matched"] = options.symmetry_min_matched;
  std::optional<Connectivity> conn;
  std::optional<FeatureEdges> feat;
  if (options.features) {
    conn = build_connectivity(input);
    FeatureParams fp;
    fp.hard_angle_deg = options.hard_angle_deg;
    feat = find_feature_edges(input, *conn, fp);
  }
  struct Candidate {
    VertexMirror mirror;
    double lines = 1.0;
    Index strict = 0;
  };
  std::optional<Candidate> best;
  auto key = [&](const Candidate& c) {
    return std::tuple(c.lines >= options.symmetry_min_mirrored_lines, c.mirror.matched_fraction(), c.lines,
                      -double(c.mirror.on_plane));
  };
  int best_axis = -1;
  double best_fraction = 0.0;
  for (int a = 0; a < 3; ++a) {
    if (axis >= 0 && a != axis) continue;
    SymmetryDetection d = detect_symmetry(input, a, dp);
    out.tolerance = d.tolerance;
    if (d.best_axis >= 0 && (best_axis < 0 || d.best_fraction > best_fraction)) {
      best_axis = d.best_axis;
      best_fraction = d.best_fraction;
    }
    if (!d.symmetric()) continue;
    Candidate c{std::move(d.mirror)};
    if (feat) c.lines = mirrored_line_fraction(input, *conn, *feat, c.mirror, c.strict);
    if (!best || key(c) > key(*best)) best = std::move(c);
  }
  out.report["best_axis"] = axis_name(best_axis);
  out.report["best_matched_fraction"] = best_fraction;
  if (best) {
    const VertexMirror& m = best->mirror;
    if (feat) {
      out.report["strict_edges"] = best->strict;
      out.report["strict_edges_mirrored_fraction"] = best->lines;
    }
    // Auto only: where the lines are not mirrored, each side's lines would bind both sides
    // (docs/symmetry.md, "Attributes"); an explicit axis mirrors anyway.
    if (axis < 0 && best->lines < options.symmetry_min_mirrored_lines) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "mirror-symmetric about the %s plane, but its UV seams, material borders and boundaries are not "
                    "(%.1f %% of %u strict edges mirrored, %.0f %% needed): reduced without symmetry (--symmetry %s "
                    "mirrors anyway, each side's lines binding both)",
                    axis_name(m.plane.axis), 100.0 * best->lines, static_cast<unsigned>(best->strict),
                    100.0 * options.symmetry_min_mirrored_lines, axis_name(m.plane.axis));
      out.note = text;
      out.report["note"] = out.note;
      return out;
    }
    // Auto only, likewise: protect weights on one side only (issue 34, docs/protect.md).
    Index weighted = 0;
    const double protect_mirrored = mirrored_protect_fraction(protect, m, weighted);
    if (weighted) out.report["protect_mirrored_fraction"] = protect_mirrored;
    if (axis < 0 && protect_mirrored < options.symmetry_min_mirrored_lines) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "mirror-symmetric about the %s plane, but its protect weights are not (%.1f %% of %u weighted "
                    "vertices mirrored, %.0f %% needed): reduced without symmetry (--symmetry %s mirrors anyway, "
                    "each side's protection binding both)",
                    axis_name(m.plane.axis), 100.0 * protect_mirrored, static_cast<unsigned>(weighted),
                    100.0 * options.symmetry_min_mirrored_lines, axis_name(m.plane.axis));
      out.note = text;
      out.report["note"] = out.note;
      return out;
    }
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
                where.c_str(), options.symmetry_tolerance, axis_name(best_axis), 100.0 * best_fraction,
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
