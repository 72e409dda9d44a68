// Dual-graph repair, paper §3.3.1. See dual_repair.h for the picture and the steps.
#include "post/dual_repair.h"

#include "mesh/union_find.h"
#include "util/progress.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <queue>

namespace quadlod {

namespace {

struct Clusters {
  UnionFind uf;
  std::vector<Index> valence;  // per root: kept edges with one endpoint in the cluster
  explicit Clusters(Index n) : uf(n), valence(n, 0) {}
};

// Valence of a merged vertex = number of distinct clusters its kept edges lead to: two kept
// edges from one cluster to another merge into one output edge (e.g. where a collapsed row
// crosses a collapsed column, the quad at the crossing becomes a valence-4 vertex, not 8).
Clusters make_clusters(const Connectivity& conn, const std::vector<std::uint8_t>& kept) {
  Clusters c(conn.num_vertices);
  for (Index e = 0; e < conn.num_edges; ++e)
    if (!kept[e]) c.uf.unite(conn.edge_vertices[e][0], conn.edge_vertices[e][1]);
  // Distinct cluster pairs, linearly: the links bucketed by their smaller root, and a stamp per
  // larger root saying which bucket last counted it (a sort of all links was 2.5 % of a 250k-face
  // reduction).
  const Index nv = conn.num_vertices;
  std::vector<Index> offsets(std::size_t(nv) + 1, 0), stamp(nv, kInvalidIndex);
  auto link_of = [&](Index e, Index& a, Index& b) {
    if (kept[e]) {
      a = c.uf.find(conn.edge_vertices[e][0]);
      b = c.uf.find(conn.edge_vertices[e][1]);
      if (a > b) std::swap(a, b);
      return a != b;  // a kept edge inside a cluster degenerates; it bounds nothing
    }
    return false;
  };
  Index a = 0, b = 0;
  for (Index e = 0; e < conn.num_edges; ++e)
    if (link_of(e, a, b)) ++offsets[a + 1];
  for (Index v = 0; v < nv; ++v) offsets[v + 1] += offsets[v];
  std::vector<Index> larger(offsets[nv]), fill(offsets.begin(), offsets.end() - 1);
  for (Index e = 0; e < conn.num_edges; ++e)
    if (link_of(e, a, b)) larger[fill[a]++] = b;
  for (Index lo = 0; lo < nv; ++lo)
    for (Index i = offsets[lo]; i < offsets[lo + 1]; ++i) {
      const Index hi = larger[i];
      if (stamp[hi] == lo) continue;
      stamp[hi] = lo;
      ++c.valence[lo];
      ++c.valence[hi];
    }
  return c;
}

// The edges of face f.
template <class F>
void for_face_edges(const PolyMesh& mesh, const Connectivity& conn, Index f, F&& fn) {
  for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) fn(conn.corner_edge[c]);
}

class Repairer {
 public:
  static constexpr std::size_t kMaxStarts = 8;  // start faces tried per split
  static constexpr std::size_t kMaxEnds = 32;   // paths evaluated per start

  Repairer(const PolyMesh& mesh, const Connectivity& conn, const PolyChordResult& chords,
           std::vector<std::uint8_t>& kept, const DualRepairParams& params, DualRepairStats& stats)
      : mesh_(mesh), conn_(conn), chords_(chords), kept_(kept), params_(params), stats_(stats) {
    degree_.assign(conn.num_vertices, 0);
    for (const auto& [a, b] : conn.edge_vertices) {
      ++degree_[a];
      ++degree_[b];
    }
  }

  void run() {
    auto over = over_limit();
    stats_.super_faces_found = static_cast<Index>(over.size());
    if (over.empty()) return;
    if (params_.erode) erode(over);
    // Split rounds: each round splits every remaining super-face once. Every split turns at
    // least one collapsed edge into a kept one, so this ends; the round cap is a safety net.
    std::vector<std::uint8_t> given_up(conn_.num_vertices, 0);
    for (int round = 0; round < 256; ++round) {
      over = over_limit();
      bool changed = false;
      for (Index root : over) {
        if (given_up[root]) continue;
        if (split(root)) {
          ++stats_.splits;
          changed = true;
        } else {
          given_up[root] = 1;
          ++stats_.unsplittable;
        }
      }
      if (!changed) break;
    }
  }

