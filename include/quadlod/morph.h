// quadlod — blend shapes (issue 34; glTF morph targets, FBX blend shapes, Blender shape keys).
//
// The shapes live in the mesh (PolyMesh::morph_targets, include/quadlod/mesh.h): one displacement
// per vertex per shape. This header holds what is done with them:
//   * posing a mesh in a mix of its shapes (base + Σ_k w_k d_k), for tests, metrics and the bar;
//   * moving the shapes onto another surface (the reduction's output) by the same projection the
//     skin weights take (skin.h, transfer_skin_weights): each target vertex's closest point on the
//     source, on a triangle facing its way and on its own part, blends that triangle's three
//     corners' displacements by its barycentric coordinates. A vertex that did not move lands on
//     its own input vertex and keeps that vertex's displacement exactly.
// docs/blend_shapes.md has the format support, the carry rule and the selection's error term.
#pragma once

#include "quadlod/mesh.h"
#include "quadlod/skin.h"

#include <span>
#include <vector>

namespace quadlod {

/// The mesh with positions p_v + Σ_k weights[k] · d_k(v) (weights beyond the mesh's shapes are
/// ignored; missing ones are 0). Everything else is copied, the shapes included; per-corner
/// normals are dropped (they would need re-deriving, as pose_mesh does).
PolyMesh apply_morph_targets(const PolyMesh& mesh, std::span<const double> weights);

/// The mesh in shape k at full weight (apply_morph_targets with weight 1 on k, 0 elsewhere).
PolyMesh apply_morph_target(const PolyMesh& mesh, Index k);

/// The shapes of `source` for every vertex of `target` by projection onto the source's surface
/// (see the file comment; `params` as for transfer_skin_weights, whose projection this is: its
/// max_influences and min_weight are not used). Names and default weights are copied. Empty
/// when the source has no shapes. Preconditions: both meshes pass check_layout(). Deterministic.
std::vector<MorphTarget> transfer_morph_targets(const PolyMesh& source, const PolyMesh& target,
                                                const SkinTransferParams& params = {});

}  // namespace quadlod
