// Protected regions (issue 34; docs/protect.md): one weight per input vertex in [0, 1] that says
// how much the reduction must leave the vertex alone.
//
//   * weight 1: the vertex keeps its exact input position (bit-exact in the output, through every
//     pass and the surface fit) and every edge between two weight-1 vertices stays. A weight-1
//     vertex may absorb unprotected neighbours (the merged vertex lands on it, a half-edge
//     collapse), but never another weight-1 vertex.
//   * 0 < w < 1: collapses that move the vertex cost more (SimplifyOptions::protect_strength for
//     the shape objective, protect_importance for the paper objective).
//   * 0: no protection, as without weights.
// When vertices merge, the merged vertex takes the largest weight among them (the most protected
// member wins: a weight-1 member is where the merged vertex sits).
//
// Where weights come from: SimplifyOptions::protect_weights (the CLI's --protect FILE, Python's
// protect=, the Blender add-on's vertex group), or a vertex colour channel
// (SimplifyOptions::protect_channel: OBJ `v x y z r g b`, glTF COLOR_0 / FBX colour set 0
// through assimp; the CLI's --protect-from color:r).
#pragma once

#include "quadlod/mesh.h"
#include "quadlod/simplify.h"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace quadlod {

/// "none", "color:r", "color:g", "color:b" (SimplifyOptions::ProtectChannel).
std::optional<SimplifyOptions::ProtectChannel> parse_protect_channel(const std::string& name);
const char* to_string(SimplifyOptions::ProtectChannel channel);
std::vector<std::pair<std::string, SimplifyOptions::ProtectChannel>> protect_channel_names();

struct ProtectWeightsRead {
  std::vector<double> weights;  ///< one per vertex, in file order
  std::string error;            ///< one line naming the file (and line): "w.txt:7: ..."
  bool ok() const { return error.empty(); }
};

/// Reads a protect file: one weight per vertex, the i-th weight line is vertex i (0-based). A
/// weight line holds one decimal number in [0, 1] and nothing else (spaces around it allowed).
/// Blank lines and lines whose first non-blank character is '#' are comments: they are skipped
/// and do not count as vertices (so a file may carry a header). `expected_vertices` > 0: the file
/// must hold exactly that many weights. Errors, one line each: an unreadable file, a line that is
/// not a number ("w.txt:7: 'abc' is not a number"), a value outside [0, 1] ("w.txt:7: weight 1.5
/// is outside [0, 1]"), too many weights ("w.txt:13: weight for vertex 12, the mesh has 12
/// vertices"), too few ("w.txt: 11 weights, the mesh has 12 vertices").
ProtectWeightsRead read_protect_weights(const std::string& path, std::size_t expected_vertices = 0);

/// The weights of `mesh`'s vertices from one colour channel (each value clamped to [0, 1]);
/// empty when the mesh has no vertex colours or `channel` is None.
std::vector<double> protect_weights_from_colors(const PolyMesh& mesh, SimplifyOptions::ProtectChannel channel);

/// "" when `weights` is empty or holds one finite value in [0, 1] per vertex of a mesh of
/// `vertices` vertices; else the first problem ("protect weight of vertex 3 is 1.5, outside [0, 1]").
std::string check_protect_weights(const std::vector<double>& weights, Index vertices);

/// Splits weights over the meshes of a scene, in mesh order (mesh m gets the next `sizes[m]`):
/// the per-mesh weights, or an error naming the counts when the total differs.
std::string split_protect_weights(const std::vector<double>& weights, const std::vector<Index>& sizes,
                                  std::vector<std::vector<double>>& per_mesh);

}  // namespace quadlod
