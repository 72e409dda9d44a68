// Medial-curve clustering (paper §3.2.3, Fig. 6; Eq. 5 after Knodt 2025; plane quadrics after
// Garland & Heckbert 1997 and Trettner & Kobbelt 2020). Contract and criteria: medial_clustering.h.
//
// One chord at a time. The curve is a doubly linked list of medial edges over the medial points
// (original point ids are kept by the surviving vertices, so every current edge spans a
// contiguous range of original points and every cluster a contiguous range of quads):
//
//   original:   p0 ──e0── p1 ──e1── p2 ──e2── p3 ──e3── p4          (open chord, m = 4 quads)
//                  C(e0)     C(e1)     C(e2)     C(e3)              C(e_i) = loopy edges of quad i
//
//   collapse e1 = ⟨p1, p2⟩:  p1 survives at x ∈ [p1, p2], p2 is removed, e2 now starts at p1;
//   C(e1) joins C(e0) or C(e2), whichever edge centre is nearer to e1's centre:
//
//               p0 ──e0── x ─────e2───── p3 ──e3── p4
//                  C(e0)+C(e1)  C(e2)      C(e3)                    (if e0's centre was nearer)
//
// The spatial check measures the original points spanned by the two edges around the collapse
// against the edge that will span them (u..a against u → x, a..c against x → c below); the rest
// of the curve is unchanged. Upper bounds kept per edge (and, for the normal criteria, per
// cluster) make most checks O(1); an exact scan runs only when a bound exceeds the limit.
//
//        u ──prev── a ──k── b ──next── c      ⇒      u ──── x ──── c
#include "geometry/medial_clustering.h"

#include "geometry/quadric.h"

#include <cmath>
#include <limits>
#include <queue>

namespace quadlod {

namespace {

double point_segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * d)).norm();
}

enum class Verdict { Accept, NormalDeviation, NormalVariation };

class CurveClusterer {
 public:
  CurveClusterer(const PolyMesh& mesh, const Connectivity& conn, const MedialClusteringParams& params,
                 double bbox_diagonal, MedialClusteringResult& out)
      : mesh_(mesh), conn_(conn), params_(params), out_(out),
        max_deviation_(params.max_spatial_deviation * bbox_diagonal),
        cos_deviation_(std::cos(params.max_normal_deviation)),
        cos_variation_(std::cos(params.max_normal_variation)),
        edge_stamp_(conn.num_edges, 0) {}

  void run(Index chord_id, const PolyChord& chord) {
    setup(chord);
    simplify();
    emit(chord_id, chord);
    out_.stats.exact_spatial_checks = exact_spatial_checks_;
    out_.stats.exact_normal_checks = exact_normal_checks_;
  }

 private:
  struct Entry {
    double cost;
    Index edge;
    Index version;
    bool operator>(const Entry& o) const { return cost != o.cost ? cost > o.cost : edge > o.edge; }
  };

  Index num_points() const { return static_cast<Index>(orig_.size()); }

  void setup(const PolyChord& chord) {
    m_ = chord.size();
    closed_ = chord.closed;
    orig_ = medial_curve(mesh_, conn_, chord);
    normals_ = chord_quad_normals(mesh_, conn_, chord);
    pos_ = orig_;
    quadric_.assign(num_points(), Quadric{});
    start_.resize(m_);
    end_.resize(m_);
    prev_.resize(m_);
    next_.resize(m_);
    alive_.assign(m_, 1);
    version_.assign(m_, 0);
    cluster_first_.resize(m_);
    cluster_last_.resize(m_);
    normal_sum_.resize(m_);
    deviation_.assign(m_, 0.0);
    spread_.assign(m_, 0.0);
    rejected_.assign(m_, 0);
    for (Index i = 0; i < m_; ++i) {
      start_[i] = i;
      end_[i] = (i + 1) % num_points();
      prev_[i] = i > 0 ? i - 1 : (closed_ ? m_ - 1 : kInvalidIndex);
      next_[i] = i + 1 < m_ ? i + 1 : (closed_ ? 0 : kInvalidIndex);
      cluster_first_[i] = cluster_last_[i] = i;
      normal_sum_[i] = normals_[i];
      const Quadric q = edge_quadric(orig_[start_[i]], orig_[end_[i]], normals_[i], params_.w_f);
      quadric_[start_[i]] += q;
      quadric_[end_[i]] += q;
    }
    alive_count_ = m_;
    out_.stats.num_medial_edges += m_;
  }

  Index min_edges() const { return closed_ ? 2 : 1; }

