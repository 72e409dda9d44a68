// Shape-first edge selection: a lazy greedy over segment collapses (paper §3.2.2, Eq. 4 units)
// priced by the geometric error of the clusters they create (§3.3.2 quadrics and placement,
// Knodt 2025 per-edge planes) and by the shape of the quads around them.
//
//   before                     after collapsing segment s (its opposing edges ┃)
//   ──●────●────●────●──        ──●─────────●────●──
//     │    ┃    │    │            │         │    │      the two rows of vertices along ┃ merge
//   ──●────●────●────●──        ──●─────────●────●──    pairwise; each merged pair is a cluster
//     │    ┃    │    │            │         │    │      placed at its quadric's minimiser; the
//   ──●────●────●────●──        ──●─────────●────●──    quads beside s get wider (shape term)
//
// The incremental state keeps, per cluster root, the summed quadric terms, the placed position
// and its error; per face, its kept edges (Eq. 1 counts the face as max(0, kept − 2)).
#include "select/shape_selection.h"

#include "mesh/symmetry.h"
#include "mesh/union_find.h"
#include "select/groups.h"
#include "util/parallel.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <queue>
#include <span>
#include <atomic>
#include <mutex>

namespace quadlod {

namespace {

// Decision units: the groups of the fast formulation (select/groups.h) — the opposing edges of
// a segment joined through shared non-manifold edges, every other edge on its own — with the
// groups that hold a pinned edge fixed.
struct Units {
  select_detail::Groups g;
  Index count() const { return g.count; }
  std::span<const Index> of(Index u) const {
    return {g.edges.data() + g.offsets[u], std::size_t(g.offsets[u + 1] - g.offsets[u])};
  }
};

Units make_units(const Connectivity& conn, const AnalysisResult& analysis, const ShapeSelectionParams& params,
                 const std::vector<std::uint8_t>& pinned) {
  SelectionParams grouping;
  grouping.consistency = params.consistency;
  grouping.keep_nonmanifold_edges = false;  // already in `pinned`
  grouping.keep_edges = pinned;
  return {select_detail::make_groups(conn, analysis, std::vector<double>(conn.num_edges, 0.0), grouping)};
}

// Pinned edges: the caller's keep list and (optionally) non-manifold edges.
std::vector<std::uint8_t> pinned_edges(const Connectivity& conn, const ShapeSelectionParams& params) {
  std::vector<std::uint8_t> pinned(conn.num_edges, 0);
  for (Index e = 0; e < conn.num_edges; ++e) {
    if (params.keep_nonmanifold_edges && conn.is_nonmanifold_edge(e)) pinned[e] = 1;
    if (!params.keep_edges.empty() && params.keep_edges[e]) pinned[e] = 1;
    const auto [a, b] = conn.edge_vertices[e];
    if (a == b) pinned[e] = 1;
  }
  return pinned;
}

// What collapsing a set of kept edges would change.
struct Move {
  std::int64_t reduced = 0;  // triangle-equivalents removed (Eq. 1)
  double error = 0.0;        // Δ Σ cluster errors (raw units)
  double shape = 0.0;        // Δ Σ quad-shape penalties (raw units, before λ_shape)
  bool valid = true;         // no face around the move flips or degenerates
  std::int64_t triangles_made = 0;  // faces left with three kept edges (quads or n-gons before)
  // The largest mean squared distance of a cluster's face planes to its vertex (face-plane
  // weight = area) among the clusters the move makes (evaluate) or dissolves (uncollapse): the
  // local deviation a Hausdorff distance sees and the summed error hides.
  double peak2 = 0.0;
  double cost(double lambda_shape) const { return error + lambda_shape * shape; }
};

// Scratch of one pricing (ShapeState::evaluate): the local union-find over the old roots a move
// joins, the faces it touches and the clusters it makes. Tokens mark what the current pricing
// has seen, so nothing is cleared per move.
struct Scratch {
  Scratch() = default;
  Scratch(Index nv, Index nf) : root_token(nv, 0), root_local(nv, 0), face_token(nf, 0), face_removed(nf, 0) {}
  struct NewCluster {
    ClusterTerms terms;
    std::vector<Index> roots;
    ClusterPlacement placement;
  };
  Index token = 0, face_tok2 = 0;
  std::vector<Index> root_token, root_local, face_token, face_removed, face_token2;
  std::vector<Index> locals, local_parent, set_of, moved_edges, touched_faces, shape_faces;
  // The clusters of the current pricing are sets[0, live): the entries are reused, so their
  // member lists keep their capacity and a pricing allocates nothing once warm.
  std::vector<NewCluster> sets;
  std::size_t live = 0;
  std::span<NewCluster> live_sets() { return {sets.data(), live}; }
  std::span<const NewCluster> live_sets() const { return {sets.data(), live}; }
  NewCluster& add_set() {
    if (live == sets.size()) sets.emplace_back();
    NewCluster& s = sets[live++];
    s.terms = ClusterTerms{};
    s.roots.clear();
    return s;
  }

