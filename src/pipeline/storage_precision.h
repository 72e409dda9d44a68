// Decisions on float32 coordinates (issue 21): FBX, glTF and every DCC tool store positions as
// 32-bit floats, an OBJ in decimal text with as many digits as its exporter chose. The reduction
// is a long chain of comparisons (greedy order, ties, thresholds), so a 1e-7 relative difference
// between two copies of one mesh can take it down a different path (docs/scenes.md: up to 0.012
// in quad fraction at 0.5, 0.036 one LOD further). simplify() therefore decides on the positions
// rounded to float32 — the same values whichever format the mesh came in — and gives the
// vertices that did not move their input coordinates back.
#pragma once

#include "quadlod/mesh.h"

#include <optional>

namespace quadlod {

/// `mesh` with every position rounded to the nearest float32, or nothing when that changes no
/// position (already float32 values) or cannot be done (a coordinate beyond float32's range,
/// or not finite: then decisions stay on the doubles, and validation reports the latter).
std::optional<PolyMesh> with_float32_positions(const PolyMesh& mesh);

/// Every vertex of `output` that sits exactly on a rounded position of an `input` vertex gets
/// that input vertex's own coordinates back (the lowest-numbered one where several round to the
/// same point): unmoved vertices, and clusters placed at a member.
void restore_input_positions(const PolyMesh& input, PolyMesh& output);

}  // namespace quadlod