  // Where collapsing edge k puts the merged vertex, and the error there.
  Quadric::Minimum collapse_point(Index k) const {
    const Index a = start_[k], b = end_[k];
    const Quadric q = quadric_[a] + quadric_[b];
    if (prev_[k] == kInvalidIndex) return {pos_[a], std::max(0.0, q(pos_[a])), 0.0};
    if (next_[k] == kInvalidIndex) return {pos_[b], std::max(0.0, q(pos_[b])), 1.0};
    return q.minimize_on_segment(pos_[a], pos_[b]);
  }

  void push(Index k) {
    ++version_[k];
    rejected_[k] = 0;
    heap_.push({collapse_point(k).error, k, version_[k]});
  }

  Vec3 centre(Index k) const { return 0.5 * (pos_[start_[k]] + pos_[end_[k]]); }

  // Quad positions of a cluster, cyclic on closed chords.
  template <class F>
  void for_cluster_quads(Index k, F&& f) const {
    for (Index i = cluster_first_[k];; i = (i + 1) % m_) {
      f(i);
      if (i == cluster_last_[k]) break;
    }
  }

  // Largest distance of the original points strictly between ids first and last (cyclic) from
  // segment [s0, s1]; 0 when there are none.
  double interior_deviation(Index first, Index last, const Vec3& s0, const Vec3& s1) const {
    const Index np = num_points();
    double worst = 0.0;
    for (Index j = (first + 1) % np; j != last; j = (j + 1) % np)
      worst = std::max(worst, point_segment_distance(orig_[j], s0, s1));
    return worst;
  }

  // Spatial criterion for collapsing k = ⟨a, b⟩ to x with vertex `keep` surviving:
  //
  //      u ──p── a ──k── b ──n── c     ⇒     u ──P'── x ──N'── c        (keep = a: b's point and
  //                                                                      k's interior join N')
  // Every original point must stay within max_deviation_ of the simplified curve: an interior
  // point of an edge's span of its own edge, a vertex's point of the nearer adjacent edge. The
  // vertex points of u, keep and c are checked exactly (O(1)). For interior points `deviation_`
  // keeps an upper bound per edge, and O(1) bounds (a point moves with its edge by at most the
  // distance its edge's end moved; points of a segment are within its farther endpoint's
  // distance of another segment) decide most cases; the exact scan decides the rest. On success
  // the new edges' interior bounds are returned.
  bool spatial_ok(Index k, const Vec3& x, Index keep, double& dev_prev, double& dev_next) const {
    const Index p = prev_[k], n = next_[k];
    const Index a = start_[k], b = end_[k];
    const Index removed = keep == a ? b : a;
    const Vec3 u = p != kInvalidIndex ? pos_[start_[p]] : x;
    const Vec3 c = n != kInvalidIndex ? pos_[end_[n]] : x;
    // Vertex points. P' replaces p, N' replaces n (k itself disappears).
    auto vertex_ok = [&](Index v, Index e0, Index e1) {
      double d = std::numeric_limits<double>::infinity();
      for (Index e : {e0, e1}) {
        if (e == kInvalidIndex) continue;
        if (e == p) d = std::min(d, point_segment_distance(orig_[v], u, x));
        else if (e == n) d = std::min(d, point_segment_distance(orig_[v], x, c));
        else d = std::min(d, point_segment_distance(orig_[v], pos_[start_[e]], pos_[end_[e]]));
      }
      return d == std::numeric_limits<double>::infinity() || d <= max_deviation_;
    };
    if (!vertex_ok(keep, p, n)) return false;
    if (p != kInvalidIndex && !vertex_ok(start_[p], prev_[p], p)) return false;
    if (n != kInvalidIndex && !vertex_ok(end_[n], n, next_[n])) return false;

    // Interior points: bounds first.
    dev_prev = p != kInvalidIndex ? deviation_[p] + (pos_[a] - x).norm() : 0.0;
    dev_next = n != kInvalidIndex ? deviation_[n] + (pos_[b] - x).norm() : 0.0;
    const Vec3& s0 = keep == a ? x : u;  // the new edge that takes k's points and `removed`
    const Vec3& s1 = keep == a ? c : x;
    const double joined =
        std::max(deviation_[k] + std::max(point_segment_distance(pos_[a], s0, s1), point_segment_distance(pos_[b], s0, s1)),
                 point_segment_distance(orig_[removed], s0, s1));
    (keep == a ? dev_next : dev_prev) = std::max(keep == a ? dev_next : dev_prev, joined);
    if (dev_prev <= max_deviation_ && dev_next <= max_deviation_) return true;
    ++exact_spatial_checks_;
    if (p != kInvalidIndex) dev_prev = interior_deviation(start_[p], keep, u, x);
    if (n != kInvalidIndex) dev_next = interior_deviation(keep, end_[n], x, c);
    return dev_prev <= max_deviation_ && dev_next <= max_deviation_;
  }

