// Joint-influence borders (issue 24): see skin_borders.h. Like the strict feature pins of
// src/pipeline/simplify.cpp (issue 7), they enter the selection as edges it must keep, so a
// cluster cannot be formed across one; the collapse then never blends the weights of two
// unrelated bones into one vertex, which would tear or glue the surface once they move apart.
#include "skin/skin_borders.h"

#include "quadlod/skin.h"

namespace quadlod {

SkinBorders find_skin_borders(const PolyMesh& mesh, const Connectivity& conn, const SkinBorderParams& params) {
  SkinBorders out;
  out.edge_border.assign(conn.num_edges, 0);
  const SkinWeights& skin = mesh.skin;
  auto dominant = [&](Index v) { return skin.influences(v) ? skin.joint[skin.offsets[v]] : kInvalidIndex; };
  auto parent = [&](Index j) { return j < params.joint_parents.size() ? params.joint_parents[j] : kInvalidIndex; };
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    if (a == b || skin.influences(a) == 0 || skin.influences(b) == 0) continue;
    if (weight_distance(skin, a, skin, b) <= params.max_weight_distance) continue;
    const Index ja = dominant(a), jb = dominant(b);
    if (ja == jb || parent(ja) == jb || parent(jb) == ja) {
      ++out.related_edges;
      continue;
    }
    out.edge_border[e] = 1;
    ++out.border_edges;
  }
  return out;
}

}  // namespace quadlod