  Index local_of(Index root) {
    if (root_token[root] != token) {
      root_token[root] = token;
      root_local[root] = Index(locals.size());
      locals.push_back(root);
      local_parent.push_back(Index(local_parent.size()));
    }
    return root_local[root];
  }
  Index find_local(Index x) {
    while (local_parent[x] != x) x = local_parent[x] = local_parent[local_parent[x]];
    return x;
  }
  void unite_local(Index a, Index b) {
    a = find_local(a);
    b = find_local(b);
    if (a != b) local_parent[std::max(a, b)] = std::min(a, b);
  }
};

class ShapeState {
 public:
  ShapeState(const PolyMesh& mesh, const Connectivity& conn, const ShapeSelectionParams& params)
      : mesh_(mesh), conn_(conn), params_(params), uf_(mesh.num_vertices()) {
    const Index nv = mesh.num_vertices(), nf = mesh.num_faces();
    if (!params.vertex_quadrics) own_quadrics_ = build_vertex_quadrics(mesh, conn, params.placement);
    quadrics_ = params.vertex_quadrics ? params.vertex_quadrics : &own_quadrics_;
    h_ = quadrics_->mean_edge;
    // Per-face set-up on all threads: every item is written by one chunk and the sums below run
    // in item order, so the state is the same for any thread count.
    slot_.assign(nv, kInvalidIndex);  // every vertex alone: its terms come from the quadrics
    err_.assign(nv, 0.0);  // a lone vertex sits on all of its planes
    pos_ = mesh.positions;
    next_member_.resize(nv);
    std::iota(next_member_.begin(), next_member_.end(), Index{0});  // circular member lists
    kept_.assign(conn.num_edges, 1);
    face_kept_.resize(nf);
    log_aspect0_.resize(nf);
    pen_.assign(nf, 0.0);
    face_n0_.resize(nf);
    std::vector<double> face_area(nf);
    parallel_chunks(std::size_t(nf), params.threads, params.min_parallel_candidates, [&](std::size_t b, std::size_t e, std::size_t) {
      for (Index f = Index(b); f < Index(e); ++f) {
        face_kept_[f] = mesh.face_size(f);
        const Vec3 av = face_area_vector(mesh, f);
        face_area[f] = av.norm();
        face_n0_[f] = face_area[f] > 0.0 ? Vec3(av / face_area[f]) : Vec3::Zero();
        log_aspect0_[f] = mesh.face_size(f) == 4 ? log_aspect(f, [&](Index v) -> const Vec3& { return mesh.positions[v]; }) : 0.0;
      }
    });
    double area = 0.0;
    for (Index f = 0; f < nf; ++f) area += face_area[f];
    const double diag = bounding_box(mesh).diagonal();
    cos_flip_ = std::cos(std::clamp(params.flip_angle_deg, 1e-6, 180.0) * std::numbers::pi / 180.0);
    min_area2_ = 2.0 * std::max(0.0, params.zero_area_epsilon) * diag * diag;
    norm_ = (area > 0.0 ? area : 1.0) * (diag > 0.0 ? diag * diag : 1.0);
    for (Index f = 0; f < nf; ++f) count_ += tri_equivalents(face_kept_[f]);
    main_ = Scratch(nv, nf);
  }

  std::int64_t count() const { return count_; }
  double error() const { return error_; }
  double shape() const { return shape_; }
  double normalisation() const { return norm_; }
  bool kept(Index e) const { return kept_[e] != 0; }
  const std::vector<std::uint8_t>& edge_kept() const { return kept_; }

  // Prices collapsing the kept edges among `edges`; the scratch then holds the move for apply().
  Move evaluate(std::span<const Index> edges) { return evaluate(edges, main_); }

