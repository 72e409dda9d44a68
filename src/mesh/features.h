// Feature edges and UV islands (issue 7): the lines a reduction must not tear, merge or move away.
//
// An input edge is a *feature edge* when one of these holds (several may):
//   * open boundary — used by exactly one face;
//   * non-manifold — used by more than two faces;
//   * UV seam — in some UV set, the two faces' corners at either endpoint carry different UV
//     values (compared by value, so duplicate pool entries with equal values are not a seam), or
//     one side has a UV and the other has none;
//   * normal seam — the per-corner normals differ across the edge in the same sense;
//   * material border — the two faces have different `face_material`;
//   * hard edge — dihedral angle >= hard_angle_deg, or (when smoothing groups are present) the
//     faces lie in different smoothing groups; smoothing off (group 0, flat shading) counts as a
//     group of its own, so flat | smooth is hard and flat | flat only by its dihedral angle.
// Only manifold interior edges can be seams, borders or hard edges; boundary and non-manifold
// edges carry their own bit.
//
// *Strict* features (boundary, non-manifold, UV seam, material border) separate things that
// must stay separate: two strict feature points may only merge when they are neighbours along one
// strict line, otherwise a seam would tear (one island's UVs meeting another's off their common
// seam), a hole would be pinched shut, a thin open part would vanish, or two materials would meet
// along a border the input does not have. Exception: the seams of a per-face UV layout (most faces
// alone in their island) are not strict: such a mesh must lose islands to be reduced at all.
// Hard edges and normal seams are *placement* features: a merged vertex that touches one such
// line stays on it, but two such lines may merge (a bevel between two creases may collapse at a
// coarse LOD). The measurements behind this split are in docs/attributes.md.
//
// Feature *lines* are maximal chains of feature edges between feature corners. A vertex is a
// feature corner when its number of incident feature edges is not 2 (an endpoint or a junction),
// or when its two feature edges have different bits (a seam turning into a boundary), or when
// they meet at a turn sharper than corner_angle_deg (a corner of a hard-surface outline).
// A closed feature loop without any corner is one line; its smallest vertex counts as a corner so
// that every line has an endpoint to anchor to.
#pragma once

#include "mesh/connectivity.h"
#include "quadlod/mesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace quadlod {

enum FeatureBit : std::uint8_t {
  kFeatureBoundary = 1u << 0,
  kFeatureNonManifold = 1u << 1,
  kFeatureUvSeam = 1u << 2,
  kFeatureNormalSeam = 1u << 3,
  kFeatureMaterialBorder = 1u << 4,
  kFeatureHardEdge = 1u << 5,
};
/// Features that must never be merged with a different feature line (see above).
inline constexpr std::uint8_t kStrictFeatures =
    kFeatureBoundary | kFeatureNonManifold | kFeatureUvSeam | kFeatureMaterialBorder;
inline constexpr std::uint8_t kAllFeatures = 0x3f;

struct FeatureParams {
  /// Manifold edges with a dihedral angle of at least this many degrees are hard edges. 60° is
  /// the paper's epsilon_theta (§3.2.2), the angle it uses for sharp breakpoints.
  double hard_angle_deg = 60.0;
  /// Use OBJ smoothing groups (`s`) when the mesh has them.
  bool smoothing_groups = true;
  /// Two feature edges meeting at a vertex turn by more than this many degrees: the vertex is a
  /// feature corner and may not move.
  double corner_angle_deg = 45.0;
  /// Which bits count at all (e.g. kStrictFeatures to ignore hard edges).
  std::uint8_t enabled = kAllFeatures;
  /// Which bits are strict (never merged with another line; see above).
  std::uint8_t strict = kStrictFeatures;
  /// A UV set in which more than this fraction of the faces are alone in their island is a
  /// per-face layout (the OpenSubdiv cages): it can only be reduced by letting islands vanish, so
  /// its seams are placement seams, not strict ones. Corpus: 1.00 on the two cages, at most 0.06
  /// on every other mesh (docs/attributes.md).
  double per_face_layout_fraction = 0.5;
  /// Threads for the per-edge classification (0 = every core); only the speed depends on them.
  /// Below min_parallel_edges edges it runs on one thread (a thread costs more than it saves).
  int threads = 1;
  std::size_t min_parallel_edges = 20000;
};

struct FeatureEdges {
  std::vector<std::uint8_t> edge_bits;           ///< per Connectivity edge, OR of FeatureBit
  std::vector<std::uint32_t> edge_uv_seam_sets;  ///< per edge: bit k = seam in UV set k (k < 32)
  std::vector<std::uint8_t> vertex_bits;         ///< per vertex, OR over its incident edges
  std::vector<Index> vertex_valence;             ///< per vertex, number of incident feature edges
  std::vector<std::uint8_t> vertex_corner;       ///< per vertex, 1 = feature corner (see above)
  std::vector<Index> edge_line;  ///< per edge, its feature line; kInvalidIndex if no feature
  Index num_lines = 0;
  /// Edges carrying each bit (index = bit position), and feature edges / corners in total.
  std::array<Index, 6> edges_with_bit{};
  Index feature_edges = 0;
  Index corners = 0;
  /// Strictness (see above): per edge, and per vertex (on a strict edge); strict edges in total.
  std::vector<std::uint8_t> edge_strict, vertex_strict;
  Index strict_edges = 0;

