// Symmetric reduction (issue 34, docs/symmetry.md): what simplify() adds around its stages when
// SimplifyOptions::symmetry finds a mirror plane. The stages themselves take the mirror maps
// (ShapeSelectionParams::edge_mirror, ClusterCollapseParams::mirror, SurfaceFitParams::mirror);
// here are the choice of the plane, the maps of one pass, and the rules that make a set of edge
// decisions symmetric.
#pragma once

#include "mesh/connectivity.h"
#include "mesh/symmetry.h"
#include "post/cluster_collapse.h"
#include "quadlod/simplify.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace quadlod {

/// The plane a run reduces about (none: plane.axis < 0), its absolute tolerance, the report's
/// `symmetry` object and the one-line note when a plane was asked for (auto or an axis) and the
/// input is not symmetric within the tolerance.
struct SymmetrySetup {
  MirrorPlane plane;
  double tolerance = 0.0;
  nlohmann::json report;
  std::string note;
  bool active() const { return plane.valid(); }
};
/// `protect`: the run's protect weights (issue 34; empty = none). Auto also needs them mirrored
/// (symmetry_min_mirrored_lines of the weighted vertices' partners carry the same weight): one
/// side's protection would otherwise bind both sides.
SymmetrySetup setup_symmetry(const PolyMesh& input, const SimplifyOptions& options,
                             const std::vector<double>& protect = {});

/// The mirror maps of one pass's input: vertices by position (the tolerance of the run; after the
/// first pass the pairs are exact), edges by their endpoints' partners.
struct PassMirror {
  VertexMirror vertices;
  std::vector<Index> edges;
};
PassMirror pass_mirror(const PolyMesh& mesh, const Connectivity& conn, const SymmetrySetup& setup);

/// An edge stays kept when its mirror edge is kept (the union of the kept sets): a selection,
/// pins, a repaired selection become symmetric without collapsing anything new.
void keep_mirrored(std::vector<std::uint8_t>& edge_kept, const PassMirror& mirror);

/// collapse_clusters(), then, while the collapsed edges are not symmetric (a refusal split one
/// cluster and not its mirror), the collapse again on their intersection with their mirror
/// images, at most `max_reruns` times: each rerun asks for a subset of what the last one
/// collapsed, so it ends. `reruns` counts the extra collapses.
ClusterCollapseResult collapse_symmetric(const PolyMesh& mesh, const Connectivity& conn,
                                         const std::vector<std::uint8_t>& edge_kept, const ClusterCollapseParams& params,
                                         const PassMirror& mirror, int max_reruns, int& reruns);

}  // namespace quadlod