  // Scratch for pricing beside evaluate(edges) (another thread's): evaluate(edges, scratch)
  // only reads the state while no move is applied yet (every vertex its own root, so
  // UnionFind::find writes nothing), which is when the greedy prices all its candidates.
  Scratch make_scratch() const { return Scratch(mesh_.num_vertices(), mesh_.num_faces()); }
  Move evaluate(std::span<const Index> edges, Scratch& sc) {
    ++sc.token;
    sc.locals.clear();
    sc.local_parent.clear();
    sc.moved_edges.clear();
    for (Index e : edges) {
      if (!kept_[e]) continue;
      sc.moved_edges.push_back(e);
      const auto [a, b] = conn_.edge_vertices[e];
      const Index la = sc.local_of(uf_.find(a)), lb = sc.local_of(uf_.find(b));
      sc.unite_local(la, lb);
    }
    Move m;
    if (sc.moved_edges.empty()) return m;

    // New clusters: the sums of their old clusters' terms, placed.
    sc.set_of.assign(sc.locals.size(), kInvalidIndex);
    sc.live = 0;
    for (std::size_t i = 0; i < sc.locals.size(); ++i) {
      const Index r = sc.find_local(Index(i));
      if (sc.set_of[r] == kInvalidIndex) {
        sc.set_of[r] = Index(sc.live);
        sc.add_set();
      }
      NewCluster& s = sc.sets[sc.set_of[r]];
      add_terms_of(sc.locals[i], s.terms);
      s.roots.push_back(sc.locals[i]);
      m.error -= err_[sc.locals[i]];
    }
    for (NewCluster& s : sc.live_sets()) {
      s.placement = place_cluster(s.terms, h_, params_.placement, [&](auto&& visit) {
        for (Index r : s.roots) for_each_member(r, [&](Index v) { visit(mesh_.positions[v]); });
      });
      m.error += s.placement.error;
      if (s.terms.w > 0.0) m.peak2 = std::max(m.peak2, s.placement.error / s.terms.w);
    }

    // Eq. 1: faces along the collapsed edges lose kept edges.
    sc.touched_faces.clear();
    for (Index e : sc.moved_edges)
      for (Index c : conn_.corners_of_edge(e)) {
        const Index f = conn_.corner_face[c];
        if (sc.face_token[f] != sc.token) {
          sc.face_token[f] = sc.token;
          sc.face_removed[f] = 0;
          sc.touched_faces.push_back(f);
        }
        ++sc.face_removed[f];
      }
    for (Index f : sc.touched_faces) {
      m.reduced += tri_equivalents(face_kept_[f]) - tri_equivalents(face_kept_[f] - sc.face_removed[f]);
      if (face_kept_[f] >= 4 && face_kept_[f] - sc.face_removed[f] == 3) ++m.triangles_made;
    }

    // Faces with a corner in a merged cluster (their corners move): validity and quad shapes.
    if (params_.check_faces || params_.lambda_shape > 0.0) {
      gather_faces(sc, [&](auto&& visit) {
        for (const NewCluster& s : sc.live_sets())
          for (Index r : s.roots) for_each_member(r, visit);
      });
      for (Index f : sc.shape_faces) {
        const Index removed = sc.face_token[f] == sc.token ? sc.face_removed[f] : 0;
        auto placed = [&](Index v) -> const Vec3& {
          const Index r = uf_.find(v);
          if (sc.root_token[r] == sc.token) return sc.sets[sc.set_of[sc.find_local(sc.root_local[r])]].placement.position;
          return pos_[r];
        };
        if (params_.check_faces && tri_equivalents(face_kept_[f] - removed) > 0 && !faces_like_input(f, placed)) {
          m.valid = false;
          return m;
        }
        if (params_.lambda_shape > 0.0) m.shape += penalty(f, face_kept_[f] - removed, placed) - pen_[f];
      }
    }
    return m;
  }

  // Undoes the collapse of the collapsed edges among `edges`: the clusters they are in are split
  // and rebuilt from the collapsed edges left, placed again, and the faces around them priced
  // again. Returns the change (reduced < 0: the count grows).
  Move uncollapse(std::span<const Index> edges) {
    Scratch& sc = main_;
    Move m;
    ++sc.token;
    split_roots_.clear();
    split_members_.clear();
    for (Index e : edges) {
      if (kept_[e]) continue;
      kept_[e] = 1;
      for (Index c : conn_.corners_of_edge(e)) {
        const Index f = conn_.corner_face[c];
        const std::int64_t before = tri_equivalents(face_kept_[f]);
        ++face_kept_[f];
        m.reduced -= tri_equivalents(face_kept_[f]) - before;
      }
      for (Index v : conn_.edge_vertices[e]) {
        const Index r = uf_.find(v);
        if (sc.root_token[r] == sc.token) continue;
        sc.root_token[r] = sc.token;
        split_roots_.push_back(r);
      }
    }
    if (split_roots_.empty()) return m;
    count_ -= m.reduced;
    for (Index r : split_roots_) {
      m.error -= err_[r];
      const double w = slot_[r] == kInvalidIndex ? quadrics_->terms[r].w : pool_[slot_[r]].w;
      if (w > 0.0) m.peak2 = std::max(m.peak2, err_[r] / w);
      for_each_member(r, [&](Index v) { split_members_.push_back(v); });
    }
    gather_faces(sc, [&](auto&& visit) {
      for (Index v : split_members_) visit(v);
    });
    for (Index v : split_members_) {
      uf_.reset(v);
      next_member_[v] = v;
      drop_terms(v);
      err_[v] = 0.0;
      pos_[v] = mesh_.positions[v];
    }
    // Rebuild along the collapsed edges left (they join members only: a collapsed edge lies
    // inside one cluster).
    for (Index v : split_members_)
      for (Index c : conn_.corners_at_vertex(v))
        for (Index e : {conn_.corner_edge[c], conn_.corner_edge[conn_.corner_prev[c]]}) {
          if (kept_[e]) continue;
          const auto [a, b] = conn_.edge_vertices[e];
          const Index ra = uf_.find(a), rb = uf_.find(b);
          if (ra == rb) continue;
          ClusterTerms t = slot_[ra] == kInvalidIndex ? vertex_alone(ra) : pool_[slot_[ra]];
          add_terms_of(rb, t);
          std::swap(next_member_[ra], next_member_[rb]);
          const Index r = uf_.unite(ra, rb);
          drop_terms(ra);
          drop_terms(rb);
          set_terms(r, t);
        }
    ++sc.token;
    for (Index v : split_members_) {
      const Index r = uf_.find(v);
      if (sc.root_token[r] == sc.token) continue;
      sc.root_token[r] = sc.token;
      if (next_member_[r] == r) continue;  // a lone vertex: at its place, no error
      const ClusterPlacement pl = place_cluster(pool_[slot_[r]], h_, params_.placement, [&](auto&& visit) {
        for_each_member(r, [&](Index w) { visit(mesh_.positions[w]); });
      });
      err_[r] = pl.error;
      pos_[r] = pl.position;
      m.error += pl.error;
    }
    error_ += m.error;
    if (params_.lambda_shape > 0.0)
      for (Index f : sc.shape_faces) {
        const double p = penalty(f, face_kept_[f], [&](Index v) -> const Vec3& { return pos_[uf_.find(v)]; });
        m.shape += p - pen_[f];
        shape_ += p - pen_[f];
        pen_[f] = p;
      }
    return m;
  }