  static double angle(const Vec3& unit_a, const Vec3& unit_b) {
    return std::acos(std::clamp(unit_a.dot(unit_b), -1.0, 1.0));
  }

  // Normal criteria for merging cluster k into cluster `target`. `spread_` holds an upper bound
  // of the angle between a cluster's quad normals and its average; by the triangle inequality on
  // the sphere a merged cluster's spread is at most max(spread_X + ∠(avg_X, avg_new)) over its two
  // parts, which decides most cases in O(1); otherwise the quads are scanned.
  Verdict check_normals(Index k, Index target, double& spread) const {
    const Vec3 sa = normal_sum_[k], sb = normal_sum_[target];
    spread = std::max(spread_[k], spread_[target]);
    if (sa.squaredNorm() == 0.0 || sb.squaredNorm() == 0.0) return Verdict::Accept;  // degenerate quads
    const Vec3 na = sa.normalized(), nb = sb.normalized();
    if (na.dot(nb) < cos_deviation_) return Verdict::NormalDeviation;
    const Vec3 sum = sa + sb;
    if (sum.squaredNorm() == 0.0) return Verdict::NormalVariation;
    const Vec3 avg = sum.normalized();
    spread = std::max(spread_[k] + angle(na, avg), spread_[target] + angle(nb, avg));
    if (spread <= params_.max_normal_variation) return Verdict::Accept;
    ++exact_normal_checks_;
    double min_dot = 1.0;
    auto scan = [&](Index i) {
      if (normals_[i].squaredNorm() > 0.0) min_dot = std::min(min_dot, normals_[i].dot(avg));
    };
    for_cluster_quads(k, scan);
    for_cluster_quads(target, scan);
    spread = std::acos(std::clamp(min_dot, -1.0, 1.0));
    return min_dot < cos_variation_ ? Verdict::NormalVariation : Verdict::Accept;
  }

  void simplify() {
    heap_ = {};
    if (alive_count_ <= min_edges()) return;
    for (Index k = 0; k < m_; ++k) push(k);
    MedialClusteringStats& s = out_.stats;
    while (!heap_.empty() && alive_count_ > min_edges()) {
      const Entry top = heap_.top();
      heap_.pop();
      const Index k = top.edge;
      if (!alive_[k] || top.version != version_[k]) continue;

      const Index p = prev_[k], n = next_[k];
      // Merge target: the neighbour whose centre is nearer (§3.2.3); if the normal criteria
      // forbid that merge, the other neighbour (see medial_clustering.h).
      Index target = p, other = n;
      if (p == kInvalidIndex) {
        target = n;
        other = kInvalidIndex;
      } else if (n != kInvalidIndex) {
        const Vec3 ck = centre(k);
        if ((centre(n) - ck).squaredNorm() < (centre(p) - ck).squaredNorm()) std::swap(target, other);
      }
      const Quadric::Minimum x = collapse_point(k);
      // Curve: keep the vertex on the side that has no neighbour (open ends stay put), else a.
      const Index a = start_[k], b = end_[k];
      const Index keep = n == kInvalidIndex ? b : a;
      double dev_prev = 0.0, dev_next = 0.0;
      if (!spatial_ok(k, x.point, keep, dev_prev, dev_next)) {
        ++s.rejected_spatial_deviation;
        rejected_[k] = 1;
        continue;
      }
      double spread = 0.0;
      const Verdict verdict = check_normals(k, target, spread);
      if (verdict != Verdict::Accept) {
        if (other != kInvalidIndex && check_normals(k, other, spread) == Verdict::Accept) {
          target = other;
          ++s.merged_into_farther;
        } else {
          if (verdict == Verdict::NormalDeviation) ++s.rejected_normal_deviation;
          else ++s.rejected_normal_variation;
          rejected_[k] = 1;
          continue;
        }
      }

      pos_[keep] = x.point;
      quadric_[keep] = quadric_[a] + quadric_[b];
      if (p != kInvalidIndex) {
        end_[p] = keep;
        next_[p] = n;
        deviation_[p] = dev_prev;
      }
      if (n != kInvalidIndex) {
        start_[n] = keep;
        prev_[n] = p;
        deviation_[n] = dev_next;
      }
      alive_[k] = 0;
      --alive_count_;
      ++s.num_collapses;

      // Cluster: C(k) joins the target, which stays contiguous.
      if (target == p) cluster_last_[p] = cluster_last_[k];
      else cluster_first_[n] = cluster_first_[k];
      normal_sum_[target] += normal_sum_[k];
      spread_[target] = spread;

      // Costs changed around the moved vertex (prev, next); one step further out only the
      // legality changed, which matters to edges that were rejected before.
      if (p != kInvalidIndex) push(p);
      if (n != kInvalidIndex && n != p) push(n);
      for (Index e : {p != kInvalidIndex ? prev_[p] : kInvalidIndex, n != kInvalidIndex ? next_[n] : kInvalidIndex})
        if (e != kInvalidIndex && e != p && e != n && alive_[e] && rejected_[e]) push(e);
    }
  }

