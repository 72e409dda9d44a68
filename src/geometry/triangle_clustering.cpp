// Triangle-region clustering (paper §3.2.4; QEM after Garland & Heckbert 1997). Contract:
// triangle_clustering.h.
//
// Vertex classes (union-find over mesh vertices) stand for the vertices of the simulated
// decimation; an edge is alive while its endpoints are in different classes. Collapsing ⟨a, b⟩:
//
//          u                           u
//         ╱ ╲                          │╲        ⟨u,a⟩ and ⟨u,b⟩ become parallel edges
//        ╱   ╲                         │ ╲       between u and r; both stay alive (clusters of
//       a ──e─ b      ⇒               r  (par)   their own); collapsing one of them later turns
//        ╲   ╱                         │ ╱       the other into a loop, removed with it.
//         ╲ ╱                          │╱
//          w                           w
//   C_t(e) joins the cluster of the alive edge at r whose centre is nearest e's centre.
#include "geometry/triangle_clustering.h"

#include "geometry/quadric.h"
#include "mesh/union_find.h"

#include <algorithm>
#include <array>
#include <deque>
#include <queue>

namespace quadlod {

namespace {

struct Entry {
  double cost;
  Index edge;
  Index version;
  bool operator>(const Entry& o) const { return cost != o.cost ? cost > o.cost : edge > o.edge; }
};

}  // namespace

TriangleClusteringResult cluster_triangle_regions(const PolyMesh& mesh, const Connectivity& conn,
                                                  const TriangleClusteringParams& params) {
  TriangleClusteringResult out;
  const Index nf = conn.num_faces, ne = conn.num_edges, nv = conn.num_vertices;
  out.edge_cluster.assign(ne, kInvalidIndex);
  out.edge_region.assign(ne, kInvalidIndex);
  const double diag = bounding_box(mesh).diagonal();
  out.epsilon_tri = params.epsilon_tri_relative * diag * diag;

  // 1. Regions: the connected components of the graph of edges that border a triangle (edges
  //    joined by a shared vertex), found by a breadth-first search over those edges.
  std::vector<std::uint8_t> borders(ne, 0);
  for (Index f = 0; f < nf; ++f) {
    if (conn.face_degree[f] != 3) continue;
    ++out.stats.num_triangles;
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) borders[conn.corner_edge[c]] = 1;
  }
  std::deque<Index> queue;
  std::vector<std::uint8_t> vertex_done(nv, 0);  // its corners scanned once: linear time
  for (Index e0 = 0; e0 < ne; ++e0) {
    if (!borders[e0] || out.edge_region[e0] != kInvalidIndex) continue;
    const Index region = out.stats.num_regions++;
    out.edge_region[e0] = region;
    queue.push_back(e0);
    while (!queue.empty()) {
      const Index e = queue.front();
      queue.pop_front();
      for (Index v : conn.edge_vertices[e]) {
        if (vertex_done[v]) continue;
        vertex_done[v] = 1;
        for (Index c : conn.corners_at_vertex(v))
          for (Index g : {conn.corner_edge[c], conn.corner_edge[conn.corner_prev[c]]})
            if (borders[g] && out.edge_region[g] == kInvalidIndex) {
              out.edge_region[g] = region;
              queue.push_back(g);
            }
      }
    }
  }

  // 2. Local edges (in mesh edge order) and the vertices they touch.
  std::vector<Index> edges;  // local edge → mesh edge
  std::vector<Index> vertex_local(nv, kInvalidIndex);
  std::vector<Index> vertices;  // local vertex → mesh vertex
  for (Index e = 0; e < ne; ++e) {
    if (out.edge_region[e] == kInvalidIndex) continue;
    edges.push_back(e);
    for (Index v : conn.edge_vertices[e])
      if (vertex_local[v] == kInvalidIndex) {
        vertex_local[v] = static_cast<Index>(vertices.size());
        vertices.push_back(v);
      }
  }
  const Index n_edges = static_cast<Index>(edges.size());
  const Index n_verts = static_cast<Index>(vertices.size());
  out.stats.num_region_edges = n_edges;

  // 3. Vertex quadrics: unweighted planes of all incident faces.
  std::vector<Quadric> quadric(n_verts);
  std::vector<Vec3> pos(n_verts);
  for (Index i = 0; i < n_verts; ++i) {
    const Index v = vertices[i];
    pos[i] = mesh.positions[v];
    for (Index c : conn.corners_at_vertex(v)) {
      const Index f = conn.corner_face[c];
      const Vec3 n = face_normal(mesh, f);
      if (n.squaredNorm() > 0.0) quadric[i] += Quadric::plane(face_centroid(mesh, f), n);
    }
  }

  std::vector<std::array<Index, 2>> ends(n_edges);
  std::vector<std::vector<Index>> incident(n_verts);
  for (Index k = 0; k < n_edges; ++k) {
    const auto& ev = conn.edge_vertices[edges[k]];
    ends[k] = {vertex_local[ev[0]], vertex_local[ev[1]]};
    incident[ends[k][0]].push_back(k);
    if (ends[k][1] != ends[k][0]) incident[ends[k][1]].push_back(k);
  }

