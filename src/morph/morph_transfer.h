// Internal to the reduction (issue 34): the blend of source shapes by a projection already made,
// so that a run builds the original input's search structures once (SurfaceProjector) and
// projects every pass's output onto them. transfer_morph_targets (quadlod/morph.h) is this with
// a projection of its own.
#pragma once

#include "quadlod/mesh.h"
#include "skin/surface_projection.h"

#include <vector>

namespace quadlod {

/// The shapes of `source` for every vertex of `target`, from `projection` = the projection of
/// `target` onto `source` (SurfaceProjector::project or project_onto_surface). A vertex exactly on
/// a corner of its triangle takes that corner alone (its displacement bit for bit); otherwise
/// the barycentric mix. Empty when the source has no shapes.
std::vector<MorphTarget> blend_morph_targets(const PolyMesh& source, const PolyMesh& target, SurfaceProjection projection);

}  // namespace quadlod
