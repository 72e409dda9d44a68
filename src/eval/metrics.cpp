// `quadlod eval`: Chamfer, Hausdorff, QPR, PCCD and flow deviation (docs/metrics.md is the
// definition; this file implements exactly that and names the section it implements).
//
// Papers: Zhang et al., "Quad-dominant mesh reduction via ILP" §4.1 (normalisation, Chamfer,
// Hausdorff, QPR, PCCD); Knodt 2025 (QPR); Ericson 2005 §5.1.5 (closest point, in geometry/bvh).
//
// Data flow:
//   input, output ──scale by the input's bbox──► scaled copies
//     ├─ fan triangulation ─► TriangleBvh (one per mesh)
//     ├─ area-weighted samples (stream 0 = input, 1 = output) + used vertices
//     │     └─ nearest point on the other mesh (parallel, one slot per sample) ─► Chamfer, Hausdorff
//     │                                                                      └─► flow (output side)
//     └─ poly-chords ─► medial curves ─► arc-length samples ─► SegmentBvh ─► PCCD
// Queries run in fixed chunks of Morton-ordered points, each chunk warm-starting every search
// from the previous answer; every query writes its own slot and every reduction runs serially in
// sample order afterwards, so the numbers do not depend on the thread count (docs/metrics.md §7).
//
// The features section (§6c: seams, UV islands, UV error, materials, feature lines) is in
// feature_metrics.cpp; what both files share is in metrics_common.h.
#include "quadlod/metrics.h"

#include "eval/hausdorff_bound.h"
#include "eval/metrics_common.h"
#include "geometry/bvh.h"
#include "geometry/sampling.h"
#include "mesh/connectivity.h"
#include "topology/polychords.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <numbers>
#include <thread>

namespace quadlod {

namespace eval_detail {

PolyMesh scaled_copy(const PolyMesh& m, const Vec3& centre, double s) {
  PolyMesh out;
  out.positions.resize(m.positions.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) out.positions[i] = (m.positions[i] - centre) * s;
  out.face_offsets = m.face_offsets;
  out.corner_vertex = m.corner_vertex;
  return out;
}

}  // namespace eval_detail

using eval_detail::scaled_copy;

using eval_detail::Directed;
using eval_detail::feature_metrics;
using eval_detail::kNaN;
using eval_detail::morton_order;
using eval_detail::parallel_chunks;
using eval_detail::run_both;
using eval_detail::Sum;

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
/// PCCD when exactly one mesh has medial curves (docs/metrics.md §5): the longest side of the
/// normalised input bbox, larger than any PCCD between overlapping meshes in practice.
constexpr double kPccdMissingCurvesPenalty = 1.0;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}


/// Vertices used by at least one face, in increasing id order.
std::vector<Vec3> used_vertices(const PolyMesh& m) {
  std::vector<char> used(m.num_vertices(), 0);
  for (Index v : m.corner_vertex) used[v] = 1;
  std::vector<Vec3> out;
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (used[v]) out.push_back(m.positions[v]);
  return out;
}

std::string check_mesh(const PolyMesh& m, const char* name) {
  if (std::string e = m.check_layout(); !e.empty()) return std::string(name) + ": " + e;
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (!m.positions[v].allFinite())
      return std::string(name) + ": vertex " + std::to_string(v) + " has a non-finite coordinate";
  if (m.num_faces() == 0) return std::string(name) + ": no faces";
  return {};
}

}  // namespace