  // Applies the move last priced by evaluate().
  void apply(const Move& m) {
    const Scratch& sc = main_;
    for (Index e : sc.moved_edges) kept_[e] = 0;
    for (Index f : sc.touched_faces) face_kept_[f] -= sc.face_removed[f];
    count_ -= m.reduced;
    error_ += m.error;
    for (const NewCluster& s : sc.live_sets()) {
      Index root = s.roots[0];
      for (std::size_t i = 1; i < s.roots.size(); ++i) {
        const Index joined = uf_.unite(root, s.roots[i]);
        std::swap(next_member_[root], next_member_[s.roots[i]]);  // splice the circular lists
        root = joined;
      }
      root = uf_.find(root);
      for (Index r : s.roots) drop_terms(r);
      set_terms(root, s.terms);
      err_[root] = s.placement.error;
      pos_[root] = s.placement.position;
    }
    if (params_.lambda_shape > 0.0) {
      for (Index f : sc.shape_faces) {
        const double p = penalty(f, face_kept_[f], [&](Index v) -> const Vec3& { return pos_[uf_.find(v)]; });
        shape_ += p - pen_[f];
        pen_[f] = p;
      }
    }
  }

 private:
  using NewCluster = Scratch::NewCluster;

  ClusterTerms vertex_alone(Index v) const {
    ClusterTerms t;
    t.add_vertex(quadrics_->terms[v], mesh_.positions[v]);
    return t;
  }

  // The summed terms of root r's cluster added to `sum` (a lone vertex's built as it always was,
  // so the sums are the same bits whichever way they are stored).
  void add_terms_of(Index r, ClusterTerms& sum) const {
    if (slot_[r] == kInvalidIndex) sum += vertex_alone(r);
    else sum += pool_[slot_[r]];
  }
  void set_terms(Index r, const ClusterTerms& t) {
    if (slot_[r] == kInvalidIndex) {
      if (free_slots_.empty()) {
        slot_[r] = Index(pool_.size());
        pool_.push_back(t);
        return;
      }
      slot_[r] = free_slots_.back();
      free_slots_.pop_back();
    }
    pool_[slot_[r]] = t;
  }
  void drop_terms(Index r) {
    if (slot_[r] == kInvalidIndex) return;
    free_slots_.push_back(slot_[r]);
    slot_[r] = kInvalidIndex;
  }

  // Eq. 1: a face with `kept` kept edges counts max(0, kept − 2) triangle-equivalents.
  static std::int64_t tri_equivalents(Index kept) { return kept > 2 ? kept - 2 : 0; }

  // The face after the move (its corners at their clusters' positions; corners in one cluster
  // fall together, which Newell's sum ignores) must face the way its input face did, within
  // flip_angle_deg, and keep an area: the collapse refuses flipped and degenerate faces
  // (post/cluster_collapse.h, guarantees), so a move that makes one is never worth its price.
  template <class PositionOf>
  bool faces_like_input(Index f, PositionOf&& at) const {
    const Index b = mesh_.face_begin(f), k = mesh_.face_size(f);
    const Vec3& o = at(mesh_.corner_vertex[b]);
    Vec3 av = Vec3::Zero();
    for (Index i = 1; i + 1 < k; ++i) av += (at(mesh_.corner_vertex[b + i]) - o).cross(at(mesh_.corner_vertex[b + i + 1]) - o);
    const double len = av.norm();
    if (!(len > min_area2_)) return false;
    return face_n0_[f].squaredNorm() == 0.0 || av.dot(face_n0_[f]) > cos_flip_ * len;
  }

