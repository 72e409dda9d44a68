// quadlod — procedural meshes with known topology, for tests, benchmarks and the demo.
//
// Every generator returns counter-clockwise (outward-facing) polygons with per-corner UVs.
// The known answers tests rely on are stated with each generator.
#pragma once

#include "quadlod/mesh.h"
#include "quadlod/skin.h"

namespace quadlod {

/// Planar n×m quad grid in the XY plane covering [0,width]×[0,height].
/// (n+1)(m+1) vertices, n·m quads, 2(n+m) boundary edges, n+m open poly-chords.
PolyMesh make_grid(Index n, Index m, double width = 1.0, double height = 1.0);

/// Closed torus of n (around the main ring) × m (around the tube) quads. n,m >= 3.
/// n·m vertices and quads, no boundary, n+m closed poly-chords.
PolyMesh make_torus(Index n, Index m, double major_radius = 1.0, double minor_radius = 0.35);

/// Open cylinder (no caps) of n quads around × m quads along its axis (Z), n >= 3.
/// n(m+1) vertices, 2 boundary loops, n open chords along the axis and m closed rings.
PolyMesh make_cylinder(Index n, Index m, double radius = 0.5, double height = 1.0);

/// Axis-aligned cube [-s/2,s/2]^3 whose every side is k×k quads (k >= 1), vertices shared.
/// 6k² quads; 3k closed poly-chords (3 when k = 1).
PolyMesh make_cube(Index k = 1, double size = 1.0);

/// The project's own demo asset: a closed, quad-dominant "vase" — a surface of revolution with
/// a wavy, bulging profile (so curvature varies along the loops), closed at the bottom by a
/// triangle fan around a pole vertex and at the top by one `segments`-gon lid, so triangles,
/// quads and an n-gon all occur. `segments` (>= 3) quads around × `rings` (>= 1) along:
/// segments·rings quads, `segments` triangles, one n-gon; closed, one component.
PolyMesh make_demo_vase(Index segments = 48, Index rings = 40);

/// A skinned test rig (issue 24): make_cylinder(around, along, radius, length) along +Z driven by
/// a chain of `bones` (2 or 3) joints, joint k at z = k·length/bones (joint 0 the root at the
/// origin, each a child of the one before), with inverse bind matrices of that rest pose.
/// Weights: a vertex at height z belongs to bone ⌊z·bones/length⌋ alone, except within
/// `blend` (a fraction of one bone's length) of a joint k >= 1, where it blends linearly from
/// bone k−1 (weight 1 at z_k − blend·L/bones) to bone k (weight 1 at z_k + blend·L/bones); so
/// every vertex has one or two influences (blend 0: rigid weights, one each) and the lower half (z < z_1 − blend·L/bones) follows
/// joint 0 only. One animation "bend", keyed at each of `frames` frames (1/24 s apart): every
/// joint k >= 1 turns about +X from 0 to `max_angle_deg` linearly.
SkinnedMesh make_bending_tube(Index around = 16, Index along = 24, Index bones = 2, double radius = 0.25,
                              double length = 2.0, double blend = 0.25, Index frames = 12,
                              double max_angle_deg = 60.0);

}  // namespace quadlod