  void emit(Index chord_id, const PolyChord& chord) {
    // First occurrences of loopy edges along the chord (walking order from position 0).
    const Index stamp = chord_id + 1;
    first_occurrence_.assign(2 * std::size_t{m_}, 0);
    for (Index i = 0; i < m_; ++i)
      for (Index side = 0; side < 2; ++side) {
        const Index e = chord.loopy_edges[i][side];
        if (edge_stamp_[e] == stamp) {
          ++out_.stats.duplicate_loopy_edges;
          continue;
        }
        edge_stamp_[e] = stamp;
        first_occurrence_[2 * i + side] = 1;
      }

    // Surviving medial edges in chord order: an open curve from its first edge, a closed one
    // from the edge whose cluster starts earliest.
    Index start = kInvalidIndex;
    for (Index k = 0; k < m_; ++k) {
      if (!alive_[k]) continue;
      if (start == kInvalidIndex) start = k;
      if (!closed_ && prev_[k] == kInvalidIndex) start = k;
      if (closed_ && cluster_first_[k] < cluster_first_[start]) start = k;
    }
    out_.chord_cluster_begin.push_back(static_cast<Index>(out_.clusters.size()));
    for (Index k = start;;) {
      EdgeCluster cluster;
      cluster.chord = chord_id;
      cluster.first = cluster_first_[k];
      cluster.last = cluster_last_[k];
      if (normal_sum_[k].squaredNorm() > 0.0) cluster.normal = normal_sum_[k].normalized();
      Index quads = 0;
      for_cluster_quads(k, [&](Index i) {
        ++quads;
        for (Index side = 0; side < 2; ++side)
          if (first_occurrence_[2 * i + side]) cluster.edges.push_back(chord.loopy_edges[i][side]);
      });
      out_.stats.largest_cluster = std::max(out_.stats.largest_cluster, quads);
      if (cluster.edges.empty()) ++out_.stats.empty_clusters_dropped;
      else out_.clusters.push_back(std::move(cluster));
      k = next_[k];
      if (k == kInvalidIndex || k == start) break;
    }
  }

  const PolyMesh& mesh_;
  const Connectivity& conn_;
  const MedialClusteringParams& params_;
  MedialClusteringResult& out_;
  double max_deviation_;
  double cos_deviation_;
  double cos_variation_;
  std::vector<Index> edge_stamp_;
  std::vector<std::uint8_t> first_occurrence_;

  // Per chord.
  Index m_ = 0;
  bool closed_ = false;
  std::vector<Vec3> orig_, pos_, normals_;
  std::vector<Quadric> quadric_;
  std::vector<Index> start_, end_, prev_, next_, version_, cluster_first_, cluster_last_;
  std::vector<std::uint8_t> alive_, rejected_;
  std::vector<Vec3> normal_sum_;
  std::vector<double> deviation_;  // per edge: bound on its original points' distance to it
  std::vector<double> spread_;     // per cluster: bound on its quad normals' angle to its average
  mutable std::size_t exact_spatial_checks_ = 0;
  mutable std::size_t exact_normal_checks_ = 0;
  Index alive_count_ = 0;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap_;
};

}  // namespace

MedialClusteringResult cluster_medial_curves(const PolyMesh& mesh, const Connectivity& conn,
                                             const PolyChordResult& chords,
                                             const MedialClusteringParams& params) {
  MedialClusteringResult out;
  out.bbox_diagonal = bounding_box(mesh).diagonal();
  out.chord_cluster_begin.reserve(chords.chords.size() + 1);
  CurveClusterer clusterer(mesh, conn, params, out.bbox_diagonal, out);
  for (Index c = 0; c < chords.chords.size(); ++c) clusterer.run(c, chords.chords[c]);
  out.chord_cluster_begin.push_back(static_cast<Index>(out.clusters.size()));
  return out;
}

}  // namespace quadlod