/// Query order: points sorted by their 63-bit Morton code in the points' bounding box (ties by
/// index), so consecutive queries are close and each can start from its predecessor's answer.
std::vector<std::uint32_t> eval_detail::morton_order(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  const std::size_t n = a.size() + b.size();
  auto at = [&](std::size_t i) -> const Vec3& { return i < a.size() ? a[i] : b[i - a.size()]; };
  BoundingBox box;
  for (std::size_t i = 0; i < n; ++i) box.extend(at(i));
  const Vec3 ext = box.extent();
  auto spread = [](std::uint64_t x) {  // 21 bits → every third bit
    x &= 0x1FFFFF;
    x = (x | x << 32) & 0x1F00000000FFFFULL;
    x = (x | x << 16) & 0x1F0000FF0000FFULL;
    x = (x | x << 8) & 0x100F00F00F00F00FULL;
    x = (x | x << 4) & 0x10C30C30C30C30C3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double t = ext[k] > 0.0 ? (at(i)[k] - box.min[k]) / ext[k] : 0.0;
      const auto q = static_cast<std::uint64_t>(std::clamp(t, 0.0, 1.0) * 2097151.0);
      code |= spread(q) << k;
    }
    keyed[i] = {code, static_cast<std::uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

namespace {

Directed directed_distances(const std::vector<Vec3>& samples, const std::vector<Vec3>& extra,
                            const TriangleBvh& target, unsigned threads) {
  Directed r;
  const std::size_t n = samples.size();
  r.dist.resize(n);
  r.nearest.resize(n);
  std::vector<double> extra_d(extra.size());
  const std::vector<std::uint32_t> order = morton_order(samples, extra);
  parallel_chunks(order.size(), threads, [&](std::size_t begin, std::size_t end) {
    Index hint = kInvalidIndex;
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t i = order[k];
      const NearestHit h = target.nearest(i < n ? samples[i] : extra[i - n], hint);
      hint = h.primitive;
      if (i < n) {
        r.dist[i] = std::sqrt(h.distance_sq);
        r.nearest[i] = h.primitive;
      } else {
        extra_d[i - n] = std::sqrt(h.distance_sq);
      }
    }
  });
  Sum s, s2;
  double mx = 0.0;
  for (double d : r.dist) {
    s.add(d);
    s2.add(d * d);
    mx = std::max(mx, d);
  }
  for (double d : extra_d) mx = std::max(mx, d);
  r.mean = n ? s.value() / static_cast<double>(n) : kNaN;
  r.mean_sq = n ? s2.value() / static_cast<double>(n) : kNaN;
  r.max = mx;
  return r;
}

// --- PCCD (§5) ----------------------------------------------------------------------------------

struct Curves {
  std::vector<std::array<Vec3, 2>> segments;
  std::uint64_t chords = 0;
};

/// Medial curves of every poly-chord as segments: consecutive medial points, plus the closing
/// segment (last → first) of a closed chord.
Curves medial_curves(const PolyMesh& scaled) {
  Curves c;
  const Connectivity conn = build_connectivity(scaled);
  const PolyChordResult pcs = extract_polychords(scaled, conn);
  c.chords = pcs.chords.size();
  for (const PolyChord& chord : pcs.chords) {
    const std::vector<Vec3> pts = medial_curve(scaled, conn, chord);
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) c.segments.push_back({pts[i], pts[i + 1]});
    if (chord.closed && pts.size() >= 2) c.segments.push_back({pts.back(), pts.front()});
  }
  return c;
}

double mean_curve_distance(const std::vector<Vec3>& samples, const SegmentBvh& target,
                           unsigned threads) {
  // Samples are in arc-length order along the curves: already coherent, no sorting needed.
  std::vector<double> d(samples.size());
  parallel_chunks(samples.size(), threads, [&](std::size_t begin, std::size_t end) {
    Index hint = kInvalidIndex;
    for (std::size_t i = begin; i < end; ++i) {
      const NearestHit h = target.nearest(samples[i], hint);
      hint = h.primitive;
      d[i] = std::sqrt(h.distance_sq);
    }
  });
  Sum s;
  for (double x : d) s.add(x);
  return s.value() / static_cast<double>(samples.size());
}

// --- flow (§6) -------------------------------------------------------------------------------------

/// Edge directions of a quad as unoriented lines: d1 = (p1 − p0) + (p2 − p3) (the mean of the
/// opposite edges p0p1 and p3p2, up to a factor 2), d2 = (p2 − p1) + (p3 − p0); n = unit Newell
/// normal (zero for a zero-area quad).
struct QuadFrame {
  Vec3 d1, d2, n;
};

QuadFrame quad_frame(const PolyMesh& m, Index f) {
  const auto v = m.face_vertices(f);
  const Vec3 &p0 = m.positions[v[0]], &p1 = m.positions[v[1]], &p2 = m.positions[v[2]],
             &p3 = m.positions[v[3]];
  return {(p1 - p0) + (p2 - p3), (p2 - p1) + (p3 - p0), face_normal(m, f)};
}

/// Angle in degrees between two lines (unoriented): atan2(|a × b|, |a · b|) ∈ [0°, 90°]
/// (the same value as acos(|a·b| / |a||b|), accurate near 0°).
double line_angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b))) * kDeg;
}

