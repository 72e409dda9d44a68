// `quadlod eval`, the features section (docs/metrics.md §6c): torn UV seams and boundaries, UV
// islands vanished / merged / split, UV error, material borders and feature-line deviation, from
// src/mesh/features.h on both meshes. Called by evaluate() (metrics.cpp) on its scaled copies,
// fan triangulations, output samples and their nearest input triangles.
#include "eval/metrics_common.h"

#include "geometry/bvh.h"
#include "geometry/sampling.h"
#include "mesh/connectivity.h"
#include "mesh/features.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace quadlod::eval_detail {

namespace {

// --- features, UVs, materials (§6c) -------------------------------------------------------------

/// §6c: the distance of an output feature point when the input has no feature of the kind it is
/// compared with (the same penalty as PCCD's, for the same reason).
constexpr double kMissingFeaturePenalty = 1.0;
/// §6c: positions along an output edge where it is sampled (quarter points and midpoint).
constexpr double kEdgeSampleT[3] = {0.25, 0.5, 0.75};
/// §6c: absolute slack (normalised units) added to the torn-seam tolerance, so that a zero-length
/// output edge lying on an input feature is not torn by rounding (1e-9 of the box, far above the
/// ~1e-16 rounding of coordinates, far below any real displacement).
constexpr double kTornAbsoluteSlack = 1e-9;
/// §6c island votes: other input islands within 2·d + this slack (normalised units) of an output
/// sample at distance d from the input compete for its vote; the slack lets exactly coincident
/// sheets (d = 0) compete. At most this many islands are compared per sample.
constexpr double kCoincidentSlack = 1e-9;
constexpr int kMaxVoteCandidates = 4;
/// §6c island matching: a point whose UV is farther than this fraction of its island's UV
/// diagonal from the UV of its closest input point looks across a reduced seam; then up to
/// kMaxMatchCandidates islands within reach compete by UV.
constexpr double kMatchUvMismatch = 0.25;
constexpr int kMaxMatchCandidates = 32;
/// §6c island matching: UV distances this close are a tie (exactly coincident twin sheets with
/// the same UVs give equal distances up to rounding).
constexpr double kUvTie = 1e-9;

/// Material name of face f; "" when the mesh has no materials or the face has none. §6c compares
/// by name because the two meshes' name tables need not agree.
std::string_view material_name(const PolyMesh& m, Index f) {
  if (m.face_material.empty() || m.face_material[f] == kInvalidIndex) return {};
  return m.material_names[m.face_material[f]];
}

using Segment = std::array<Vec3, 2>;

Segment edge_segment(const PolyMesh& scaled, const Connectivity& conn, Index e) {
  return {scaled.positions[conn.edge_vertices[e][0]], scaled.positions[conn.edge_vertices[e][1]]};
}

/// Distance from p to the nearest segment of `target`; the missing-feature penalty when empty.
double feature_distance(const SegmentBvh& target, const Vec3& p) {
  if (target.size() == 0) return kMissingFeaturePenalty;
  return std::sqrt(target.nearest(p).distance_sq);
}

/// Everything §6c needs of one mesh: connectivity, feature edges (FeatureParams defaults) and
/// the islands of UV set 0 (empty without UVs).
struct MeshFeatures {
  Connectivity conn;
  FeatureEdges fe;
  UvIslands islands;
  std::uint64_t islands_with_area = 0;
};

MeshFeatures mesh_features(const PolyMesh& m) {
  MeshFeatures r;
  r.conn = build_connectivity(m);
  r.fe = find_feature_edges(m, r.conn);
  if (m.has_uvs()) {
    r.islands = find_uv_islands(m, r.conn, 0);
    for (double a : r.islands.area_3d) r.islands_with_area += a > 0.0;
  }
  return r;
}

/// Input feature edges of one kind as a segment BVH.
template <class Keep>
SegmentBvh feature_segments(const PolyMesh& scaled, const MeshFeatures& mf, Keep&& keep) {
  std::vector<Segment> segs;
  for (Index e = 0; e < mf.conn.num_edges; ++e)
    if (keep(e)) segs.push_back(edge_segment(scaled, mf.conn, e));
  return SegmentBvh(segs);
}

struct EdgeDeviation {
  double max = kNaN;
  double mean = kNaN;  ///< weighted by edge length: an arc-length average over the feature lines
};

/// Distances of the sample points (kEdgeSampleT) of output edges `edges` to `target_of(e)`.
template <class TargetOf>
EdgeDeviation edge_deviation(const PolyMesh& out, const Connectivity& conn,
                             const std::vector<Index>& edges, TargetOf&& target_of) {
  EdgeDeviation r;
  if (edges.empty()) return r;
  Sum weighted, length;
  double mx = 0.0;
  for (Index e : edges) {
    const Segment s = edge_segment(out, conn, e);
    const double len = (s[1] - s[0]).norm();
    const SegmentBvh& target = target_of(e);
    double sum = 0.0;
    for (double t : kEdgeSampleT) {
      const double d = feature_distance(target, s[0] + t * (s[1] - s[0]));
      sum += d;
      mx = std::max(mx, d);
    }
    weighted.add(len * sum / 3.0);
    length.add(len);
  }
  r.max = mx;
  if (length.value() > 0.0) r.mean = weighted.value() / length.value();
  return r;
}

/// §6c seams_torn: output boundary / UV seam edges with a sample point farther than
/// feature_tolerance × length (+ slack) from every input edge of the same kind (UV seams per set).
std::uint64_t count_torn(const PolyMesh& in, const MeshFeatures& fin, const PolyMesh& out,
                         const MeshFeatures& fout, double tolerance) {
  const SegmentBvh boundary_in =
      feature_segments(in, fin, [&](Index e) { return (fin.fe.edge_bits[e] & kFeatureBoundary) != 0; });
  std::uint32_t out_sets = 0;
  for (Index e = 0; e < fout.conn.num_edges; ++e) out_sets |= fout.fe.edge_uv_seam_sets[e];
  std::vector<SegmentBvh> seams_in(32);
  for (int k = 0; k < 32; ++k)
    if (out_sets >> k & 1u)
      seams_in[k] = feature_segments(in, fin, [&](Index e) { return (fin.fe.edge_uv_seam_sets[e] >> k & 1u) != 0; });
  std::uint64_t torn = 0;
  for (Index e = 0; e < fout.conn.num_edges; ++e) {
    const std::uint8_t bits = fout.fe.edge_bits[e];
    if (!(bits & (kFeatureBoundary | kFeatureUvSeam))) continue;
    const Segment s = edge_segment(out, fout.conn, e);
    const double tol = tolerance * (s[1] - s[0]).norm() + kTornAbsoluteSlack;
    auto off = [&](const SegmentBvh& target) {
      for (double t : kEdgeSampleT)
        if (feature_distance(target, s[0] + t * (s[1] - s[0])) > tol) return true;
      return false;
    };
    bool is_torn = (bits & kFeatureBoundary) && off(boundary_in);
    for (int k = 0; k < 32 && !is_torn; ++k)
      if (fout.fe.edge_uv_seam_sets[e] >> k & 1u) is_torn = off(seams_in[k]);
    torn += is_torn;
  }
  return torn;
}

/// First fan triangle of every face in a soup (faces appear in order, degree − 2 triangles each).
std::vector<Index> first_triangles(const TriangleSoup& soup, Index num_faces) {
  std::vector<Index> first(num_faces, kInvalidIndex);
  for (Index t = static_cast<Index>(soup.face.size()); t-- > 0;) first[soup.face[t]] = t;
  return first;
}

/// UV (set 0) at point p of fan triangle t: barycentric interpolation of the triangle's corner
/// UVs, the weights clamped to [0, 1] and renormalised so that rounding on a sliver cannot
/// extrapolate beyond the triangle's UVs. Every corner of the face must have a UV.
Vec2 uv_at(const PolyMesh& m, const TriangleSoup& soup, const std::vector<Index>& first, Index t,
           const Vec3& p) {
  const Index f = soup.face[t];
  const Index i = t - first[f];
  const Index b = m.face_begin(f);
  const Index corners[3] = {b, b + i + 1, b + i + 2};
  const auto& tri = soup.triangles[t];
  const Vec3 e0 = tri[1] - tri[0], e1 = tri[2] - tri[0], q = p - tri[0];
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = q.dot(e0), d21 = q.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  double w[3] = {1.0, 0.0, 0.0};
  if (den > 0.0) {
    w[1] = std::clamp((d11 * d20 - d01 * d21) / den, 0.0, 1.0);
    w[2] = std::clamp((d00 * d21 - d01 * d20) / den, 0.0, 1.0);
    w[0] = std::max(0.0, 1.0 - w[1] - w[2]);
    const double sum = w[0] + w[1] + w[2];
    for (double& x : w) x /= sum;
  }
  const UvSet& set = m.uv_sets[0];
  Vec2 uv = Vec2::Zero();
  for (int k = 0; k < 3; ++k) uv += w[k] * set.values[set.corner[corners[k]]];
  return uv;
}

/// §6c island correspondence: the input island a point p of the output (UV uv_out there) lies in.
/// Its closest input point is on triangle t0; when other islands come within `bound` of p (at most
/// `kCandidates` islands are compared), the one whose UV at its closest point is nearest uv_out
/// wins (ties → the smaller island id). With a non-zero `facing` (the output face's normal),
/// islands whose triangle there faces the same way win over those facing away first: the two
/// sheets of a two-sided panel are coincident, often with the same UVs. tri_island: per input fan
/// triangle, its island (kInvalidIndex for zero area or no UV).
struct IslandVote {
  Index island = kInvalidIndex;
  double uv_distance = 0.0;  ///< |uv_out − UV at the closest point of `island`|
  /// Islands exactly as good (same facing, UV distance within kUvTie): `island` and its twins.
  std::array<Index, kMaxMatchCandidates> ties{};
  int num_ties = 0;
};
template <int kCandidates>
IslandVote vote_island(const PolyMesh& input, const TriangleSoup& soup_in, const std::vector<Index>& first_in,
                       const std::vector<Index>& tri_island, const TriangleBvh& bvh_in, const Vec3& p,
                       const Vec2& uv_out, Index t0, double bound, const Vec3& facing = Vec3::Zero()) {
  static_assert(kCandidates <= kMaxMatchCandidates);
  IslandVote v;
  if (t0 == kInvalidIndex || tri_island[t0] == kInvalidIndex) return v;
  auto away = [&](Index t) {
    const auto& tri = soup_in.triangles[t];
    return facing.dot((tri[1] - tri[0]).cross(tri[2] - tri[0])) < 0.0;
  };
  Index seen[kCandidates] = {tri_island[t0]};
  bool seen_away[kCandidates] = {away(t0)};
  const auto& tri = soup_in.triangles[t0];
  double seen_uv[kCandidates] = {
      (uv_at(input, soup_in, first_in, t0, closest_point_on_triangle(p, tri[0], tri[1], tri[2]).point) - uv_out).norm()};
  int count = 1;
  for (; count < kCandidates; ++count) {
    const int c = count;
    const NearestHit h = bvh_in.nearest_if(
        p, [&](Index t) { return tri_island[t] != kInvalidIndex && std::find(seen, seen + c, tri_island[t]) == seen + c; },
        kInvalidIndex, bound * bound);
    if (h.primitive == kInvalidIndex) break;
    seen[c] = tri_island[h.primitive];
    seen_away[c] = away(h.primitive);
    seen_uv[c] = (uv_at(input, soup_in, first_in, h.primitive, h.point) - uv_out).norm();
  }
  int best = 0;
  for (int c = 1; c < count; ++c)
    if (seen_away[c] < seen_away[best] ||
        (seen_away[c] == seen_away[best] &&
         (seen_uv[c] < seen_uv[best] || (seen_uv[c] == seen_uv[best] && seen[c] < seen[best]))))
      best = c;
  v.island = seen[best];
  v.uv_distance = seen_uv[best];
  for (int c = 0; c < count; ++c)
    if (seen_away[c] == seen_away[best] && seen_uv[c] <= seen_uv[best] + kUvTie) v.ties[v.num_ties++] = seen[c];
  return v;
}

/// Per input fan triangle: the island (UV set 0) of its face, kInvalidIndex for zero area.
std::vector<Index> triangle_islands(const TriangleSoup& soup_in, const MeshFeatures& fin) {
  std::vector<Index> tri_island(soup_in.triangles.size(), kInvalidIndex);
  for (std::size_t t = 0; t < tri_island.size(); ++t)
    if (triangle_area(soup_in.triangles[t]) > 0.0) tri_island[t] = fin.islands.face_island[soup_in.face[t]];
  return tri_island;
}

struct IslandMatch {
  std::uint64_t vanished = 0, merged = 0, split = 0;
};

/// §6c uv_islands_vanished / _merged / _split: every output fan triangle of positive area on a
/// face with UVs votes (vote_island) at its centroid for the input island it lies in. Every
/// output face takes part, however small, so an island that survives as one sliver still counts.
/// First the coincident islands compete, as for uv_error's votes (twin sheets, both sides of a
/// seam); when the winner's UV there is off by more than kMatchUvMismatch of its UV diagonal, the
/// point looks across a reduced seam from its own chart, and the islands within the closest
/// distance plus the longest edge of the output face (the farthest a reduced seam can have moved
/// across the point; the rule of uv_error's self-seams) compete by UV instead.
IslandMatch match_islands(const PolyMesh& input, const PolyMesh& output, const PolyMesh& out,
                          const MeshFeatures& fin, const MeshFeatures& fout, const TriangleSoup& soup_in,
                          const TriangleSoup& soup_out, const TriangleBvh& bvh_in, unsigned threads) {
  IslandMatch r;
  std::vector<double> longest_edge(out.num_faces(), 0.0);
  for (Index f = 0; f < out.num_faces(); ++f)
    for (Index c = out.face_begin(f); c < out.face_end(f); ++c)
      longest_edge[f] = std::max(longest_edge[f], (out.positions[out.corner_vertex[out.next_corner(f, c)]] -
                                                   out.positions[out.corner_vertex[c]]).norm());
  const std::vector<Index> tri_island = triangle_islands(soup_in, fin);
  const std::vector<Index> first_in = first_triangles(soup_in, input.num_faces());
  const std::vector<Index> first_out = first_triangles(soup_out, output.num_faces());
  const std::size_t n = soup_out.triangles.size();
  std::vector<IslandVote> vote(n);
  std::vector<char> shows_chart(n, 0);
  parallel_chunks(n, threads, [&](std::size_t begin, std::size_t end) {
    Index hint = kInvalidIndex;
    for (std::size_t t = begin; t < end; ++t) {
      const auto& tri = soup_out.triangles[t];
      if (fout.islands.face_island[soup_out.face[t]] == kInvalidIndex || !(triangle_area(tri) > 0.0)) continue;
      const Vec3 c = (tri[0] + tri[1] + tri[2]) / 3.0;
      const NearestHit h = bvh_in.nearest(c, hint);
      if (h.primitive == kInvalidIndex) continue;
      hint = h.primitive;
      const Vec2 u0 = uv_at(output, soup_out, first_out, static_cast<Index>(t), tri[0]);
      const Vec2 u1 = uv_at(output, soup_out, first_out, static_cast<Index>(t), tri[1]);
      const Vec2 u2 = uv_at(output, soup_out, first_out, static_cast<Index>(t), tri[2]);
      const Vec2 e1 = u1 - u0, e2 = u2 - u0;
      const bool no_chart = !(std::abs(e1.x() * e2.y() - e1.y() * e2.x()) > 0.0);
      const Vec2 uv = (u0 + u1 + u2) / 3.0;
      const Vec3 facing = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
      const double d = std::sqrt(h.distance_sq);
      IslandVote v = vote_island<kMaxMatchCandidates>(input, soup_in, first_in, tri_island, bvh_in, c, uv, h.primitive,
                                                     2.0 * d + kCoincidentSlack, facing);
      if (v.island != kInvalidIndex &&
          v.uv_distance > kMatchUvMismatch * (fin.islands.uv_max[v.island] - fin.islands.uv_min[v.island]).norm()) {
        // By UV alone: facing only separates coincident sheets; within reach, on a curved or
        // folded surface, the right chart's closest triangle may well face another way
        // (makehuman_teeth_base at 0.2: 3 false merges when facing decided here too).
        const double reach = d + longest_edge[soup_out.face[t]] + kCoincidentSlack;
        v = vote_island<kMaxMatchCandidates>(input, soup_in, first_in, tri_island, bvh_in, c, uv, h.primitive, reach);
      }
      vote[t] = v;
      shows_chart[t] = !no_chart;
    }
  });
  // Each output island's chart: an input island that every one of its votes names or that
  // explains the vote's point as well — it lies within the point's reach and its UV there is
  // within kMatchUvMismatch of its UV diagonal (islands whose UVs continue each other across their
  // seam, or tiny neighbours in 3D and in the atlas, where a point can go either way). Candidates
  // are the islands the output island's votes name, most named first (ties → smaller id); an
  // output island that no candidate explains is merged.
  std::vector<std::pair<Index, Index>> pairs;  // (output island, input island), one per vote and tie
  std::vector<std::pair<Index, Index>> votes_by_island;  // (output island, output fan triangle)
  for (std::size_t t = 0; t < n; ++t) {
    if (vote[t].island == kInvalidIndex) continue;
    // A triangle whose UVs have no area (all corners on one texel or line, as hard-surface models
    // colour whole parts) shows no chart: it keeps its island from vanishing but decides nothing.
    if (!shows_chart[t]) continue;
    const Index o = fout.islands.face_island[soup_out.face[t]];
    for (int k = 0; k < vote[t].num_ties; ++k) pairs.emplace_back(o, vote[t].ties[k]);
    votes_by_island.emplace_back(o, static_cast<Index>(t));
  }
  std::sort(pairs.begin(), pairs.end());
  std::sort(votes_by_island.begin(), votes_by_island.end());
  auto names = [&](Index t, Index x) {
    return std::find(vote[t].ties.begin(), vote[t].ties.begin() + vote[t].num_ties, x) !=
           vote[t].ties.begin() + vote[t].num_ties;
  };
  // X's UV at its closest point to p (within p's reach) is within kMatchUvMismatch of uv.
  auto matches = [&](const Vec3& p, const Vec2& uv, double ell, Index x) {
    const double reach = std::sqrt(bvh_in.nearest(p).distance_sq) + ell + kCoincidentSlack;
    const NearestHit h = bvh_in.nearest_if(p, [&](Index q) { return tri_island[q] == x; }, kInvalidIndex, reach * reach);
    return h.primitive != kInvalidIndex && (uv_at(input, soup_in, first_in, h.primitive, h.point) - uv).norm() <=
                                               kMatchUvMismatch * (fin.islands.uv_max[x] - fin.islands.uv_min[x]).norm();
  };
  // A corner p with UV uv: some triangle of X as close as p's closest input point (within
  // 2d + kCoincidentSlack, the coincident-sheet rule of the votes) has uv within
  // kMatchUvMismatch at its closest point to p. "Some", not "the closest": at a vertex on a
  // self-seam of X (a ring unwrapped with a cut) X's triangles on both sides touch p, with
  // different UVs (yofrankie_frankie at 0.4: 0.47 apart at a corner exactly on the input).
  auto corner_matches = [&](const Vec3& p, const Vec2& uv, Index x) {
    const double reach = 2.0 * std::sqrt(bvh_in.nearest(p).distance_sq) + kCoincidentSlack;
    const double limit = kMatchUvMismatch * (fin.islands.uv_max[x] - fin.islands.uv_min[x]).norm();
    const NearestHit h = bvh_in.nearest_if(
        p,
        [&](Index q) {
          if (tri_island[q] != x) return false;
          const auto& t = soup_in.triangles[q];
          return (uv_at(input, soup_in, first_in, q, closest_point_on_triangle(p, t[0], t[1], t[2]).point) - uv).norm() <= limit;
        },
        kInvalidIndex, reach * reach);
    return h.primitive != kInvalidIndex;
  };
  // At the centroid, or else at each of the three corners: a large output triangle on a curved
  // chart interpolates, at its centroid, a UV far from the chart's UV at the nearest input point
  // (stretch, measured by uv_error), while its corners — input vertices, or moved vertices whose
  // UVs were projected from the nearest input point — carry their chart's UVs where they are.
  // A face across a seam fails at the corners on the other side (FaceAcrossASeamIsAMerge).
  auto explains = [&](Index t, Index x) {
    const auto& tri = soup_out.triangles[t];
    const double ell = longest_edge[soup_out.face[t]];
    const Vec2 u[3] = {uv_at(output, soup_out, first_out, t, tri[0]), uv_at(output, soup_out, first_out, t, tri[1]),
                       uv_at(output, soup_out, first_out, t, tri[2])};
    if (matches((tri[0] + tri[1] + tri[2]) / 3.0, (u[0] + u[1] + u[2]) / 3.0, ell, x)) return true;
    for (int k = 0; k < 3; ++k)
      if (!corner_matches(tri[k], u[k], x)) return false;
    return true;
  };
  std::vector<Index> chart(fout.islands.num_islands, kInvalidIndex);
  std::vector<char> merged(fout.islands.num_islands, 0);
  std::vector<std::pair<std::size_t, Index>> candidates;  // (−count, island)
  std::vector<std::vector<Index>> ranked(fout.islands.num_islands);  // candidates, best first
  std::vector<std::pair<std::size_t, std::size_t>> vote_range(fout.islands.num_islands, {0, 0});
  // Does input island x fit output island o: every deciding vote of o names or is explained by x?
  auto fits = [&](Index o, Index x) {
    for (std::size_t k = vote_range[o].first; k < vote_range[o].second; ++k) {
      const Index t = votes_by_island[k].second;
      if (!names(t, x) && !explains(t, x)) return false;
    }
    return true;
  };
  for (std::size_t a = 0, b, v0 = 0; a < pairs.size(); a = b) {  // serial: few islands disagree
    const Index o = pairs[a].first;
    candidates.clear();
    for (b = a; b < pairs.size() && pairs[b].first == o;) {
      std::size_t e = b;
      while (e < pairs.size() && pairs[e] == pairs[b]) ++e;
      candidates.emplace_back(std::numeric_limits<std::size_t>::max() - (e - b), pairs[b].second);
      b = e;
    }
    std::sort(candidates.begin(), candidates.end());
    while (v0 < votes_by_island.size() && votes_by_island[v0].first < o) ++v0;
    std::size_t v1 = v0;
    while (v1 < votes_by_island.size() && votes_by_island[v1].first == o) ++v1;
    vote_range[o] = {v0, v1};
    for (const auto& [minus_count, x] : candidates) {
      ranked[o].push_back(x);
      if (chart[o] == kInvalidIndex && fits(o, x)) chart[o] = x;
    }
    if (chart[o] == kInvalidIndex) {
      merged[o] = 1;
      chart[o] = candidates.front().second;
    }
  }
  // Twins: an input island can be the first fitting chart of two output islands while another
  // fitting island is nobody's chart — layered hair cards or nested eyeball shells with the same
  // UVs, close in 3D (makehuman_hair_bob01 at 0.2: 3 false splits). Such an output island takes
  // the free island instead: a split is only counted when no assignment avoids it.
  {
    std::vector<Index> pieces(fin.islands.num_islands, 0);
    for (Index o = 0; o < fout.islands.num_islands; ++o)
      if (chart[o] != kInvalidIndex && !merged[o]) ++pieces[chart[o]];
    for (Index o = 0; o < fout.islands.num_islands; ++o) {
      if (chart[o] == kInvalidIndex || merged[o] || pieces[chart[o]] < 2) continue;
      for (Index y : ranked[o])
        if (y != chart[o] && pieces[y] == 0 && fits(o, y)) {
          --pieces[chart[o]];
          ++pieces[y];
          chart[o] = y;
          break;
        }
    }
  }
  // Split: input islands that are the chart of two or more output islands without a merge.
  std::vector<Index> pieces(fin.islands.num_islands, 0);
  for (Index o = 0; o < fout.islands.num_islands; ++o) {
    if (chart[o] == kInvalidIndex) continue;
    r.merged += merged[o];
    if (!merged[o]) ++pieces[chart[o]];
  }
  // Vanished: neither the chart of an output island nor named by a vote that shows no chart or
  // belongs to a merged output island or one without a chart. A vote that merely names an island (a coincident or nested twin:
  // the three eyeball shells of flightgear_head_amelia share their UVs) does not keep it:
  // counting those hid 4–50 vanished islands per output (kc130 at 0.8: 168 → 158, 6 vanished).
  std::vector<char> covered(fin.islands.num_islands, 0);
  for (Index o = 0; o < fout.islands.num_islands; ++o)
    if (chart[o] != kInvalidIndex && !merged[o]) covered[chart[o]] = 1;
  for (std::size_t t = 0; t < n; ++t) {
    if (vote[t].island == kInvalidIndex) continue;
    const Index o = fout.islands.face_island[soup_out.face[t]];
    if (shows_chart[t] && chart[o] != kInvalidIndex && !merged[o]) continue;
    for (int k = 0; k < vote[t].num_ties; ++k) covered[vote[t].ties[k]] = 1;
  }
  for (Index i = 0; i < fin.islands.num_islands; ++i) {
    if (!(fin.islands.area_3d[i] > 0.0)) continue;
    r.vanished += !covered[i];
    r.split += pieces[i] >= 2;
  }
  return r;
}

struct UvErrorResult {
  double mean = kNaN, max = kNaN;
  std::uint64_t samples = 0;
};

/// §6c uv_error over the output samples: output island → the input island most of its samples
/// vote for; then the closest point within that island (positive-area triangles only), the other
/// side of a nearby self-seam if its UV is nearer, and the UV distance over the island's UV bbox
/// diagonal. `in`, `out`: the scaled copies (geometry); `input`, `output`: the UVs.
UvErrorResult uv_error(const PolyMesh& input, const PolyMesh& output, const PolyMesh& in,
                       const PolyMesh& out, const MeshFeatures& fin, const MeshFeatures& fout,
                       const TriangleSoup& soup_in, const TriangleSoup& soup_out,
                       const SurfaceSamples& s_out, const Directed& d_out, const TriangleBvh& bvh_in,
                       unsigned threads) {
  UvErrorResult r;
  const std::size_t n = s_out.points.size();
  const std::vector<Index> tri_island = triangle_islands(soup_in, fin);
  const std::vector<Index> first_in = first_triangles(soup_in, input.num_faces());
  const std::vector<Index> first_out = first_triangles(soup_out, output.num_faces());
  std::vector<Index> out_island(n, kInvalidIndex), vote(n, kInvalidIndex);
  std::vector<Vec2> uv_out(n, Vec2::Zero());
  const std::vector<std::uint32_t> order = morton_order(s_out.points, {});

  // Votes. A sample votes for the island of its closest input point; when other islands are
  // nearly as close (within 2·d + kCoincidentSlack: coincident twin sheets, two-sided panels,
  // both sides of a seam) it votes for the one whose UV there is nearest its own UV, so that a
  // duplicated sheet cannot capture an island by the BVH's tie order.
  parallel_chunks(order.size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      const std::size_t k = order[j];
      out_island[k] = fout.islands.face_island[soup_out.face[s_out.triangle[k]]];
      const Index t0 = d_out.nearest[k];
      if (out_island[k] == kInvalidIndex || t0 == kInvalidIndex) continue;
      uv_out[k] = uv_at(output, soup_out, first_out, s_out.triangle[k], s_out.points[k]);
      if (tri_island[t0] == kInvalidIndex) continue;
      // Only coincident or nearly as close islands compete (within 2·d + kCoincidentSlack:
      // coincident twin sheets, two-sided panels, both sides of a seam; see docs/metrics.md §6c).
      vote[k] = vote_island<kMaxVoteCandidates>(input, soup_in, first_in, tri_island, bvh_in, s_out.points[k],
                                                uv_out[k], t0, 2.0 * d_out.dist[k] + kCoincidentSlack).island;
    }
  });
  std::vector<std::pair<Index, Index>> votes;  // (output island, input island), tallied serially
  for (std::size_t k = 0; k < n; ++k)
    if (vote[k] != kInvalidIndex) votes.emplace_back(out_island[k], vote[k]);
  std::sort(votes.begin(), votes.end());
  std::vector<Index> target(fout.islands.num_islands, kInvalidIndex);
  std::vector<std::size_t> most(fout.islands.num_islands, 0);
  for (std::size_t a = 0, b; a < votes.size(); a = b) {
    for (b = a; b < votes.size() && votes[b] == votes[a]; ++b) {}
    // Strictly more votes wins; ties keep the smaller input island (seen first in sorted order).
    if (b - a > most[votes[a].first]) {
      most[votes[a].first] = b - a;
      target[votes[a].first] = votes[a].second;
    }
  }

  // Self-seams: UV seams (set 0) with one island on both sides, like a cylinder's unwrap seam (32
  // of blender_suzanne's 50 seam edges, 911 of makehuman_base_body's 1133). Restricting to the
  // island cannot tell their sides apart: an output sample that lies just across the input seam
  // from the side whose chart its face uses finds its closest point on the other side, a whole
  // island width away in UV (e = 0.85 at 3e-4 from the input surface on Blender's 40 % Suzanne).
  // So within reach of a self-seam — the closest point's distance plus the longest edge of the
  // sample's output face, the farthest a reduced seam can have moved across it — the triangles
  // of the island's faces along self-seams are candidates too, and the UV-nearest wins.
  std::vector<char> self_seam_face(input.num_faces(), 0);
  for (Index e = 0; e < fin.conn.num_edges; ++e) {
    if (!(fin.fe.edge_uv_seam_sets[e] & 1u)) continue;
    const auto cs = fin.conn.corners_of_edge(e);
    const Index f0 = fin.conn.corner_face[cs[0]], f1 = fin.conn.corner_face[cs[1]];
    if (fin.islands.face_island[f0] != kInvalidIndex && fin.islands.face_island[f0] == fin.islands.face_island[f1])
      self_seam_face[f0] = self_seam_face[f1] = 1;
  }
  std::vector<std::array<Vec3, 3>> seam_tris;  // their own BVH: a range query visits only them
  std::vector<Index> seam_tri_id;               // → triangle of soup_in
  std::vector<TriangleFrame> seam_frame;
  std::vector<std::array<Vec2, 2>> seam_uv_box;  // UV bbox: a candidate that cannot beat e is skipped
  for (std::size_t t = 0; t < soup_in.triangles.size(); ++t)
    if (tri_island[t] != kInvalidIndex && self_seam_face[soup_in.face[t]]) {
      const auto& tri = soup_in.triangles[t];
      seam_tris.push_back(tri);
      seam_tri_id.push_back(static_cast<Index>(t));
      seam_frame.push_back(make_triangle_frame(tri[0], tri[1], tri[2]));
      const std::array<Vec2, 3> uv = {uv_at(input, soup_in, first_in, static_cast<Index>(t), tri[0]),
                                      uv_at(input, soup_in, first_in, static_cast<Index>(t), tri[1]),
                                      uv_at(input, soup_in, first_in, static_cast<Index>(t), tri[2])};
      seam_uv_box.push_back({uv[0].cwiseMin(uv[1]).cwiseMin(uv[2]), uv[0].cwiseMax(uv[1]).cwiseMax(uv[2])});
    }
  const TriangleBvh seam_bvh(seam_tris);
  std::vector<double> longest_edge(out.num_faces(), 0.0);
  for (Index f = 0; f < out.num_faces(); ++f)
    for (Index c = out.face_begin(f); c < out.face_end(f); ++c)
      longest_edge[f] = std::max(longest_edge[f], (out.positions[out.corner_vertex[out.next_corner(f, c)]] -
                                                   out.positions[out.corner_vertex[c]]).norm());

  std::vector<double> err(n, kNaN);
  parallel_chunks(order.size(), threads, [&](std::size_t begin, std::size_t end) {
    Index hint = kInvalidIndex;
    for (std::size_t j = begin; j < end; ++j) {
      const std::size_t k = order[j];
      if (out_island[k] == kInvalidIndex) continue;
      const Index ii = target[out_island[k]];
      if (ii == kInvalidIndex) continue;
      const double diag = (fin.islands.uv_max[ii] - fin.islands.uv_min[ii]).norm();
      if (!(diag > 0.0)) continue;
      const Vec3& p = s_out.points[k];
      auto in_island = [&](Index t) { return tri_island[t] == ii; };
      const Index t0 = d_out.nearest[k];
      const NearestHit h = bvh_in.nearest_if(p, in_island, t0 != kInvalidIndex && in_island(t0) ? t0 : hint);
      if (h.primitive == kInvalidIndex) continue;
      hint = h.primitive;
      double e = (uv_out[k] - uv_at(input, soup_in, first_in, h.primitive, h.point)).norm();
      const double reach = std::sqrt(h.distance_sq) + longest_edge[soup_out.face[s_out.triangle[k]]];
      // Visits every candidate triangle within reach (the predicate never accepts, so the search
      // bound stays at reach and no box within it is skipped).
      seam_bvh.nearest_if(p, [&](Index st) {
        const Index t = seam_tri_id[st];
        if (tri_island[t] != ii) return false;
        const Vec2 gap = (seam_uv_box[st][0] - uv_out[k]).cwiseMax(uv_out[k] - seam_uv_box[st][1]).cwiseMax(0.0);
        if (gap.norm() >= e) return false;
        const TrianglePoint q = closest_point_on_triangle(seam_frame[st], p);
        if (q.distance_sq <= reach * reach)
          e = std::min(e, (uv_out[k] - uv_at(input, soup_in, first_in, t, q.point)).norm());
        return false;
      }, kInvalidIndex, std::nextafter(reach * reach, std::numeric_limits<double>::infinity()));
      err[k] = e / diag;
    }
  });
  Sum s;
  double mx = 0.0;
  for (double e : err) {
    if (std::isnan(e)) continue;
    s.add(e);
    mx = std::max(mx, e);
    ++r.samples;
  }
  if (r.samples) {
    r.mean = s.value() / static_cast<double>(r.samples);
    r.max = mx;
  }
  return r;
}