  template <class PositionOf>
  double log_aspect(Index f, PositionOf&& at) const {
    const Index b = mesh_.face_begin(f);
    const Vec3& p0 = at(mesh_.corner_vertex[b]);
    const Vec3& p1 = at(mesh_.corner_vertex[b + 1]);
    const Vec3& p2 = at(mesh_.corner_vertex[b + 2]);
    const Vec3& p3 = at(mesh_.corner_vertex[b + 3]);
    const double a = (p1 - p0).norm() + (p3 - p2).norm(), c = (p2 - p1).norm() + (p0 - p3).norm();
    return a > 0.0 && c > 0.0 ? std::log(a / c) : 0.0;
  }

  // A quad's shape penalty, A h² (ln aspect − ln aspect⁰)², with the quad's sides measured
  // between its placed corners and the input's aspect measured across the same corner pairs;
  // 0 for anything that is no longer a quad of four distinct clusters.
  template <class PositionOf>
  double penalty(Index f, Index kept, PositionOf&& at) {
    if (mesh_.face_size(f) != 4 || kept != 4) return 0.0;
    const Index b = mesh_.face_begin(f);
    Index r[4];
    for (int i = 0; i < 4; ++i) r[i] = uf_.find(mesh_.corner_vertex[b + i]);
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        if (r[i] == r[j]) return 0.0;
    const double d = log_aspect(f, at) - log_aspect0_[f];
    const Vec3& p0 = at(mesh_.corner_vertex[b]);
    const Vec3 area = 0.5 * (at(mesh_.corner_vertex[b + 2]) - p0).cross(at(mesh_.corner_vertex[b + 3]) - at(mesh_.corner_vertex[b + 1]));
    return area.norm() * h_ * h_ * d * d;
  }

  // Every face with a corner at a vertex that `for_each_vertex(visit)` visits, once, into
  // sc.shape_faces.
  template <class ForEachVertex>
  void gather_faces(Scratch& sc, ForEachVertex&& for_each_vertex) {
    ++sc.face_tok2;
    if (sc.face_token2.size() != sc.face_token.size()) sc.face_token2.assign(sc.face_token.size(), 0);
    sc.shape_faces.clear();
    for_each_vertex([&](Index v) {
      for (Index c : conn_.corners_at_vertex(v)) {
        const Index f = conn_.corner_face[c];
        if (sc.face_token2[f] == sc.face_tok2) continue;
        sc.face_token2[f] = sc.face_tok2;
        sc.shape_faces.push_back(f);
      }
    });
  }

  template <class F>
  void for_each_member(Index r, F&& f) const {
    Index v = r;
    do {
      f(v);
      v = next_member_[v];
    } while (v != r);
  }

  const PolyMesh& mesh_;
  const Connectivity& conn_;
  const ShapeSelectionParams& params_;
  UnionFind uf_;
  double h_ = 1.0, norm_ = 1.0;
  // The summed terms of every cluster of two or more members, at slot_[root]; a vertex alone
  // has none stored (vertex_alone builds them from the vertex quadrics): 4 bytes a vertex
  // instead of 232, most of the state on a large mesh (issue 20: the 1M grid's peak).
  std::vector<Index> slot_;
  std::vector<ClusterTerms> pool_;
  std::vector<Index> free_slots_;
  // The vertex quadrics the terms come from (a vertex alone: vertex_alone), borrowed or own;
  // kept rather than a copy of every vertex's ClusterTerms (208 bytes a vertex, issue 20).
  VertexQuadrics own_quadrics_;
  const VertexQuadrics* quadrics_ = nullptr;
  std::vector<double> err_;          // per root
  std::vector<Vec3> pos_;            // per root
  std::vector<Index> next_member_;
  std::vector<std::uint8_t> kept_;
  std::vector<Index> face_kept_;
  std::vector<double> log_aspect0_, pen_;
  std::vector<Vec3> face_n0_;  // unit normal of each input face (zero without area)
  double cos_flip_ = 0.0, min_area2_ = 0.0;  // twice the smallest area a kept face may have
  std::int64_t count_ = 0;
  double error_ = 0.0, shape_ = 0.0;