Vec3 project_to_plane(const Vec3& v, const Vec3& n) { return v - v.dot(n) * n; }

}  // namespace

// --- face counts and QPR (§4) ------------------------------------------------------------------------

FaceCounts count_faces(const PolyMesh& mesh) {
  FaceCounts c;
  c.faces = mesh.num_faces();
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Index k = mesh.face_size(f);
    if (k == 3) ++c.tris;
    else if (k == 4) ++c.quads;
    else if (k > 4) ++c.ngons;
    c.tri_equivalent += tri_equivalent(k);
  }
  return c;
}

double quad_preservation_ratio(const FaceCounts& in, const FaceCounts& out, std::string* rule) {
  const double qi = static_cast<double>(in.quads), ti = static_cast<double>(in.tris);
  const double qo = static_cast<double>(out.quads), to = static_cast<double>(out.tris);
  auto name = [&](const char* r) {
    if (rule) *rule = r;
  };
  if (in.quads == 0) {  // nothing to preserve
    name("no_input_quads");
    return 1.0;
  }
  if (out.quads == 0) {
    name("no_output_quads");
    return 0.0;
  }
  if (in.tris > 0 && out.tris > 0) {  // the paper's formula
    name("ratio");
    return (qo * ti) / (to * qi);
  }
  if (in.tris == 0) {  // input odds infinite: output quad share among quads + tris
    name("input_tri_free");
    return qo / (qo + to);
  }
  // out.tris == 0, in.tris > 0: the ratio with half an output triangle (continuity correction).
  name("output_tri_free");
  return (qo * ti) / (0.5 * qi);
}

// --- evaluate ----------------------------------------------------------------------------------------