struct UvStretch {
  double median = kNaN, p90 = kNaN;  ///< area-weighted quantiles of the normalised L2 stretch
  std::uint64_t skipped = 0;         ///< fan triangles without UVs or without UV area
};

/// Sander, Snyder, Gortler, Hoppe 2001 ("Texture mapping progressive meshes"), §3: per triangle
/// the Jacobian of UV → surface, S_s and S_t, and L2 = √((|S_s|² + |S_t|²) / 2), times
/// √(Σ A_uv / Σ A) so that the map's scale drops out (1 = no distortion). Their mesh norm, the
/// area-weighted root mean square, is dominated by a single sliver of UV (a triangle of near-zero
/// UV area has near-infinite stretch: corpus outputs reached 1e23), so the quantiles over the
/// surface area are reported: the median and the 90th percentile. Fan triangles of each face,
/// the mesh's first UV set.
UvStretch uv_stretch(const PolyMesh& m) {
  UvStretch r;
  if (m.uv_sets.empty()) return r;
  const UvSet& set = m.uv_sets[0];
  std::vector<std::pair<double, double>> l2_area;  // per triangle: unnormalised L2, surface area
  double sum_area = 0.0, sum_uv_area = 0.0;
  for (Index f = 0; f < m.num_faces(); ++f) {
    const Index b = m.face_begin(f), k = m.face_size(f);
    for (Index j = 1; j + 1 < k; ++j) {
      const Index c[3] = {b, b + j, b + j + 1};
      if (set.corner[c[0]] == kInvalidIndex || set.corner[c[1]] == kInvalidIndex || set.corner[c[2]] == kInvalidIndex) {
        ++r.skipped;
        continue;
      }
      const Vec3& q1 = m.positions[m.corner_vertex[c[0]]];
      const Vec3& q2 = m.positions[m.corner_vertex[c[1]]];
      const Vec3& q3 = m.positions[m.corner_vertex[c[2]]];
      const Vec2& u1 = set.values[set.corner[c[0]]];
      const Vec2& u2 = set.values[set.corner[c[1]]];
      const Vec2& u3 = set.values[set.corner[c[2]]];
      const double uv_area2 = (u2.x() - u1.x()) * (u3.y() - u1.y()) - (u3.x() - u1.x()) * (u2.y() - u1.y());
      const double area = 0.5 * (q2 - q1).cross(q3 - q1).norm();
      const Vec3 ss = (q1 * (u2.y() - u3.y()) + q2 * (u3.y() - u1.y()) + q3 * (u1.y() - u2.y())) / uv_area2;
      const Vec3 st = (q1 * (u3.x() - u2.x()) + q2 * (u1.x() - u3.x()) + q3 * (u2.x() - u1.x())) / uv_area2;
      const double l2 = std::sqrt(0.5 * (ss.squaredNorm() + st.squaredNorm()));
      if (!(std::abs(uv_area2) > 0.0) || !std::isfinite(l2)) {
        ++r.skipped;
        continue;
      }
      l2_area.emplace_back(l2, area);
      sum_area += area;
      sum_uv_area += 0.5 * std::abs(uv_area2);
    }
  }
  if (!(sum_area > 0.0)) return r;
  std::sort(l2_area.begin(), l2_area.end());
  const double scale = std::sqrt(sum_uv_area / sum_area);
  auto quantile = [&](double q) {
    double acc = 0.0;
    for (const auto& [l2, area] : l2_area) {
      acc += area;
      if (acc >= q * sum_area) return l2 * scale;
    }
    return l2_area.back().first * scale;
  };
  r.median = quantile(0.5);
  r.p90 = quantile(0.9);
  return r;
}

}  // namespace

