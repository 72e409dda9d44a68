// quadlod — quads recovered from a triangulated input (quad_recovery.h).
#include "mesh/quad_recovery.h"

#include "mesh/connectivity.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

namespace quadlod {

namespace {

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

bool same_tag(const std::vector<Index>& tag, Index f, Index g) { return tag.empty() || tag[f] == tag[g]; }

// Every per-corner attribute of corners c and d is the same (so the joined quad's corner can take
// either's).
bool same_corner(const PolyMesh& m, Index c, Index d) {
  for (const UvSet& set : m.uv_sets)
    if (set.corner[c] != set.corner[d]) return false;
  return m.corner_normal.empty() || m.corner_normal[c] == m.corner_normal[d];
}

struct Pair {
  double score;
  Index edge;
  Index first, second;  // the corners of the shared edge in the two triangles
};

}  // namespace

bool all_triangles(const PolyMesh& mesh) {
  if (mesh.num_faces() == 0) return false;
  for (Index f = 0; f < mesh.num_faces(); ++f)
    if (mesh.face_size(f) != 3) return false;
  return true;
}

QuadRecoveryResult recover_quads(const PolyMesh& mesh, const QuadRecoveryParams& params) {
  QuadRecoveryResult result;
  const Connectivity conn = build_connectivity(mesh);
  const auto& p = mesh.positions;

  // Triangles A (corner c1 at a, edge a→b) and B (corner c2 at b, edge b→a) make the quad
  // (b, c, a, d): A's corners next(c1), prev(c1), c1, then B's prev(c2).
  auto quad_corners = [&](Index c1, Index c2) {
    return std::array<Index, 4>{conn.corner_next[c1], conn.corner_prev[c1], c1, conn.corner_prev[c2]};
  };

  std::vector<Pair> pairs;
  for (Index e = 0; e < conn.num_edges; ++e) {
    if (conn.edge_face_count(e) != 2) continue;
    const auto cs = conn.corners_of_edge(e);
    const Index c1 = cs[0], c2 = cs[1];
    const Index fa = conn.corner_face[c1], fb = conn.corner_face[c2];
    if (fa == fb || conn.face_degree[fa] != 3 || conn.face_degree[fb] != 3) continue;
    // Oriented alike: the edge runs a→b in one and b→a in the other.
    if (conn.corner_vertex[c1] != conn.tip_vertex(c2) || conn.corner_vertex[c2] != conn.tip_vertex(c1)) continue;
    if (!same_corner(mesh, c1, conn.corner_next[c2]) || !same_corner(mesh, conn.corner_next[c1], c2)) continue;
    if (!same_tag(mesh.face_material, fa, fb) || !same_tag(mesh.face_object, fa, fb) ||
        !same_tag(mesh.face_group, fa, fb) || !same_tag(mesh.face_smoothing, fa, fb))
      continue;
    const auto q = quad_corners(c1, c2);
    Index v[4];
    for (int k = 0; k < 4; ++k) v[k] = conn.corner_vertex[q[k]];
    if (v[1] == v[3] || v[0] == v[2]) continue;
    const Vec3 na = face_area_vector(mesh, fa), nb = face_area_vector(mesh, fb);
    if (!(na.squaredNorm() > 0.0) || !(nb.squaredNorm() > 0.0)) continue;
    const double fold = angle_deg(na, nb);
    if (fold > params.max_fold_deg) continue;
    // Convex, and every corner within max_corner_deviation_deg of a right angle.
    const Vec3 n = na.normalized() + nb.normalized();
    double deviation = 0.0;
    bool convex = true;
    for (int k = 0; k < 4 && convex; ++k) {
      const Vec3 in = p[v[(k + 3) % 4]] - p[v[k]], out = p[v[(k + 1) % 4]] - p[v[k]];
      if (!(out.cross(in).dot(n) > 0.0)) convex = false;
      deviation = std::max(deviation, std::abs(angle_deg(out, in) - 90.0));
    }
    if (!convex || deviation > params.max_corner_deviation_deg) continue;
    pairs.push_back({deviation + fold, e, c1, c2});
  }
  result.candidates = static_cast<Index>(pairs.size());
  std::sort(pairs.begin(), pairs.end(),
            [](const Pair& x, const Pair& y) { return std::tie(x.score, x.edge) < std::tie(y.score, y.edge); });

  // Best first, each triangle in one quad at most; a quad goes where its first triangle was.
  enum Role : char { kAlone, kQuad, kAbsorbed };
  std::vector<Role> role(mesh.num_faces(), kAlone);
  std::vector<std::array<Index, 4>> quad_of(mesh.num_faces());
  for (const Pair& pr : pairs) {
    const Index fa = conn.corner_face[pr.first], fb = conn.corner_face[pr.second];
    if (role[fa] != kAlone || role[fb] != kAlone) continue;
    role[std::min(fa, fb)] = kQuad;
    role[std::max(fa, fb)] = kAbsorbed;
    quad_of[std::min(fa, fb)] = quad_corners(pr.first, pr.second);
    ++result.joined;
  }

  // The output: every corner's attributes carried by its input corner, per-face tags by the face
  // the output face stands at (the quad's two triangles have the same tags).
  std::vector<Index> src_corner, src_face, offsets{0};
  src_corner.reserve(mesh.num_corners());
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    if (role[f] == kAbsorbed) continue;
    if (role[f] == kQuad)
      src_corner.insert(src_corner.end(), quad_of[f].begin(), quad_of[f].end());
    else
      for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) src_corner.push_back(c);
    src_face.push_back(f);
    offsets.push_back(static_cast<Index>(src_corner.size()));
  }
  PolyMesh& out = result.mesh;
  out = mesh;
  out.face_offsets = std::move(offsets);
  out.corner_vertex.resize(src_corner.size());
  for (std::size_t i = 0; i < src_corner.size(); ++i) out.corner_vertex[i] = mesh.corner_vertex[src_corner[i]];
  for (std::size_t s = 0; s < mesh.uv_sets.size(); ++s) {
    out.uv_sets[s].corner.resize(src_corner.size());
    for (std::size_t i = 0; i < src_corner.size(); ++i) out.uv_sets[s].corner[i] = mesh.uv_sets[s].corner[src_corner[i]];
  }
  if (!mesh.corner_normal.empty()) {
    out.corner_normal.resize(src_corner.size());
    for (std::size_t i = 0; i < src_corner.size(); ++i) out.corner_normal[i] = mesh.corner_normal[src_corner[i]];
  }
  for (auto tag : {&PolyMesh::face_object, &PolyMesh::face_group, &PolyMesh::face_material, &PolyMesh::face_smoothing}) {
    if ((mesh.*tag).empty()) continue;
    (out.*tag).resize(src_face.size());
    for (std::size_t i = 0; i < src_face.size(); ++i) (out.*tag)[i] = (mesh.*tag)[src_face[i]];
  }
  return result;
}

}  // namespace quadlod