  Scratch main_;  // of evaluate(edges), uncollapse() and apply()
  std::vector<Index> split_roots_, split_members_;
};

// A candidate of the greedy: a unit (segment) collapse, or a single edge collapse.
struct Candidate {
  double priority;
  Index id;  // < units: unit; else units + edge
  std::int64_t version;
  bool operator<(const Candidate& o) const {  // std::priority_queue is a max-heap
    if (priority != o.priority) return priority > o.priority;
    return id > o.id;
  }
};

// Eq. 2's band in whole triangle-equivalents: [⌈(1 − ϵ_N) N⌉, ⌊(1 + ϵ_N) N⌋].
struct Band {
  std::int64_t lo, hi;
  bool holds(std::int64_t n) const { return n >= lo && n <= hi; }
};
Band eq2_band(std::uint64_t target, double eps) {
  return {std::int64_t(std::ceil((1.0 - eps) * double(target) - 1e-9)),
          std::int64_t(std::floor((1.0 + eps) * double(target) + 1e-9))};
}

}  // namespace

ShapeSelectionResult select_by_shape(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                     std::uint64_t target, const ShapeSelectionParams& params) {
  ShapeSelectionResult out;
  SelectionResult& sel = out.selection;
  ShapeSelectionStats& st = out.stats;
  sel.strategy = "shape-greedy";
  sel.stop_reason = "greedy";
  sel.target = target;
  std::vector<std::uint8_t> pinned = pinned_edges(conn, params);
  // Symmetry (issue 34): an edge is pinned when its mirror is (non-manifold edges, a caller's
  // list that was not symmetric), so the units and their mirrors are fixed alike.
  if (params.edge_mirror && params.edge_mirror->size() == conn.num_edges) symmetrize_flags_union(pinned, *params.edge_mirror);
  const Units units = make_units(conn, analysis, params, pinned);
  ShapeState state(mesh, conn, params);
  sel.input_tri_equivalent = std::uint64_t(state.count());
  if (target >= sel.input_tri_equivalent) {
    sel.edge_kept = state.edge_kept();
    sel.predicted = sel.greedy_predicted = sel.input_tri_equivalent;
    sel.note = "target at or above the input size: nothing to do";
    sel.stop_reason = "nothing to do";
    sel.band_enforced = true;
    return out;
  }
  const Band band = eq2_band(target, params.epsilon_n);
  const std::int64_t lo = band.lo;
  const double single_factor = params.triangle_collapse_factor;
  const bool singles = params.consistency && single_factor > 0.0 && params.max_triangle_share > 0.0;
  const std::int64_t single_budget =
      singles ? std::int64_t(params.max_triangle_share * double(sel.input_tri_equivalent - target)) : 0;
  const Index nu = units.count();

  // A single collapse is a candidate where it differs from its unit's collapse.
  // A unit whose every edge is collapsed (a unit with a pinned edge never is).
  auto wholly_collapsed = [&](Index u) {
    for (Index e : units.of(u))
      if (state.kept(e)) return false;
    return true;
  };
  auto single_edge = [&](Index e) { return !pinned[e] && units.of(units.g.edge_group[e]).size() > 1; };
  Index single_scratch = 0;
  // Symmetry (issue 34): a move's edges with their mirror images, each once; empty when a mirror
  // edge is pinned (the move would collapse what must stay). `seen` marks the move's edges.
  const std::vector<Index>* mirror = params.edge_mirror && params.edge_mirror->size() == conn.num_edges ? params.edge_mirror : nullptr;
  struct MirrorScratch {
    std::vector<Index> edges;
    std::vector<std::uint32_t> seen;
    std::uint32_t token = 0;
  };
  auto with_mirror = [&](std::span<const Index> edges, MirrorScratch& ms) -> std::span<const Index> {
    if (ms.seen.size() != conn.num_edges) ms.seen.assign(conn.num_edges, 0);
    ++ms.token;
    ms.edges.assign(edges.begin(), edges.end());
    for (Index e : edges) ms.seen[e] = ms.token;
    for (Index e : edges) {
      const Index m = (*mirror)[e];
      if (m == kInvalidIndex || ms.seen[m] == ms.token) continue;
      if (pinned[m]) return {};
      ms.seen[m] = ms.token;
      ms.edges.push_back(m);
    }
    return ms.edges;
  };
  MirrorScratch main_mirror;
  auto move_edges = [&](Index id) -> std::span<const Index> {
    std::span<const Index> edges;
    if (id < nu) edges = units.of(id);
    else {
      single_scratch = id - nu;
      edges = {&single_scratch, 1};
    }
    return mirror ? with_mirror(edges, main_mirror) : edges;
  };
  auto priority = [&](Index id, const Move& m) {
    const double per = m.cost(params.lambda_shape) / double(m.reduced);
    // A handicap that also holds for gains (negative cost): a single collapse is taken only when
    // it is better by the factor.
    // A segment move pays for the triangles it leaves at its ends (where the next segment of the
    // chord stays): triangle_penalty per triangle made, relative to the quads it removes.
    const double handicap = id < nu ? 1.0 + params.triangle_penalty * double(m.triangles_made) / std::max(1.0, 0.5 * double(m.reduced))
                                    : single_factor;
    return per >= 0.0 ? per * handicap : per / handicap;
  };

  std::int64_t version = 0;
  // The first pricing of every candidate (units, then single edges, by id): each alone against
  // the input state, so the threads share nothing but reads. The heap's pops depend only on the
  // (priority, id) order, not on the order the candidates were found in.
  std::vector<Candidate> first;
  {
    // Chunk [begin, end) writes its usable candidates from first[begin] on; the chunks are then
    // closed up in order (one array, no per-thread copies: it is the peak of a 1M-face pass).
    const std::size_t n = std::size_t(nu) + (singles ? conn.num_edges : 0);
    first.resize(n);
    std::vector<std::pair<std::size_t, std::size_t>> filled;  // per chunk: begin, end of its writes
    std::mutex filled_mutex;
    std::atomic<std::int64_t> evaluations = 0;
    // One mirror scratch per worker (its `seen` has an entry per edge), made on first use.
    std::vector<MirrorScratch> mirror_scratch(mirror ? std::max<std::size_t>(1, thread_count(params.threads)) : 0);
    auto price = [&](std::size_t begin, std::size_t end, Scratch* scratch, std::size_t worker) {
      std::size_t out = begin;
      std::int64_t evaluated = 0;
      for (std::size_t i = begin; i < end; ++i) {
        const Index id = Index(i);
        if (id < nu ? bool(units.g.fixed[id]) : !single_edge(id - nu)) continue;
        Index one = id >= nu ? id - nu : 0;
        std::span<const Index> edges = id < nu ? units.of(id) : std::span<const Index>(&one, 1);
        if (mirror) {
          edges = with_mirror(edges, mirror_scratch[worker]);
          if (edges.empty()) continue;
        }
        const Move m = scratch ? state.evaluate(edges, *scratch) : state.evaluate(edges);
        ++evaluated;
        if (m.reduced > 0 && m.valid) first[out++] = {priority(id, m), id, version};
      }
      evaluations += evaluated;
      std::lock_guard lock(filled_mutex);
      filled.push_back({begin, out});
    };
    // Weighted by edges: a segment move costs about its edge count in single pricings.
    std::vector<Scratch> scratch(std::max<std::size_t>(1, thread_count(params.threads)) - 1);
    parallel_weighted_chunks(
        n, params.threads, params.min_parallel_candidates, params.pricing_chunks_per_thread,
        [&](std::size_t i) { return i < std::size_t(nu) ? double(units.of(Index(i)).size()) : 1.0; },
        [&](std::size_t begin, std::size_t end, std::size_t worker) {
          if (worker == 0) return price(begin, end, nullptr, worker);  // the state's own scratch
          Scratch& own = scratch[worker - 1];
          if (own.root_token.empty()) own = state.make_scratch();
          price(begin, end, &own, worker);
        });
    std::sort(filled.begin(), filled.end());
    std::size_t size = 0;
    for (const auto& [begin, end] : filled) {
      std::move(first.begin() + std::ptrdiff_t(begin), first.begin() + std::ptrdiff_t(end), first.begin() + std::ptrdiff_t(size));
      size += end - begin;
    }
    first.resize(size);
    st.evaluations += evaluations;
  }
  std::priority_queue<Candidate> heap(std::less<Candidate>(), std::move(first));

  while (state.count() > std::int64_t(target) && !heap.empty()) {
    const Candidate top = heap.top();
    heap.pop();
    if (top.id >= nu && st.reduced_by_singles >= std::uint64_t(single_budget)) continue;
    const Move m = state.evaluate(move_edges(top.id));
    if (top.version != version) ++st.evaluations;
    if (m.reduced <= 0) continue;
    if (!m.valid) {
      ++st.invalid_moves;  // dropped: the faces around it only get more crowded
      continue;
    }
    const double p = priority(top.id, m);
    if (top.version != version && !heap.empty() && p > heap.top().priority) {
      heap.push({p, top.id, version});  // stale and now worse than the next: later
      continue;
    }
    if (state.count() - m.reduced < lo) {
      ++st.overshooting_moves;  // N' only falls: this move can never fit again
      continue;
    }
    if (top.id >= nu && st.reduced_by_singles + std::uint64_t(m.reduced) > std::uint64_t(single_budget)) continue;
    state.apply(m);
    ++version;
    if (top.id < nu) {
      ++st.segment_collapses;
      st.reduced_by_segments += std::uint64_t(m.reduced);
    } else {
      ++st.single_collapses;
      st.reduced_by_singles += std::uint64_t(m.reduced);
    }
  }

  st.greedy_cost = (state.error() + params.lambda_shape * state.shape()) / state.normalisation();
  sel.greedy_predicted = std::uint64_t(state.count());

  // Exchanges (item 4, "search that pays"): the greedy priced each move when it took it, but
  // later moves beside it grow its clusters, so its price now may exceed what a move it passed
  // over would cost. Each round undoes every collapsed move in turn (by id) and collapses instead
  // the best of the `swap_candidates` cheapest moves left, when that lowers the cost and keeps
  // N' in Eq. 2's band; otherwise the move is redone. Work is counted in moves, not seconds.
  if (params.swap_rounds > 0 && band.holds(state.count())) {
    std::vector<Index> taken;  // collapsed moves: units wholly collapsed, and single edges
    for (int round = 0; round < params.swap_rounds; ++round) {
      taken.clear();
      std::vector<std::uint8_t> whole(nu, 0);
      for (Index u = 0; u < nu; ++u) {
        whole[u] = wholly_collapsed(u);
        if (whole[u]) taken.push_back(u);
      }
      if (singles)
        for (Index e = 0; e < conn.num_edges; ++e)
          if (single_edge(e) && !state.kept(e) && !whole[units.g.edge_group[e]]) taken.push_back(nu + e);
      // The cheapest moves left, priced now.
      std::vector<Candidate> left;
      for (Index u = 0; u < nu; ++u) {
        if (units.g.fixed[u]) continue;
        const Move m = state.evaluate(units.of(u));
        ++st.evaluations;
        if (m.reduced > 0 && m.valid) left.push_back({priority(u, m), u, 0});
      }
      if (singles)
        for (Index e = 0; e < conn.num_edges; ++e)
          if (single_edge(e) && state.kept(e)) {
            const Move m = state.evaluate(move_edges(nu + e));
            ++st.evaluations;
            if (m.reduced > 0 && m.valid) left.push_back({priority(nu + e, m), nu + e, 0});
          }
      const std::size_t k = std::min<std::size_t>(left.size(), std::size_t(std::max(0, params.swap_candidates)));
      std::partial_sort(left.begin(), left.begin() + k, left.end(),
                        [](const Candidate& a, const Candidate& b) { return b < a; });
      left.resize(k);
      Index gained = 0;
      for (Index a : taken) {
        const Move undo = state.uncollapse(move_edges(a));
        ++st.swaps_tried;
        const std::uint64_t refund = a >= nu ? std::uint64_t(-undo.reduced) : 0;
        double best = 0.0;
        Index best_id = kInvalidIndex;
        for (const Candidate& c : left) {
          if (c.id == a) continue;
          const Move m = state.evaluate(move_edges(c.id));
          ++st.evaluations;
          if (!m.valid || m.reduced <= 0) continue;
          // No exchange makes a cluster that strays further than the worst one it undoes.
          if (params.swap_keeps_peak && m.peak2 > undo.peak2) continue;
          const std::int64_t n = state.count() - m.reduced;
          if (!band.holds(n)) continue;
          if (c.id >= nu && st.reduced_by_singles - refund + std::uint64_t(m.reduced) > std::uint64_t(single_budget))
            continue;
          const double total = undo.cost(params.lambda_shape) + m.cost(params.lambda_shape);
          if (total < best) {
            best = total;
            best_id = c.id;
          }
        }
        // Only a gain beyond rounding counts (undo + redo of the same clusters is not exact).
        if (best_id != kInvalidIndex && best < -1e-9 * std::max(1e-300, std::abs(state.error()))) {
          const Move m = state.evaluate(move_edges(best_id));
          state.apply(m);
          ++st.swaps_taken;
          ++gained;
          if (a >= nu) st.reduced_by_singles -= refund;
          else st.reduced_by_segments -= std::uint64_t(-undo.reduced);
          if (best_id >= nu) st.reduced_by_singles += std::uint64_t(m.reduced);
          else st.reduced_by_segments += std::uint64_t(m.reduced);
          for (Candidate& c : left)
            if (c.id == best_id) c.id = a;  // the undone move is a candidate now
        } else {
          state.apply(state.evaluate(move_edges(a)));
        }
      }
      if (gained == 0) break;
    }
  }

  sel.edge_kept = state.edge_kept();
  sel.predicted = std::uint64_t(state.count());
  sel.band_enforced = band.holds(state.count());
  if (!sel.band_enforced)
    sel.note = "no selection within " + std::to_string(int(std::lround(params.epsilon_n * 100))) +
               " % of the target was found by the shape greedy (closest N' " + std::to_string(state.count()) + ")";
  for (Index u = 0; u < nu; ++u) sel.collapsed_groups += wholly_collapsed(u);
  st.error = state.error() / state.normalisation();
  st.shape = state.shape() / state.normalisation();
  st.cost = st.error + params.lambda_shape * st.shape;
  sel.objective = st.cost;
  sel.greedy_objective = st.greedy_cost;
  return out;
}

ShapeSelectionStats shape_cost(const PolyMesh& mesh, const Connectivity& conn, const std::vector<std::uint8_t>& edge_kept,
                               const ShapeSelectionParams& params) {
  // From scratch: the collapsed edges applied one by one — the incremental deltas add up to the
  // cost of the final state whatever the order, so this is the oracle of the greedy's figures.
  ShapeState state(mesh, conn, params);
  ShapeSelectionStats st;
  for (Index e = 0; e < conn.num_edges; ++e) {
    if (edge_kept[e]) continue;
    const Index one[1] = {e};
    state.apply(state.evaluate(one));
  }
  st.error = state.error() / state.normalisation();
  st.shape = state.shape() / state.normalisation();
  st.cost = st.error + params.lambda_shape * st.shape;
  return st;
}

}  // namespace quadlod