/// §6c: every metric of the features section, on the scaled copies (in, out) for geometry and the
/// originals (input, output) for UVs and materials; the same vertex and face ids.
void feature_metrics(const PolyMesh& input, const PolyMesh& output, const PolyMesh& in,
                     const PolyMesh& out, const TriangleSoup& soup_in, const TriangleSoup& soup_out,
                     const SurfaceSamples& s_out, const Directed& d_out, const TriangleBvh& bvh_in,
                     const EvalParams& params, unsigned threads, EvalResult& r) {
  const std::vector<Index>& nearest_in = d_out.nearest;
  MeshFeatures fin, fout;
  run_both(
      threads, [&] { fin = mesh_features(input); }, [&] { fout = mesh_features(output); });
  r.uv_islands_in = fin.islands_with_area;
  r.uv_islands_out = fout.islands_with_area;
  const int seam = std::countr_zero(unsigned{kFeatureUvSeam});
  const int boundary = std::countr_zero(unsigned{kFeatureBoundary});
  r.seam_edges_in = fin.fe.edges_with_bit[seam];
  r.seam_edges_out = fout.fe.edges_with_bit[seam];
  r.boundary_edges_in = fin.fe.edges_with_bit[boundary];
  r.boundary_edges_out = fout.fe.edges_with_bit[boundary];
  r.feature_edges_in = fin.fe.feature_edges;
  r.feature_edges_out = fout.fe.feature_edges;

  r.seams_torn = count_torn(in, fin, out, fout, params.feature_tolerance);

  r.uv_error_mean = r.uv_error_max = kNaN;
  if (input.has_uvs() && output.has_uvs()) {
    const UvErrorResult u =
        uv_error(input, output, in, out, fin, fout, soup_in, soup_out, s_out, d_out, bvh_in, threads);
    r.uv_error_mean = u.mean;
    r.uv_error_max = u.max;
    r.uv_samples = u.samples;
    const IslandMatch m = match_islands(input, output, out, fin, fout, soup_in, soup_out, bvh_in, threads);
    r.uv_islands_vanished = m.vanished;
    r.uv_islands_merged = m.merged;
    r.uv_islands_split = m.split;
  }
  r.uv_stretch_median_in = r.uv_stretch_median_out = r.uv_stretch_p90_in = r.uv_stretch_p90_out = kNaN;
  if (input.has_uvs() && output.has_uvs()) {
    const UvStretch sin = uv_stretch(input), sout = uv_stretch(output);
    r.uv_stretch_median_in = sin.median;
    r.uv_stretch_median_out = sout.median;
    r.uv_stretch_p90_in = sin.p90;
    r.uv_stretch_p90_out = sout.p90;
    r.uv_stretch_skipped_out = sout.skipped;
  }

  // Material borders, keyed by the unordered pair of names.
  using Pair = std::pair<std::string, std::string>;
  auto pair_of = [](const PolyMesh& m, const MeshFeatures& mf, Index e) {
    const auto cs = mf.conn.corners_of_edge(e);
    std::string a(material_name(m, mf.conn.corner_face[cs[0]])), b(material_name(m, mf.conn.corner_face[cs[1]]));
    return a < b ? Pair{a, b} : Pair{b, a};
  };
  std::map<Pair, std::vector<Segment>> border_segments;
  for (Index e = 0; e < fin.conn.num_edges; ++e)
    if (fin.fe.edge_bits[e] & kFeatureMaterialBorder)
      border_segments[pair_of(input, fin, e)].push_back(edge_segment(in, fin.conn, e));
  std::map<Pair, SegmentBvh> borders_in;
  for (const auto& [key, segs] : border_segments) borders_in.emplace(key, SegmentBvh(segs));
  std::vector<Index> border_out, feature_out;
  for (Index e = 0; e < fout.conn.num_edges; ++e) {
    if (fout.fe.edge_bits[e] & kFeatureMaterialBorder) border_out.push_back(e);
    if (fout.fe.edge_bits[e]) feature_out.push_back(e);
  }
  r.material_border_edges_out = border_out.size();
  const SegmentBvh none;
  const EdgeDeviation border = edge_deviation(out, fout.conn, border_out, [&](Index e) -> const SegmentBvh& {
    const auto it = borders_in.find(pair_of(output, fout, e));
    return it == borders_in.end() ? none : it->second;
  });
  r.material_border_error = border.max;
  r.material_border_error_mean = border.mean;

  r.material_mismatch_fraction = kNaN;
  if (!input.face_material.empty() || !output.face_material.empty()) {
    std::uint64_t mismatched = 0;
    for (std::size_t k = 0; k < s_out.points.size(); ++k)
      mismatched += material_name(output, soup_out.face[s_out.triangle[k]]) !=
                    material_name(input, soup_in.face[nearest_in[k]]);
    r.material_mismatch_fraction = static_cast<double>(mismatched) / static_cast<double>(s_out.points.size());
  }

  const SegmentBvh features_in = feature_segments(in, fin, [&](Index e) { return fin.fe.is_feature(e); });
  const EdgeDeviation dev =
      edge_deviation(out, fout.conn, feature_out, [&](Index) -> const SegmentBvh& { return features_in; });
  r.feature_deviation_max = dev.max;
  r.feature_deviation_mean = dev.mean;
}

}  // namespace quadlod::eval_detail
