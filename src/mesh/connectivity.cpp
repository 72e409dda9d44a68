#include "mesh/connectivity.h"

#include "mesh/union_find.h"

#include <algorithm>
#include <numeric>

namespace quadlod {

namespace {

// Counting sort of `keys` into CSR: offsets has n+1 entries, items lists the element ids in
// increasing order within each bucket.
void bucket(const std::vector<Index>& keys, Index n, std::vector<Index>& offsets,
            std::vector<Index>& items) {
  offsets.assign(std::size_t{n} + 1, 0);
  for (Index k : keys) ++offsets[k + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  items.resize(keys.size());
  std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
  for (Index i = 0; i < keys.size(); ++i) items[fill[keys[i]]++] = i;
}

}  // namespace

Connectivity build_connectivity(const PolyMesh& mesh) {
  Connectivity conn;
  const Index nv = mesh.num_vertices();
  const Index nf = mesh.num_faces();
  const Index nc = mesh.num_corners();
  conn.num_vertices = nv;
  conn.num_faces = nf;
  conn.corner_vertex = mesh.corner_vertex;

  conn.corner_face.resize(nc);
  conn.corner_next.resize(nc);
  conn.corner_prev.resize(nc);
  conn.face_degree.resize(nf);
  for (Index f = 0; f < nf; ++f) {
    const Index b = mesh.face_begin(f), e = mesh.face_end(f);
    conn.face_degree[f] = e - b;
    for (Index c = b; c < e; ++c) {
      conn.corner_face[c] = f;
      conn.corner_next[c] = c + 1 == e ? b : c + 1;
      conn.corner_prev[c] = c == b ? e - 1 : c - 1;
    }
  }

  bucket(mesh.corner_vertex, nv, conn.vertex_corner_offsets, conn.vertex_corners);

  // Edge ids: bucket each corner's edge by its smaller endpoint, then, within a bucket, give
  // each distinct larger endpoint one id. `last_seen[w]` remembers the edge id of (v, w) for the
  // bucket v being processed, so the scan is linear overall.
  std::vector<Index> low(nc);
  for (Index c = 0; c < nc; ++c)
    low[c] = std::min(mesh.corner_vertex[c], mesh.corner_vertex[conn.corner_next[c]]);
  std::vector<Index> low_offsets, low_items;
  bucket(low, nv, low_offsets, low_items);

  conn.corner_edge.assign(nc, kInvalidIndex);
  std::vector<Index> last_seen(nv, kInvalidIndex);
  std::vector<Index> last_bucket(nv, kInvalidIndex);
  for (Index v = 0; v < nv; ++v) {
    for (Index i = low_offsets[v]; i < low_offsets[v + 1]; ++i) {
      const Index c = low_items[i];
      const Index a = mesh.corner_vertex[c], b = mesh.corner_vertex[conn.corner_next[c]];
      const Index w = std::max(a, b);
      if (last_bucket[w] != v) {
        last_bucket[w] = v;
        last_seen[w] = conn.num_edges++;
        conn.edge_vertices.push_back({v, w});
      }
      conn.corner_edge[c] = last_seen[w];
    }
  }
  bucket(conn.corner_edge, conn.num_edges, conn.edge_corner_offsets, conn.edge_corners);
  return conn;
}

namespace {

// The boundary corner that follows boundary corner c on its loop. Rotating around the tip vertex
// through the faces of c's own fan finds the right one even at a bow-tie vertex, where several
// loops touch; when the fan cannot be walked (non-manifold edge, inconsistent orientation) the
// lowest unused outgoing boundary corner at the tip is taken.
Index next_boundary_corner(const Connectivity& conn, Index c, const std::vector<bool>& used) {
  const Index tip = conn.tip_vertex(c);
  Index n = conn.corner_next[c];
  for (std::size_t steps = conn.corners_at_vertex(tip).size(); steps-- > 0;) {
    if (conn.is_boundary_edge(conn.corner_edge[n])) return used[n] ? kInvalidIndex : n;
    const Index o = conn.across(n);
    if (o == kInvalidIndex) break;
    n = conn.corner_next[o];
    if (conn.corner_vertex[n] != tip) break;
  }
  for (Index d : conn.corners_at_vertex(tip))
    if (!used[d] && conn.is_boundary_edge(conn.corner_edge[d])) return d;
  return kInvalidIndex;
}

}  // namespace

std::vector<BoundaryLoop> boundary_loops(const Connectivity& conn) {
  const Index nc = static_cast<Index>(conn.corner_edge.size());
  std::vector<bool> used(nc, false);
  std::vector<BoundaryLoop> loops;
  for (Index start = 0; start < nc; ++start) {
    if (used[start] || !conn.is_boundary_edge(conn.corner_edge[start])) continue;
    BoundaryLoop loop;
    for (Index c = start; c != kInvalidIndex && !used[c];) {
      used[c] = true;
      loop.corners.push_back(c);
      c = next_boundary_corner(conn, c, used);
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

FaceComponents face_components(const Connectivity& conn) {
  UnionFind uf(conn.num_faces);
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto cs = conn.corners_of_edge(e);
    for (std::size_t i = 1; i < cs.size(); ++i)
      uf.unite(conn.corner_face[cs[0]], conn.corner_face[cs[i]]);
  }
  FaceComponents out;
  out.face_component = uf.dense_labels(out.count);
  return out;
}

std::vector<bool> nonmanifold_vertices(const Connectivity& conn) {
  std::vector<bool> flag(conn.num_vertices, false);
  // Mark endpoints of non-manifold edges.
  for (Index e = 0; e < conn.num_edges; ++e)
    if (conn.is_nonmanifold_edge(e)) {
      flag[conn.edge_vertices[e][0]] = true;
      flag[conn.edge_vertices[e][1]] = true;
    }
  // A fan check for the rest: the corners at v are joined when their faces share a manifold edge
  // incident to v. Corner c at v touches two edges at v: edge(c) and edge(prev(c)).
  for (Index v = 0; v < conn.num_vertices; ++v) {
    if (flag[v]) continue;
    const auto cs = conn.corners_at_vertex(v);
    if (cs.size() <= 1) continue;
    UnionFind uf(static_cast<Index>(cs.size()));
    // cs is sorted (bucket order), so a corner's slot is a binary search: no quadratic blow-up
    // at vertices with huge fans.
    auto slot = [&](Index corner) -> Index {
      const auto it = std::lower_bound(cs.begin(), cs.end(), corner);
      return it != cs.end() && *it == corner ? static_cast<Index>(it - cs.begin()) : kInvalidIndex;
    };
    for (Index i = 0; i < cs.size(); ++i) {
      const Index c = cs[i];
      // Neighbour across edge(c) sits at v in the other face: it is the corner *after* the
      // across-corner (edges run opposite ways in consistently oriented faces) or the across
      // corner itself (inconsistent orientation). Look for whichever of the two is at v.
      for (Index e_corner : {c, conn.corner_prev[c]}) {
        const Index e = conn.corner_edge[e_corner];
        if (conn.edge_face_count(e) != 2) continue;
        const auto pair = conn.corners_of_edge(e);
        const Index other = pair[0] == e_corner ? pair[1] : pair[0];
        for (Index cand : {other, conn.corner_next[other]}) {
          const Index j = slot(cand);
          if (j != kInvalidIndex) uf.unite(i, j);
        }
      }
    }
    Index roots = 0;
    for (Index i = 0; i < cs.size(); ++i)
      if (uf.find(i) == i) ++roots;
    if (roots > 1) flag[v] = true;
  }
  return flag;
}

}  // namespace quadlod