  bool is_feature(Index e) const { return edge_bits[e] != 0; }
  bool is_strict(Index e) const { return edge_strict[e] != 0; }
  bool on_feature(Index v) const { return vertex_bits[v] != 0; }
  bool on_strict(Index v) const { return vertex_strict[v] != 0; }
};

/// Classifies every edge of `conn` (built from `mesh`). Linear in the corners.
FeatureEdges find_feature_edges(const PolyMesh& mesh, const Connectivity& conn,
                                const FeatureParams& params = {});

/// Per edge, 1 on the strict lines of the texture: UV seams and material borders that are not
/// also open boundaries or non-manifold edges (the lines of the shape). Their planes weigh in the
/// vertex quadrics like a crease (QuadricPlacementParams::texture_line_edges, issue 32).
std::vector<std::uint8_t> texture_line_edges(const FeatureEdges& features);

/// UV islands of one UV set: faces joined across manifold edges that are not seams of that set.
struct UvIslands {
  std::vector<Index> face_island;  ///< per face; kInvalidIndex when a corner of it has no UV
  Index num_islands = 0;
  std::vector<Vec2> uv_min, uv_max;  ///< UV bounding box of each island
  std::vector<double> area_3d;       ///< surface area of each island
};
/// Precondition: uv_set < mesh.uv_sets.size().
UvIslands find_uv_islands(const PolyMesh& mesh, const Connectivity& conn, Index uv_set);

/// The UV islands (set 0) of a mesh being reduced, each with the area a reduction judges it by:
/// its largest `face_island_area` entry (the area of the original input island each face comes
/// from, in a multi-pass reduction) or, without one, its own 3D area. Two bounds read it:
///   * an island with an area of at least one output face must keep a face (issue 7); smaller
///     ones may vanish;
///   * the lines around an island below the crossing bound may merge through it (issue 32): the
///     island shrinks between its lines, which is how a budget below the lines' own count is met.
struct IslandAreas {
  UvIslands islands;          ///< find_uv_islands(mesh, conn, 0)
  std::vector<double> area;   ///< per island, as above
  /// True when there is nothing to decide: no UVs, or a per-face layout
  /// (FeatureParams::per_face_layout_fraction), which must lose islands to be reduced at all.
  bool exempt = true;
  /// Per face: 1 when it lies in an island whose area is positive and below `bound` (empty when
  /// exempt).
  std::vector<std::uint8_t> faces_below(double bound) const;
};
IslandAreas island_areas(const PolyMesh& mesh, const Connectivity& conn, const std::vector<double>* face_island_area,
                         double per_face_layout_fraction);

}  // namespace quadlod

namespace quadlod {

/// Exact UV island accounting of a reduction from its provenance (issue 7; docs/attributes.md,
/// "Island accounting"). `quadlod eval` has to guess which input island an output face belongs
/// to from geometry (docs/metrics.md §6c); the pipeline knows: every output face comes from one
/// input face. Islands are those of find_uv_islands with positive 3D area, as eval counts them.
/// An input island and an output island are *linked* when an output face of the output island
/// comes from an input face of the input island. Then, with deg = number of links,
///   vanished = input islands without links,
///   merged   = output islands with deg >= 2 (merged_reduction = Σ (deg − 1) over them),
///   split    = input islands with deg >= 2 (split_extra = Σ (deg − 1) over them),
///   appeared = output islands without links (from faces whose input island had no area),
/// and out = in − vanished + split_extra − merged_reduction + appeared holds by construction
/// (both sides count the links).
struct UvIslandAccount {
  Index in = 0, out = 0;
  Index vanished = 0, merged = 0, split = 0, appeared = 0;
  Index split_extra = 0, merged_reduction = 0;
  /// Vanished input islands whose 3D area is below one output face (`one_face_area`): too small
  /// to keep even one face (the "whole islands vanish below one face").
  Index vanished_below_one_face = 0;
  struct Vanished {
    Index island = 0;      ///< input island id (find_uv_islands numbering of the input)
    Index faces = 0;       ///< its input faces
    double area = 0.0;     ///< its 3D area
    double output_faces = 0.0;  ///< area / one_face_area: how many output faces it was worth
  };
  std::vector<Vanished> vanished_islands;
  /// Output islands with faces from several input islands, each with the input islands.
  std::vector<std::pair<Index, std::vector<Index>>> merged_islands;
  /// Input islands whose surviving faces lie in several output islands, each with those.
  std::vector<std::pair<Index, std::vector<Index>>> split_islands;
};

/// Precondition: face_origin.size() == output.num_faces(), each entry a face of `input` (or
/// kInvalidIndex: no origin), uv_set exists in both meshes. one_face_area: the area of "one
/// output face" (simplify passes input area / target tri-equivalents, the bound its collapse
/// protects islands from; <= 0: the output's mean face area).
UvIslandAccount account_uv_islands(const PolyMesh& input, const PolyMesh& output,
                                   const std::vector<Index>& face_origin, Index uv_set = 0,
                                   double one_face_area = 0.0);

}  // namespace quadlod