  std::vector<Index> over_limit() {
    clusters_ = std::make_unique<Clusters>(make_clusters(conn_, kept_));
    limit_.assign(conn_.num_vertices, params_.max_valence);
    has_collapsed_.assign(conn_.num_vertices, 0);
    for (Index v = 0; v < conn_.num_vertices; ++v) {
      const Index r = clusters_->uf.find(v);
      limit_[r] = std::max(limit_[r], degree_[v]);
    }
    for (Index e = 0; e < conn_.num_edges; ++e)
      if (!kept_[e]) has_collapsed_[clusters_->uf.find(conn_.edge_vertices[e][0])] = 1;
    std::vector<Index> roots;
    for (Index v = 0; v < conn_.num_vertices; ++v) {
      const Index r = clusters_->uf.find(v);
      if (r == v && has_collapsed_[r] && clusters_->valence[r] > limit_[r]) roots.push_back(r);
    }
    return roots;
  }

 private:
  // All vertices of the cluster of `root`, found by a walk over collapsed edges.
  std::vector<Index> members(Index root) {
    std::vector<Index> out{root}, stack{root};
    std::vector<Index>& mark = visit_mark_;
    if (mark.size() != conn_.num_vertices) mark.assign(conn_.num_vertices, 0);
    ++stamp_;
    mark[root] = stamp_;
    while (!stack.empty()) {
      const Index v = stack.back();
      stack.pop_back();
      for (Index c : conn_.corners_at_vertex(v)) {
        // Both edges of the corner touch v: its own edge and the previous corner's edge.
        for (Index e : {conn_.corner_edge[c], conn_.corner_edge[conn_.corner_prev[c]]}) {
          if (kept_[e]) continue;
          const Index w = conn_.other_vertex(e, v);
          if (mark[w] == stamp_) continue;
          mark[w] = stamp_;
          out.push_back(w);
          stack.push_back(w);
        }
      }
    }
    return out;
  }

  std::vector<Index> faces_of(const std::vector<Index>& verts) {
    std::vector<Index> faces;
    for (Index v : verts)
      for (Index c : conn_.corners_at_vertex(v)) faces.push_back(conn_.corner_face[c]);
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    return faces;
  }

  Index kept_count(Index f) const {
    Index k = 0;
    for_face_edges(mesh_, conn_, f, [&](Index e) { k += kept_[e]; });
    return k;
  }

  // Step 1: a face of a super-face with exactly one kept edge gets it collapsed.
  void erode(const std::vector<Index>& roots) {
    for (Index root : roots) {
      for (Index f : faces_of(members(root))) {
        if (kept_count(f) != 1) continue;
        for_face_edges(mesh_, conn_, f, [&](Index e) {
          if (kept_[e] && !conn_.is_nonmanifold_edge(e)) {
            kept_[e] = 0;
            ++stats_.eroded_edges;
          }
        });
      }
    }
  }

