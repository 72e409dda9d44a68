// The symmetry line of `simplify` and `lod` (issue 34, docs/symmetry.md), from a simplify report.
#pragma once

#include "quadlod/mesh.h"

#include <nlohmann/json.hpp>

#include <string>

namespace quadlod::cli {

/// "symmetry: mirror about the x plane (x = 0): 99.9 % of the input's vertices matched …" when a
/// plane was used, "note: not mirror-symmetric …" when one was asked for and not found, nothing
/// with --symmetry off. `prefix` goes before the line ("lod1: ", or "").
void print_symmetry_line(const nlohmann::json& report, const std::string& prefix = {});

/// eval's `symmetry` metric: the input's best bbox-centred mirror plane (detect_symmetry with the
/// default tolerance, 1e-4 of the input's diagonal; the plane with the most matched vertices even
/// when below min_matched), the share of input vertices matched there, and the share of output
/// vertices whose reflection about the same plane has an output vertex within the same absolute
/// tolerance ("mirrored"; partners may repeat).
nlohmann::json symmetry_metric(const PolyMesh& input, const PolyMesh& output);

}  // namespace quadlod::cli