EvalResult evaluate(const PolyMesh& input, const PolyMesh& output, const EvalParams& params) {
  const auto t0 = Clock::now();
  EvalResult r;
  r.seed = params.seed;
  r.threads = params.threads ? params.threads : std::max(1u, std::thread::hardware_concurrency());
  const unsigned threads = r.threads;
  auto fail = [&](std::string e) {
    r.error = std::move(e);
    r.chamfer = r.chamfer_sq = r.mean_in_to_out = r.mean_out_to_in = kNaN;
    r.hausdorff = r.hausdorff_in_to_out = r.hausdorff_out_to_in = kNaN;
    r.qpr = r.quad_fraction_in = r.quad_fraction_out = kNaN;
    r.pccd = r.pccd_in_to_out = r.pccd_out_to_in = kNaN;
    r.flow_deviation_deg = r.flow_deviation_p90_deg = r.flow_coverage = kNaN;
    r.uv_error_mean = r.uv_error_max = r.material_border_error = r.material_border_error_mean = kNaN;
    r.uv_stretch_median_in = r.uv_stretch_median_out = r.uv_stretch_p90_in = r.uv_stretch_p90_out = kNaN;
    r.material_mismatch_fraction = r.feature_deviation_max = r.feature_deviation_mean = kNaN;
    r.seconds = seconds_since(t0);
    return r;
  };
  if (std::string e = check_mesh(input, "input"); !e.empty()) return fail(e);
  if (std::string e = check_mesh(output, "output"); !e.empty()) return fail(e);
  if (params.samples == 0) return fail("samples must be positive");

  // §1 normalisation.
  const BoundingBox box = bounding_box(input);
  const double side = box.longest_side();
  if (!(side > 0.0)) return fail("input: bounding box has zero size");
  r.scale = 1.0 / side;
  const Vec3 centre = 0.5 * (box.min + box.max);
  const PolyMesh in = scaled_copy(input, centre, r.scale);
  const PolyMesh out = scaled_copy(output, centre, r.scale);

  // §4 counts and QPR (no geometry needed).
  r.counts_in = count_faces(in);
  r.counts_out = count_faces(out);
  r.qpr = quad_preservation_ratio(r.counts_in, r.counts_out, &r.qpr_rule);
  r.quad_fraction_in = static_cast<double>(r.counts_in.quads) / static_cast<double>(r.counts_in.faces);
  r.quad_fraction_out =
      static_cast<double>(r.counts_out.quads) / static_cast<double>(r.counts_out.faces);

  // §2–3 surface samples and distances.
  const auto t_dist = Clock::now();
  TriangleSoup soup_in, soup_out;
  SurfaceSamples s_in, s_out;
  TriangleBvh bvh_in, bvh_out;
  run_both(
      threads,
      [&] {
        soup_in = fan_triangulate(in);
        s_in = sample_triangles(soup_in, params.samples, params.seed, 0);
        bvh_in = TriangleBvh(soup_in.triangles);
      },
      [&] {
        soup_out = fan_triangulate(out);
        s_out = sample_triangles(soup_out, params.samples, params.seed, 1);
        bvh_out = TriangleBvh(soup_out.triangles);
      });
  r.area_in = s_in.total_area;
  r.area_out = s_out.total_area;
  if (!(r.area_in > 0.0)) return fail("input: zero surface area");
  if (!(r.area_out > 0.0)) return fail("output: zero surface area");
  const std::vector<Vec3> verts_in = used_vertices(in);
  const std::vector<Vec3> verts_out = used_vertices(out);
  r.samples_in = s_in.points.size();
  r.samples_out = s_out.points.size();
  r.vertex_samples_in = verts_in.size();
  r.vertex_samples_out = verts_out.size();

  const Directed d_in = directed_distances(s_in.points, verts_in, bvh_out, threads);
  const Directed d_out = directed_distances(s_out.points, verts_out, bvh_in, threads);
  r.mean_in_to_out = d_in.mean;
  r.mean_out_to_in = d_out.mean;
  r.chamfer = 0.5 * (d_in.mean + d_out.mean);
  r.chamfer_sq = 0.5 * (d_in.mean_sq + d_out.mean_sq);
  r.hausdorff_in_to_out = d_in.max;
  r.hausdorff_out_to_in = d_out.max;
  r.hausdorff = std::max(d_in.max, d_out.max);
  if (params.hausdorff_tolerance > 0.0) {
    eval_detail::HausdorffBoundParams hp;
    hp.tolerance = params.hausdorff_tolerance;
    eval_detail::HausdorffBound b_in, b_out;
    run_both(
        threads, [&] { b_in = eval_detail::directed_hausdorff_bound(soup_in.triangles, bvh_out, soup_out.triangles, hp); },
        [&] { b_out = eval_detail::directed_hausdorff_bound(soup_out.triangles, bvh_in, soup_in.triangles, hp); });
    r.hausdorff_bounded = true;
    r.hausdorff_converged = b_in.converged && b_out.converged;
    r.hausdorff_in_to_out = b_in.lower;
    r.hausdorff_out_to_in = b_out.lower;
    r.hausdorff = std::max(b_in.lower, b_out.lower);
    r.hausdorff_upper = std::max(b_in.upper, b_out.upper);
    r.hausdorff_queries = b_in.queries + b_out.queries;
    r.hausdorff_point_on_output = b_out.lower > b_in.lower;
    r.hausdorff_point = (r.hausdorff_point_on_output ? b_out.at : b_in.at) / r.scale + centre;
  }
  r.seconds_distance = seconds_since(t_dist);

  // §6b orientation: an output face is flipped when the nearest input surface that faces its way
  // is more than twice as far (plus flip_tolerance) as the nearest input surface: coincident
  // two-sided input and faces lying between two close sheets are not counted. An output face
  // that IS an input face (same corners, same positions, same order) replaces nothing: if the
  // rule flags it, the input was already like that (folded quads whose fan triangles disagree
  // with their Newell normal) and it is counted apart, in flipped_faces_kept.
  {
    std::vector<Vec3> normal_in(soup_in.triangles.size());
    for (std::size_t t = 0; t < soup_in.triangles.size(); ++t) {
      const auto& tri = soup_in.triangles[t];
      normal_in[t] = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    }
    // Built on the first flagged face only: input vertices as points, input faces by corner cycle.
    SegmentBvh input_points;
    std::set<std::vector<Index>> input_cycles;
    auto canonical = [](std::vector<Index> cycle) {
      std::rotate(cycle.begin(), std::min_element(cycle.begin(), cycle.end()), cycle.end());
      return cycle;
    };
    auto is_input_face = [&](Index f) {
      if (input_points.size() == 0) {
        std::vector<std::array<Vec3, 2>> pts(in.positions.size());
        for (std::size_t v = 0; v < pts.size(); ++v) pts[v] = {in.positions[v], in.positions[v]};
        input_points = SegmentBvh(pts);
        for (Index g = 0; g < in.num_faces(); ++g) {
          const auto vs = in.face_vertices(g);
          input_cycles.insert(canonical({vs.begin(), vs.end()}));
        }
      }
      // Positions are normalised (longest side 1); 1e-9 absorbs the text round trip of 9 digits.
      std::vector<Index> cycle;
      for (Index v : out.face_vertices(f)) {
        const NearestHit h = input_points.nearest(out.positions[v]);
        if (h.primitive == kInvalidIndex || h.distance_sq > 1e-18) return false;
        cycle.push_back(h.primitive);
      }
      return input_cycles.count(canonical(std::move(cycle))) > 0;
    };
    for (Index f = 0; f < out.num_faces(); ++f) {
      const Vec3 n_out = face_area_vector(out, f);
      if (n_out.isZero(0.0)) continue;
      const Vec3 c = face_centroid(out, f);
      const NearestHit any = bvh_in.nearest(c);
      if (any.primitive == kInvalidIndex) continue;
      const NearestHit agreeing = bvh_in.nearest_if(c, [&](Index t) { return normal_in[t].dot(n_out) >= 0.0; });
      if (agreeing.primitive == kInvalidIndex ||
          std::sqrt(agreeing.distance_sq) > 2.0 * std::sqrt(any.distance_sq) + params.flip_tolerance)
        ++(is_input_face(f) ? r.flipped_faces_kept : r.flipped_faces);
    }
  }

  // §6 flow deviation on the output samples that lie on quads.
  {
    std::vector<char> frame_done_in(in.num_faces(), 0), frame_done_out(out.num_faces(), 0);
    std::vector<QuadFrame> frame_in(in.num_faces()), frame_out(out.num_faces());
    auto frame = [](const PolyMesh& m, Index f, std::vector<char>& done, std::vector<QuadFrame>& fr)
        -> const QuadFrame& {
      if (!done[f]) {
        fr[f] = quad_frame(m, f);
        done[f] = 1;
      }
      return fr[f];
    };
    const double min_cos = std::cos(params.flow_max_normal_angle_deg / kDeg);
    std::vector<double> dev;
    dev.reserve(s_out.points.size());
    for (std::size_t k = 0; k < s_out.points.size(); ++k) {
      const Index fo = soup_out.face[s_out.triangle[k]];
      if (out.face_size(fo) != 4 || d_out.nearest[k] == kInvalidIndex) continue;
      const Index fi = soup_in.face[d_out.nearest[k]];
      if (in.face_size(fi) != 4) continue;
      const QuadFrame& qo = frame(out, fo, frame_done_out, frame_out);
      const QuadFrame& qi = frame(in, fi, frame_done_in, frame_in);
      if (qo.n.isZero(0.0) || qi.n.isZero(0.0)) continue;
      if (std::abs(qo.n.dot(qi.n)) < min_cos) continue;
      const Vec3 a1 = project_to_plane(qo.d1, qi.n), a2 = project_to_plane(qo.d2, qi.n);
      const Vec3 b1 = project_to_plane(qi.d1, qi.n), b2 = project_to_plane(qi.d2, qi.n);
      if (a1.isZero(0.0) || a2.isZero(0.0) || b1.isZero(0.0) || b2.isZero(0.0)) continue;
      const double straight = 0.5 * (line_angle_deg(a1, b1) + line_angle_deg(a2, b2));
      const double crossed = 0.5 * (line_angle_deg(a1, b2) + line_angle_deg(a2, b1));
      dev.push_back(std::min(straight, crossed));
    }
    r.flow_samples = dev.size();
    r.flow_coverage = static_cast<double>(dev.size()) / static_cast<double>(s_out.points.size());
    if (dev.empty()) {
      r.flow_deviation_deg = r.flow_deviation_p90_deg = kNaN;
    } else {
      Sum s;
      for (double x : dev) s.add(x);
      r.flow_deviation_deg = s.value() / static_cast<double>(dev.size());
      // Nearest rank: the ceil(0.9·n)-th smallest value.
      const std::size_t rank = (9 * dev.size() + 9) / 10;
      std::nth_element(dev.begin(), dev.begin() + (rank - 1), dev.end());
      r.flow_deviation_p90_deg = dev[rank - 1];
    }
  }

  // §6c features, UVs, materials.
  const auto t_features = Clock::now();
  feature_metrics(input, output, in, out, soup_in, soup_out, s_out, d_out, bvh_in, params, threads, r);
  r.seconds_features = seconds_since(t_features);

  // §5 PCCD.
  const auto t_pccd = Clock::now();
  Curves c_in, c_out;
  run_both(
      threads, [&] { c_in = medial_curves(in); }, [&] { c_out = medial_curves(out); });
  r.chords_in = c_in.chords;
  r.chords_out = c_out.chords;
  CurveSamples cs_in = sample_segments_by_arc_length(c_in.segments, params.curve_samples);
  CurveSamples cs_out = sample_segments_by_arc_length(c_out.segments, params.curve_samples);
  r.curve_length_in = cs_in.total_length;
  r.curve_length_out = cs_out.total_length;
  r.curve_samples_in = cs_in.points.size();
  r.curve_samples_out = cs_out.points.size();
  const bool has_in = !cs_in.points.empty(), has_out = !cs_out.points.empty();
  if (has_in && has_out) {
    SegmentBvh seg_in, seg_out;
    run_both(
        threads, [&] { seg_in = SegmentBvh(c_in.segments); },
        [&] { seg_out = SegmentBvh(c_out.segments); });
    r.pccd_in_to_out = mean_curve_distance(cs_in.points, seg_out, threads);
    r.pccd_out_to_in = mean_curve_distance(cs_out.points, seg_in, threads);
    r.pccd = 0.5 * (r.pccd_in_to_out + r.pccd_out_to_in);
    r.pccd_defined = true;
  } else {
    r.pccd_defined = false;
    r.pccd_in_to_out = r.pccd_out_to_in = kNaN;
    r.pccd = (has_in || has_out) ? kPccdMissingCurvesPenalty : 0.0;
  }
  r.seconds_pccd = seconds_since(t_pccd);

  r.seconds = seconds_since(t0);
  return r;
}