  // Step 2: one split of the super-face of `root`. Returns false if no split improves it.
  bool split(Index root) {
    const std::vector<Index> verts = members(root);
    const std::vector<Index> faces = faces_of(verts);
    auto in_cluster = [&](Index v) { return clusters_->uf.find(v) == root; };
    // Boundary dual vertices: faces with a kept edge leaving the cluster.
    auto is_boundary = [&](Index f) {
      bool b = false;
      for_face_edges(mesh_, conn_, f, [&](Index e) {
        if (!kept_[e]) return;
        const bool a_in = in_cluster(conn_.edge_vertices[e][0]), b_in = in_cluster(conn_.edge_vertices[e][1]);
        b |= a_in != b_in;
      });
      return b;
    };
    // Interior dual edges of face f: its collapsed manifold edges inside the cluster.
    auto interior_edges = [&](Index f, auto&& fn) {
      for_face_edges(mesh_, conn_, f, [&](Index e) {
        if (kept_[e] || conn_.edge_face_count(e) != 2 || !in_cluster(conn_.edge_vertices[e][0])) return;
        const auto cs = conn_.corners_of_edge(e);
        fn(e, conn_.corner_face[cs[0]] == f ? conn_.corner_face[cs[1]] : conn_.corner_face[cs[0]]);
      });
    };
    // Start faces: boundary faces that reach into the super-face, highest valence first (the
    // paper's v*_begin; the next ones are tried when the first cannot split it).
    std::vector<std::pair<Index, Index>> starts;  // (−valence, face)
    for (Index f : faces) {
      bool inward = false;
      interior_edges(f, [&](Index, Index) { inward = true; });
      if (inward && is_boundary(f)) starts.push_back({kept_count(f), f});
    }
    std::sort(starts.begin(), starts.end(), [](const auto& a, const auto& b) {
      return a.first > b.first || (a.first == b.first && a.second < b.second);
    });
    if (starts.size() > kMaxStarts) starts.resize(kMaxStarts);

    const std::size_t n = faces.size();
    auto local = [&](Index f) {
      return static_cast<std::size_t>(std::lower_bound(faces.begin(), faces.end(), f) - faces.begin());
    };
    const Index current = clusters_->valence[root];
    Index best_score = current;
    double best_cost = std::numeric_limits<double>::infinity();
    std::vector<Index> best_path;
    std::vector<double> dist(n);
    std::vector<Index> via_edge(n), via_face(n);
    for (const auto& [valence, begin] : starts) {
      // Dijkstra over the star's faces through interior dual edges; the arrival edge of a face
      // decides the loop-change penalty of the next step.
      std::fill(dist.begin(), dist.end(), std::numeric_limits<double>::infinity());
      std::fill(via_edge.begin(), via_edge.end(), kInvalidIndex);
      std::fill(via_face.begin(), via_face.end(), kInvalidIndex);
      using Item = std::pair<double, Index>;
      std::priority_queue<Item, std::vector<Item>, std::greater<>> heap;
      dist[local(begin)] = 0.0;
      heap.push({0.0, begin});
      std::vector<Index> ends;
      while (!heap.empty() && ends.size() < kMaxEnds) {
        // Plain variables, not a structured binding: the lambda below captures them, which
        // clang before 16 (the fuzz tree's clang-15) refuses for bindings.
        const double d = heap.top().first;
        const Index f = heap.top().second;
        heap.pop();
        const std::size_t lf = local(f);
        if (d > dist[lf]) continue;
        if (f != begin && is_boundary(f)) {
          ends.push_back(f);  // a path ends at the first boundary face it meets
          continue;
        }
        interior_edges(f, [&](Index e, Index g) {
          const std::size_t lg = local(g);
          if (lg >= n || faces[lg] != g) return;
          double step = 1.0;
          const Index prev = via_edge[lf];
          if (prev != kInvalidIndex && chords_.edge_chord[prev] != chords_.edge_chord[e])
            step += params_.loop_change_penalty;
          if (d + step < dist[lg]) {
            dist[lg] = d + step;
            via_edge[lg] = e;
            via_face[lg] = f;
            heap.push({d + step, g});
          }
        });
      }
      // The path whose split leaves the smallest larger half wins; then the cheapest path.
      for (Index end : ends) {
        std::vector<Index> path;
        for (Index f = end; f != begin; f = via_face[local(f)]) path.push_back(via_edge[local(f)]);
        const Index score = split_score(verts, path);
        const double cost = dist[local(end)];
        if (score < current && (score < best_score || (score == best_score && cost < best_cost))) {
          best_score = score;
          best_cost = cost;
          best_path = std::move(path);
        }
      }
      (void)valence;
    }
    if (best_path.empty()) return false;
    for (Index e : best_path) {
      kept_[e] = 1;
      ++stats_.restored_edges;
    }
    return true;
  }

