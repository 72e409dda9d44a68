// Decisions on float32 coordinates (issue 21): FBX, glTF and every DCC tool store positions as
// 32-bit floats, an OBJ in decimal text with as many digits as its exporter chose. The reduction
// is a long chain of comparisons (greedy order, ties, thresholds), so a 1e-7 relative difference
// between two copies of one mesh can take it down a different path (docs/scenes.md: up to 0.012
// in quad fraction at 0.5, 0.036 one LOD further). simplify() therefore decides on the positions,
// UVs and normals rounded to float32 — the same values whichever format the mesh came in — and
// gives the vertices that did not move (and the UVs and normals that were kept) their input
// values back.
#pragma once

#include "quadlod/mesh.h"

#include <optional>

namespace quadlod {

/// True when rounding `mesh`'s positions, normals and UVs to float32 changes one of them and can
/// be done (no value beyond float32's range or not finite: then decisions stay on the doubles,
/// and validation reports the latter).
bool float32_rounding_changes(const PolyMesh& mesh);

/// Rounds `mesh`'s positions, normals and UVs to float32 in place, returning their exact values
/// (a mesh holding only positions, normals and UV values) — or nothing, and `mesh` unchanged,
/// when float32_rounding_changes() is false.
std::optional<PolyMesh> round_to_float32_in_place(PolyMesh& mesh);

/// Puts the values taken by round_to_float32_in_place() back.
void put_back_exact_values(PolyMesh&& exact, PolyMesh& mesh);

/// Every position (normal, UV) of `output` that is exactly a rounded value of `input` gets that
/// input value back (the lowest-numbered one where several round to the same): unmoved vertices,
/// clusters placed at a member, kept UVs and normals.
void restore_input_values(const PolyMesh& input, PolyMesh& output);

}  // namespace quadlod