// --- JSON ---------------------------------------------------------------------------------------------

nlohmann::json to_json(const EvalResult& r) {
  auto num = [](double x) -> nlohmann::json {
    if (std::isfinite(x)) return x;
    return nullptr;
  };
  nlohmann::json j;
  j["ok"] = r.ok();
  if (!r.ok()) j["error"] = r.error;
  j["scale"] = num(r.scale);
  j["area_in"] = num(r.area_in);
  j["area_out"] = num(r.area_out);
  j["chamfer"] = num(r.chamfer);
  j["chamfer_sq"] = num(r.chamfer_sq);
  j["mean_in_to_out"] = num(r.mean_in_to_out);
  j["mean_out_to_in"] = num(r.mean_out_to_in);
  j["hausdorff"] = num(r.hausdorff);
  j["hausdorff_in_to_out"] = num(r.hausdorff_in_to_out);
  j["hausdorff_out_to_in"] = num(r.hausdorff_out_to_in);
  if (r.hausdorff_bounded) {  // only then, so the JSON of a default eval does not change
    j["hausdorff_upper"] = num(r.hausdorff_upper);
    j["hausdorff_converged"] = r.hausdorff_converged;
    j["hausdorff_queries"] = r.hausdorff_queries;
    // Where the distance is attained (input units), and on which mesh: what to look at.
    j["hausdorff_point"] = {r.hausdorff_point.x(), r.hausdorff_point.y(), r.hausdorff_point.z()};
    j["hausdorff_on"] = r.hausdorff_point_on_output ? "output" : "input";
  }
  j["qpr"] = num(r.qpr);
  j["qpr_rule"] = r.qpr_rule;
  j["quad_fraction_in"] = num(r.quad_fraction_in);
  j["quad_fraction_out"] = num(r.quad_fraction_out);
  auto counts = [&](const FaceCounts& c, const std::string& suffix) {
    j["faces" + suffix] = c.faces;
    j["tris" + suffix] = c.tris;
    j["quads" + suffix] = c.quads;
    j["ngons" + suffix] = c.ngons;
    j["tri_equivalent" + suffix] = c.tri_equivalent;
  };
  counts(r.counts_in, "_in");
  counts(r.counts_out, "_out");
  j["pccd"] = num(r.pccd);
  j["pccd_defined"] = r.pccd_defined;
  j["pccd_in_to_out"] = num(r.pccd_in_to_out);
  j["pccd_out_to_in"] = num(r.pccd_out_to_in);
  j["chords_in"] = r.chords_in;
  j["chords_out"] = r.chords_out;
  j["curve_length_in"] = num(r.curve_length_in);
  j["curve_length_out"] = num(r.curve_length_out);
  j["flow_deviation_deg"] = num(r.flow_deviation_deg);
  j["flow_deviation_p90_deg"] = num(r.flow_deviation_p90_deg);
  j["flow_coverage"] = num(r.flow_coverage);
  j["flipped_faces"] = r.flipped_faces;
  j["flipped_faces_kept"] = r.flipped_faces_kept;
  j["uv_islands_in"] = r.uv_islands_in;
  j["uv_islands_out"] = r.uv_islands_out;
  j["uv_islands_vanished"] = r.uv_islands_vanished;
  j["uv_islands_merged"] = r.uv_islands_merged;
  j["uv_islands_split"] = r.uv_islands_split;
  j["seams_torn"] = r.seams_torn;
  j["seam_edges_in"] = r.seam_edges_in;
  j["seam_edges_out"] = r.seam_edges_out;
  j["boundary_edges_in"] = r.boundary_edges_in;
  j["boundary_edges_out"] = r.boundary_edges_out;
  j["uv_error_mean"] = num(r.uv_error_mean);
  j["uv_error_max"] = num(r.uv_error_max);
  j["uv_samples"] = r.uv_samples;
  j["uv_stretch_median_in"] = num(r.uv_stretch_median_in);
  j["uv_stretch_median_out"] = num(r.uv_stretch_median_out);
  j["uv_stretch_p90_in"] = num(r.uv_stretch_p90_in);
  j["uv_stretch_p90_out"] = num(r.uv_stretch_p90_out);
  j["uv_stretch_skipped_out"] = r.uv_stretch_skipped_out;
  j["material_border_error"] = num(r.material_border_error);
  j["material_border_error_mean"] = num(r.material_border_error_mean);
  j["material_border_edges_out"] = r.material_border_edges_out;
  j["material_mismatch_fraction"] = num(r.material_mismatch_fraction);
  j["feature_deviation_max"] = num(r.feature_deviation_max);
  j["feature_deviation_mean"] = num(r.feature_deviation_mean);
  j["feature_edges_in"] = r.feature_edges_in;
  j["feature_edges_out"] = r.feature_edges_out;
  j["seed"] = r.seed;
  j["samples_in"] = r.samples_in;
  j["samples_out"] = r.samples_out;
  j["vertex_samples_in"] = r.vertex_samples_in;
  j["vertex_samples_out"] = r.vertex_samples_out;
  j["curve_samples_in"] = r.curve_samples_in;
  j["curve_samples_out"] = r.curve_samples_out;
  j["flow_samples"] = r.flow_samples;
  j["threads"] = r.threads;
  j["seconds"] = num(r.seconds);
  j["seconds_distance"] = num(r.seconds_distance);
  j["seconds_pccd"] = num(r.seconds_pccd);
  j["seconds_features"] = num(r.seconds_features);
  return j;
}

}  // namespace quadlod