  // Max valence of the parts the cluster falls into when `path` edges are kept; the current
  // valence if it does not fall apart.
  Index split_score(const std::vector<Index>& verts, const std::vector<Index>& path) {
    for (Index e : path) kept_[e] = 1;
    // Local union-find over the members.
    std::vector<Index> sorted = verts;
    std::sort(sorted.begin(), sorted.end());
    auto id = [&](Index v) -> Index {
      const auto it = std::lower_bound(sorted.begin(), sorted.end(), v);
      return it != sorted.end() && *it == v ? static_cast<Index>(it - sorted.begin()) : kInvalidIndex;
    };
    UnionFind uf(static_cast<Index>(sorted.size()));
    std::vector<Index> edges;
    for (Index v : sorted)
      for (Index c : conn_.corners_at_vertex(v))
        for (Index e : {conn_.corner_edge[c], conn_.corner_edge[conn_.corner_prev[c]]}) edges.push_back(e);
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (Index e : edges)
      if (!kept_[e]) {
        const Index a = id(conn_.edge_vertices[e][0]), b = id(conn_.edge_vertices[e][1]);
        if (a != kInvalidIndex && b != kInvalidIndex) uf.unite(a, b);
      }
    // Distinct (part, neighbour) links; neighbours outside the cluster are named by their
    // cluster root, offset past the local part ids.
    Index parts = 0;
    for (Index i = 0; i < sorted.size(); ++i) parts += uf.find(i) == i;
    const Index outside = static_cast<Index>(sorted.size());
    std::vector<std::pair<Index, Index>> links;
    for (Index e : edges) {
      if (!kept_[e]) continue;
      const Index a = id(conn_.edge_vertices[e][0]), b = id(conn_.edge_vertices[e][1]);
      const Index ra = a == kInvalidIndex ? outside + clusters_->uf.find(conn_.edge_vertices[e][0]) : uf.find(a);
      const Index rb = b == kInvalidIndex ? outside + clusters_->uf.find(conn_.edge_vertices[e][1]) : uf.find(b);
      if (ra == rb) continue;
      if (ra < outside) links.emplace_back(ra, rb);
      if (rb < outside) links.emplace_back(rb, ra);
    }
    std::sort(links.begin(), links.end());
    links.erase(std::unique(links.begin(), links.end()), links.end());
    std::vector<Index> valence(sorted.size(), 0);
    for (const auto& link : links) ++valence[link.first];
    for (Index e : path) kept_[e] = 0;
    if (parts < 2) return clusters_->valence[clusters_->uf.find(verts[0])];
    return *std::max_element(valence.begin(), valence.end());
  }

  const PolyMesh& mesh_;
  const Connectivity& conn_;
  const PolyChordResult& chords_;
  std::vector<std::uint8_t>& kept_;
  const DualRepairParams& params_;
  DualRepairStats& stats_;
  std::vector<Index> degree_;
  std::unique_ptr<Clusters> clusters_;
  std::vector<Index> limit_;
  std::vector<std::uint8_t> has_collapsed_;
  std::vector<Index> visit_mark_;
  Index stamp_ = 0;
};

Index max_cluster_valence(const Connectivity& conn, const std::vector<std::uint8_t>& kept) {
  const Clusters c = make_clusters(conn, kept);
  Index m = 0;
  for (Index v : c.valence) m = std::max(m, v);
  return m;
}

}  // namespace

std::vector<Index> cluster_valences(const Connectivity& conn, const std::vector<std::uint8_t>& edge_kept) {
  Clusters c = make_clusters(conn, edge_kept);
  std::vector<Index> out(conn.num_vertices);
  for (Index v = 0; v < conn.num_vertices; ++v) out[v] = c.valence[c.uf.find(v)];
  return out;
}

DualRepairResult repair_dual_graph(const PolyMesh& mesh, const Connectivity& conn,
                                   const PolyChordResult& chords,
                                   const std::vector<std::uint8_t>& edge_kept,
                                   const DualRepairParams& params) {
  Stopwatch clock;
  DualRepairResult result;
  result.edge_kept = edge_kept;
  result.stats.max_valence_before = max_cluster_valence(conn, edge_kept);
  if (params.enable) {
    Repairer repairer(mesh, conn, chords, result.edge_kept, params, result.stats);
    repairer.run();
    result.stats.super_faces_left = static_cast<Index>(repairer.over_limit().size());
  }
  result.stats.max_valence_after = max_cluster_valence(conn, result.edge_kept);
  result.seconds = clock.seconds();
  return result;
}

}  // namespace quadlod