  // 4. Greedy collapse.
  UnionFind vclass(n_verts);  // vertex classes; the root's pos/quadric/incident are current
  UnionFind cluster(n_edges);
  std::vector<std::uint8_t> alive(n_edges, 1);
  std::vector<Index> version(n_edges, 0);
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  auto collapse_point = [&](Index k) {
    const Index a = vclass.find(ends[k][0]), b = vclass.find(ends[k][1]);
    return (quadric[a] + quadric[b]).minimize_on_segment(pos[a], pos[b]);
  };
  auto centre = [&](Index k) { return 0.5 * (pos[vclass.find(ends[k][0])] + pos[vclass.find(ends[k][1])]); };
  auto push = [&](Index k) {
    ++version[k];
    heap.push({collapse_point(k).error, k, version[k]});
  };
  for (Index k = 0; k < n_edges; ++k) {
    if (ends[k][0] == ends[k][1]) {
      alive[k] = 0;  // a degenerate edge (face repeating a vertex): a cluster of its own
      continue;
    }
    push(k);
  }

  std::vector<Index> loops, others;
  while (!heap.empty()) {
    const Entry top = heap.top();
    heap.pop();
    const Index k = top.edge;
    if (!alive[k] || top.version != version[k]) continue;
    if (top.cost > out.epsilon_tri) break;
    const Index a = vclass.find(ends[k][0]), b = vclass.find(ends[k][1]);
    auto other_end = [&](Index j, Index r) {
      const Index x = vclass.find(ends[j][0]);
      return x == r ? vclass.find(ends[j][1]) : x;
    };
    // Alive edges at a or b after the merge: loops (other end in {a, b}) go with k.
    loops.clear();
    others.clear();
    for (Index r : {a, b})
      for (Index j : incident[r]) {
        if (!alive[j] || j == k) continue;
        const Index o = other_end(j, r);
        if (o == a || o == b) {
          if (std::find(loops.begin(), loops.end(), j) == loops.end()) loops.push_back(j);
        } else {
          others.push_back(j);
        }
      }
    if (others.empty()) {
      ++out.stats.rejected_no_neighbour;
      continue;
    }
    // Cluster merges, with centres taken before the vertex moves.
    loops.push_back(k);
    for (Index j : loops) {
      const Vec3 cj = centre(j);
      Index best = others.front();
      double best_d = (centre(best) - cj).squaredNorm();
      for (Index o : others) {
        const double d = (centre(o) - cj).squaredNorm();
        if (d < best_d || (d == best_d && o < best)) {
          best = o;
          best_d = d;
        }
      }
      cluster.unite(best, j);
      alive[j] = 0;
    }
    out.stats.num_collapses += 1;
    out.stats.num_loop_collapses += static_cast<Index>(loops.size()) - 1;

    // Merge the vertex classes.
    const Quadric::Minimum x = collapse_point(k);
    const Index r = vclass.unite(a, b);
    const Index gone = r == a ? b : a;
    pos[r] = x.point;
    quadric[r] = quadric[a] + quadric[b];
    std::vector<Index>& list = incident[r];
    std::vector<Index>& other_list = incident[gone];
    list.insert(list.end(), other_list.begin(), other_list.end());
    std::vector<Index>().swap(other_list);
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    list.erase(std::remove_if(list.begin(), list.end(), [&](Index j) { return !alive[j]; }), list.end());
    for (Index j : list) push(j);
  }

  // 5. Clusters in mesh edge order.
  std::vector<Index> root_cluster(n_edges, kInvalidIndex);
  for (Index k = 0; k < n_edges; ++k) {
    const Index root = cluster.find(k);
    if (root_cluster[root] == kInvalidIndex) {
      root_cluster[root] = static_cast<Index>(out.clusters.size());
      out.clusters.push_back({{}, out.edge_region[edges[k]]});
    }
    const Index id = root_cluster[root];
    out.clusters[id].edges.push_back(edges[k]);
    out.edge_cluster[edges[k]] = id;
    if (alive[k] || out.clusters[id].representative == kInvalidIndex) out.clusters[id].representative = edges[k];
  }
  for (const TriangleCluster& c : out.clusters)
    out.stats.largest_cluster = std::max(out.stats.largest_cluster, static_cast<Index>(c.edges.size()));

  // 6. Neighbours: clusters sharing a vertex.
  std::vector<Index> at_vertex;
  for (Index v : vertices) {
    at_vertex.clear();
    for (Index c : conn.corners_at_vertex(v))
      for (Index e : {conn.corner_edge[c], conn.corner_edge[conn.corner_prev[c]]})
        if (out.edge_cluster[e] != kInvalidIndex) at_vertex.push_back(out.edge_cluster[e]);
    std::sort(at_vertex.begin(), at_vertex.end());
    at_vertex.erase(std::unique(at_vertex.begin(), at_vertex.end()), at_vertex.end());
    for (std::size_t i = 0; i < at_vertex.size(); ++i)
      for (std::size_t j = i + 1; j < at_vertex.size(); ++j) {
        out.neighbours.emplace_back(at_vertex[i], at_vertex[j]);
        out.neighbours.emplace_back(at_vertex[j], at_vertex[i]);
      }
  }
  std::sort(out.neighbours.begin(), out.neighbours.end());
  out.neighbours.erase(std::unique(out.neighbours.begin(), out.neighbours.end()), out.neighbours.end());
  return out;
}

}  // namespace quadlod
