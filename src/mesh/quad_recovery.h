// quadlod — quads recovered from a triangulated input (session 16; docs/scenes.md, "Triangulated
// inputs").
//
// glTF holds triangles only, and most exporters triangulate on the way out, so an artist's
// quad-dominant character arrives as two triangles per quad: no poly-chords, no quad layout, and
// the reduction falls back to triangle clusters (the ram's walk .glb at 0.2: 0 quads, and the
// target missed by 20 % after 79 refused clusters). Before the reduction, pairs of triangles that
// were one quad are joined again, as Blender's "Tris to Quads" does: two triangles sharing a
// manifold edge, oriented alike, with the same attributes on both sides of that edge (no UV or
// normal seam along it, the same material, object, group and smoothing), that together make a
// convex quad whose corners are near right angles and whose halves are nearly coplanar. Pairs are
// taken best first (least corner deviation plus fold), so the result does not depend on the face
// order beyond ties, which go to the lower edge id. Vertices, their attributes and skin weights
// are unchanged; only faces are joined.
#pragma once

#include "quadlod/mesh.h"

namespace quadlod {

struct QuadRecoveryParams {
  /// Largest angle (degrees) between the two triangles' normals. Blender's default is 40°.
  double max_fold_deg = 40.0;
  /// Largest deviation (degrees) of a corner of the joined quad from a right angle. Blender's
  /// default is 40°.
  double max_corner_deviation_deg = 40.0;
};

struct QuadRecoveryResult {
  PolyMesh mesh;          ///< the input with the joined pairs as quads (face order: each quad at its first triangle)
  Index candidates = 0;   ///< triangle pairs that passed every test
  Index joined = 0;       ///< pairs joined (each face in at most one)
};

/// Joins triangle pairs of `mesh` (which must pass check_layout()) into quads, as described above.
/// Faces that are not triangles are copied as they are.
QuadRecoveryResult recover_quads(const PolyMesh& mesh, const QuadRecoveryParams& params = {});

/// True when every face of `mesh` is a triangle (and there is at least one): the input a
/// triangulating exporter writes, which SimplifyOptions::recover_quads "auto" joins.
bool all_triangles(const PolyMesh& mesh);

}  // namespace quadlod
