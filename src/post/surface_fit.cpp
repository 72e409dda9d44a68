// The final fit of the output's vertices to the input surface: see surface_fit.h.
#include "post/surface_fit.h"

#include "geometry/bvh.h"
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "mesh/symmetry.h"
#include "post/cluster_collapse.h"
#include "util/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace quadlod {
namespace {

struct FanTriangle {
  std::array<Index, 3> v;
};

std::vector<FanTriangle> fan_triangles(const PolyMesh& m) {
  std::vector<FanTriangle> t;
  t.reserve(m.corner_vertex.size());
  for (Index f = 0; f < m.num_faces(); ++f) {
    const auto fv = m.face_vertices(f);
    for (std::size_t k = 1; k + 1 < fv.size(); ++k) t.push_back({{fv[0], fv[k], fv[k + 1]}});
  }
  return t;
}

Vec3 area_vector(const std::vector<Vec3>& p, const FanTriangle& t) {
  return 0.5 * (p[t.v[1]] - p[t.v[0]]).cross(p[t.v[2]] - p[t.v[0]]);
}

double longest_edge(const std::vector<Vec3>& p, const FanTriangle& t) {
  return std::max({(p[t.v[1]] - p[t.v[0]]).norm(), (p[t.v[2]] - p[t.v[1]]).norm(), (p[t.v[0]] - p[t.v[2]]).norm()});
}

std::vector<std::array<Vec3, 3>> corners_of(const std::vector<Vec3>& p, const std::vector<FanTriangle>& tris) {
  std::vector<std::array<Vec3, 3>> c(tris.size());
  for (std::size_t i = 0; i < tris.size(); ++i) c[i] = {p[tris[i].v[0]], p[tris[i].v[1]], p[tris[i].v[2]]};
  return c;
}

// Barycentric points of a triangle: its centroid and the centroids of the three corner
// sub-triangles of its midpoint subdivision (a fixed, symmetric set: the output's samples; the
// input's are the first one or all four, see below). Four, not more: the queries are the fit's
// whole cost (7 points per output triangle and 4 per input one took 19 s of a 25 s reduction of
// assimp_suzanne_subdiv at 0.4 on one thread).
constexpr std::array<std::array<double, 3>, 4> kPoints = {{{1.0 / 3, 1.0 / 3, 1.0 / 3},
                                                           {2.0 / 3, 1.0 / 6, 1.0 / 6},
                                                           {1.0 / 6, 2.0 / 3, 1.0 / 6},
                                                           {1.0 / 6, 1.0 / 6, 2.0 / 3}}};

// Barycentric coordinates of x (a point of triangle abc) — for spreading a residual on the corners.
std::array<double, 3> barycentric(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e0 = b - a, e1 = c - a, d = x - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1), d20 = d.dot(e0), d21 = d.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 0.0)) return {1.0 / 3, 1.0 / 3, 1.0 / 3};
  const double v = std::clamp((d11 * d20 - d01 * d21) / den, 0.0, 1.0);
  const double w = std::clamp((d00 * d21 - d01 * d20) / den, 0.0, 1.0 - v);
  return {1.0 - v - w, v, w};
}

// The kinds of FeatureReference::by_kind, in its order.
constexpr std::array<std::uint8_t, 4> kLineKinds = {kFeatureBoundary, kFeatureNonManifold, kFeatureUvSeam,
                                                    kFeatureMaterialBorder};

// The closest point to p on the input's lines of the first of `kinds` that has any.
Vec3 onto_line(const FeatureReference& ref, std::uint8_t kinds, const Vec3& p) {
  for (std::size_t k = 0; k < kLineKinds.size(); ++k)
    if ((kinds & kLineKinds[k]) && ref.by_kind[k].size() > 0) return ref.by_kind[k].nearest(p).point;
  return p;
}

// eval's seams_torn rule for one output line edge a–b: its points at ¼, ½, ¾ lie within
// tolerance × |ab| of the input's lines of every one of its kinds.
bool on_input_lines(const FeatureReference& ref, std::uint8_t kinds, const Vec3& a, const Vec3& b, double tolerance,
                    double slack) {
  const double bound = tolerance * (b - a).norm() + slack;
  for (std::size_t k = 0; k < kLineKinds.size(); ++k) {
    if (!(kinds & kLineKinds[k]) || ref.by_kind[k].size() == 0) continue;
    for (double t : {0.25, 0.5, 0.75})
      if (ref.by_kind[k].nearest(a + t * (b - a)).distance_sq > bound * bound) return false;
  }
  return true;
}

}  // namespace

FitLines fit_lines(const PolyMesh& output, const Connectivity& conn, const FeatureEdges& features,
                   const FeatureReference& reference) {
  FitLines lines;
  lines.reference = &reference;
  const Index nv = output.num_vertices();
  lines.vertex_kinds.assign(nv, 0);
  lines.corners.assign(nv, 0);
  std::vector<Index> valence(nv, 0);
  for (Index e = 0; e < conn.num_edges; ++e) {
    // Strict lines, and the UV seams of a per-face layout (not strict, but held to the input's
    // seams by eval as any other: without this the fit tore 5–28 seams of opensubdiv_bishop_cage).
    if (!features.is_strict(e) && !(features.edge_bits[e] & kFeatureUvSeam)) continue;
    const std::uint8_t kinds = features.edge_bits[e] & kStrictFeatures;
    const auto [a, b] = conn.edge_vertices[e];
    lines.edges.push_back({a, b, kinds});
    for (Index v : {a, b}) {
      if (valence[v]++ > 0 && lines.vertex_kinds[v] != kinds) lines.corners[v] = 1;
      lines.vertex_kinds[v] = kinds;
    }
  }
  for (Index v = 0; v < nv; ++v)
    if (valence[v] > 0 && valence[v] != 2) lines.corners[v] = 1;
  for (Index v = 0; v < nv; ++v)
    if (lines.corners[v]) lines.vertex_kinds[v] = 0;
  return lines;
}

SurfaceFitResult fit_to_surface(const PolyMesh& input, PolyMesh& output, const SurfaceFitParams& params) {
  SurfaceFitResult result;
  const std::vector<FanTriangle> in_tris = fan_triangles(input), out_tris = fan_triangles(output);
  if (in_tris.empty() || out_tris.empty()) return result;
  // An output with an n-gon above max_face_corners is left as it is: its fan is not its surface,
  // and the fit over a 50 000-corner fan took 75 s (the hostile catalogue's ngon_100k).
  for (Index f = 0; f < output.num_faces(); ++f)
    if (output.face_size(f) > params.max_face_corners) return result;
  // The input surface as eval triangulates it, with unit normals: the reference of the closest
  // points and of the orientation guard (the collapse's, cluster_collapse.h).
  SurfaceReference own;
  if (!params.surface) own = make_surface_reference(input, params.threads);
  const SurfaceReference& ref = params.surface ? *params.surface : own;
  const TriangleBvh& in_bvh = ref.bvh;
  const double orientation_tol = params.orientation_tolerance * ref.longest_side;
  const std::size_t nv = output.positions.size();

  // Input samples: the centroid of every input triangle, or four points each where the input has
  // fewer triangles than the output (so every output triangle sees some).
  const int in_points = in_tris.size() >= out_tris.size() ? 1 : 4;
  std::vector<Vec3> in_samples;
  std::vector<double> in_weight;
  double in_area = 0.0;
  for (const FanTriangle& t : in_tris) {
    const double a = area_vector(input.positions, t).norm();
    in_area += a;
    for (int k = 0; k < in_points; ++k) {
      const auto& b = kPoints[k];
      in_samples.push_back(b[0] * input.positions[t.v[0]] + b[1] * input.positions[t.v[1]] + b[2] * input.positions[t.v[2]]);
      in_weight.push_back(a / in_points);
    }
  }
  if (!(in_area > 0.0)) return result;
  for (double& w : in_weight) w /= in_area;

  // Vertex → incident fan triangles (for the guards and the step bound).
  std::vector<std::vector<Index>> vertex_tris(nv);
  for (std::size_t i = 0; i < out_tris.size(); ++i)
    for (Index v : out_tris[i].v) vertex_tris[v].push_back(static_cast<Index>(i));
  std::vector<Vec3> area0(out_tris.size());
  for (std::size_t i = 0; i < out_tris.size(); ++i) area0[i] = area_vector(output.positions, out_tris[i]);
  const double cos_turn = std::cos(params.max_turn_deg * M_PI / 180.0);
  const std::vector<Vec3> start = output.positions;

  // The previous step's closest triangle of every sample seeds its next query (the answer does
  // not depend on it; the search prunes more). Triangle ids of both sets are fixed.
  const std::size_t np = params.output_points == 1 ? 1 : kPoints.size();  // points per output triangle
  std::vector<Index> out_hint(out_tris.size() * np, kInvalidIndex), in_hint(in_samples.size(), kInvalidIndex);
  std::vector<Index> peak_hint(nv, kInvalidIndex);
  // One evaluation of E at the current positions; with `num`/`den`, the lumped step's sums.
  // `reach`, if given, takes the longest residual that enters the step (the Hausdorff guard's scale).
  auto energy = [&](std::vector<Vec3>* num, std::vector<double>* den, double* reach) {
    const std::vector<Vec3>& p = output.positions;
    double out_area = 0.0;
    for (const FanTriangle& t : out_tris) out_area += area_vector(p, t).norm();
    if (!(out_area > 0.0)) return 0.0;
    // Output samples → input surface (queries in parallel, sums in sample order: deterministic).
    const std::size_t n_out = out_tris.size() * np;
    std::vector<Vec3> closest(n_out);
    parallel_chunks(n_out, params.threads, 4096, [&](std::size_t begin, std::size_t end, std::size_t) {
      for (std::size_t s = begin; s < end; ++s) {
        const FanTriangle& t = out_tris[s / np];
        const auto& b = kPoints[s % np];
        const NearestHit h = in_bvh.nearest(b[0] * p[t.v[0]] + b[1] * p[t.v[1]] + b[2] * p[t.v[2]], out_hint[s]);
        closest[s] = h.point;
        out_hint[s] = h.primitive;
      }
    });
    // Input samples → output surface.
    const TriangleBvh out_bvh(corners_of(p, out_tris), {.threads = params.threads});
    std::vector<NearestHit> hit(in_samples.size());
    parallel_chunks(in_samples.size(), params.threads, 4096, [&](std::size_t begin, std::size_t end, std::size_t) {
      for (std::size_t s = begin; s < end; ++s) in_hint[s] = (hit[s] = out_bvh.nearest(in_samples[s], in_hint[s])).primitive;
    });
    double e = 0.0;
    // The longest residual of each output triangle's samples (for the peak vertices below).
    std::vector<double> tri_residual(params.vertex_weight > 0.0 ? out_tris.size() : 0, 0.0);
    for (std::size_t s = 0; s < n_out; ++s) {
      const FanTriangle& t = out_tris[s / np];
      const auto& b = kPoints[s % np];
      const Vec3 x = b[0] * p[t.v[0]] + b[1] * p[t.v[1]] + b[2] * p[t.v[2]];
      const Vec3 r = closest[s] - x;
      if (!tri_residual.empty()) tri_residual[s / np] = std::max(tri_residual[s / np], r.norm());
      const double w = area_vector(p, t).norm() / np / out_area;
      e += w * r.squaredNorm();
      if (!num) continue;
      const double edge = longest_edge(p, t), len = r.norm();
      if (len > params.max_residual_edge_multiple * edge) continue;
      if (reach) *reach = std::max(*reach, len);
      const bool rounding = len <= params.min_residual_edge_fraction * edge;
      for (int k = 0; k < 3; ++k) {
        if (!rounding) (*num)[t.v[k]] += w * b[k] * r;
        (*den)[t.v[k]] += w * b[k];
      }
    }
    // Peak vertices: no face sample lies at a corner, so a vertex the collapse placed off the
    // surface, between faces whose samples lie near it, is invisible to the step and can be the
    // Hausdorff point (tpsdemo_red_robot at 0.8: 0.016 off at the end of 0.43-long thin quads;
    // the samples' step took it farther and the guard refused it). Such a vertex, farther from
    // the input than every sample of its triangles, is a sample of E too (vertex_weight).
    if (!tri_residual.empty()) {
      std::vector<NearestHit> vh(nv);
      parallel_chunks(nv, params.threads, 4096, [&](std::size_t begin, std::size_t end, std::size_t) {
        for (std::size_t v = begin; v < end; ++v)
          if (!vertex_tris[v].empty()) peak_hint[v] = (vh[v] = in_bvh.nearest(p[v], peak_hint[v])).primitive;
      });
      for (std::size_t v = 0; v < nv; ++v) {
        if (vertex_tris[v].empty()) continue;
        const Vec3 r = vh[v].point - p[v];
        const double len = r.norm();
        double share = 0.0, edge = 0.0, farthest_sample = 0.0;
        for (Index i : vertex_tris[v]) {
          share += area_vector(p, out_tris[i]).norm() / 3.0;
          edge = std::max(edge, longest_edge(p, out_tris[i]));
          farthest_sample = std::max(farthest_sample, tri_residual[i]);
        }
        if (!(len > farthest_sample)) continue;
        const double w = params.vertex_weight * share / out_area;
        e += w * r.squaredNorm();
        if (!num) continue;
        if (len > params.max_residual_edge_multiple * edge) continue;
        if (reach) *reach = std::max(*reach, len);
        if (len > params.min_residual_edge_fraction * edge) (*num)[v] += w * r;
        (*den)[v] += w;
      }
    }
    for (std::size_t s = 0; s < in_samples.size(); ++s) {
      const FanTriangle& t = out_tris[hit[s].primitive];
      const Vec3 r = in_samples[s] - hit[s].point;
      e += in_weight[s] * r.squaredNorm();
      if (!num) continue;
      const double edge = longest_edge(p, t), len = r.norm();
      if (len > params.max_residual_edge_multiple * edge) continue;
      if (reach) *reach = std::max(*reach, len);
      const bool rounding = len <= params.min_residual_edge_fraction * edge;
      const auto b = barycentric(hit[s].point, p[t.v[0]], p[t.v[1]], p[t.v[2]]);
      for (int k = 0; k < 3; ++k) {
        if (!rounding) (*num)[t.v[k]] += in_weight[s] * b[k] * r;
        (*den)[t.v[k]] += in_weight[s] * b[k];
      }
    }
    return e;
  };

  // A face may turn by max_turn_deg per step and shrink to min_area_ratio of its area before the
  // step, and never face away from where it faced before the fit (no flip).
  std::vector<Vec3> area_step(out_tris.size());
  auto face_ok = [&](Index i) {
    const Vec3 a = area_vector(output.positions, out_tris[i]);
    const double n0 = area_step[i].norm(), n1 = a.norm();
    if (n1 < params.min_area_ratio * n0) return false;
    if (area0[i].squaredNorm() > 0.0 && !(a.dot(area0[i]) > 0.0)) return false;
    return n0 == 0.0 || a.dot(area_step[i]) >= cos_turn * n0 * n1;
  };

  // docs/metrics.md §6b, as the collapse applies it (collapse_checks.cpp): from a face's
  // centroid, the nearest input triangle facing its way is at most twice as far as the nearest
  // of either way, plus the tolerance.
  auto faces_input = [&](Index f, double tol) {
    const auto fv = output.face_vertices(f);
    Vec3 c = Vec3::Zero(), av = Vec3::Zero();
    for (std::size_t i = 0; i < fv.size(); ++i) {
      const Vec3& a = output.positions[fv[i]];
      c += a;
      av += a.cross(output.positions[fv[i + 1 == fv.size() ? 0 : i + 1]]);
    }
    c /= static_cast<double>(fv.size());
    const NearestHit any = in_bvh.nearest(c);
    if (any.primitive == kInvalidIndex) return true;
    const double reach = 2.0 * std::sqrt(any.distance_sq) + tol;
    const double min_dot = 1e-3 * av.norm();  // as the collapse: near-perpendicular does not agree
    const NearestHit agreeing = in_bvh.nearest_if(
        c, [&](Index t) { return ref.normal[t].dot(av) >= min_dot; }, kInvalidIndex, reach * reach);
    return agreeing.primitive != kInvalidIndex && std::sqrt(agreeing.distance_sq) <= reach;
  };
  // Per face, the slack it is held to: the collapse's where it passes with it, eval's (twice
  // that) where only eval's holds, none where even eval's fails before the fit (already counted).
  std::vector<double> face_tol(output.num_faces(), -1.0);
  parallel_chunks(std::size_t(output.num_faces()), params.threads, 4096, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (Index f = Index(begin); f < Index(end); ++f) {
      if (faces_input(f, orientation_tol)) face_tol[f] = orientation_tol;
      else if (faces_input(f, 2.0 * orientation_tol)) face_tol[f] = 2.0 * orientation_tol;
    }
  });
  // A face that fails even eval's rule before the fit is an input face kept as it was (eval counts
  // it apart, in flipped_faces_kept, only while its corners stay where they are): its vertices stay.
  std::vector<std::uint8_t> fixed(nv, 0);
  if (params.fixed_vertices && params.fixed_vertices->size() == nv) fixed = *params.fixed_vertices;
  const FitLines* lines = params.lines && params.lines->reference && params.lines->vertex_kinds.size() == nv &&
                                  params.lines->corners.size() == nv
                              ? params.lines
                              : nullptr;
  if (lines)
    for (std::size_t v = 0; v < nv; ++v) fixed[v] = fixed[v] || lines->corners[v];
  // Slack of the line rule: what eval forgives (kTornAbsoluteSlack, 1e-9 of the bbox's longest side), halved.
  const double line_slack = 5e-10 * ref.longest_side;
  for (Index f = 0; f < output.num_faces(); ++f)
    if (face_tol[f] < 0.0)
      for (Index v : output.face_vertices(f)) fixed[v] = 1;

  // The Hausdorff guard: Chamfer is a mean and the step minimises it, but a vertex that the
  // samples of its faces pull off the surface can become the farthest point (shipyard_crane at
  // 0.4: the fit lowered Chamfer by 40 % and raised Hausdorff by 9 %, at one vertex that moved
  // 0.05 away from the input). No vertex may end farther from the input than it was, or than
  // `max_vertex_distance_fraction` of the farthest point before the fit (the longest residual of
  // the first step or vertex distance: the Hausdorff distance as the fit sees it), whichever is
  // more; the reach is set once the first step's residuals are known.
  std::vector<double> vertex_reach(nv, 0.0), vertex_dist(nv, 0.0);
  std::vector<Index> vertex_hint(nv, kInvalidIndex);
  parallel_chunks(nv, params.threads, 4096, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t v = begin; v < end; ++v) {
      if (vertex_tris[v].empty()) continue;
      const NearestHit h = in_bvh.nearest(output.positions[v]);
      vertex_dist[v] = std::sqrt(h.distance_sq);
      vertex_hint[v] = h.primitive;
    }
  });

  std::vector<Vec3> num(nv);
  std::vector<double> den(nv);
  std::vector<std::uint8_t> faces_ok(output.num_faces()), put_back(nv);
  double last_energy = 0.0;
  bool settled = false;  // the last step moved no vertex: the next would start where it did
  for (int it = 0; it < params.iterations && !settled; ++it) {
    std::fill(num.begin(), num.end(), Vec3::Zero());
    std::fill(den.begin(), den.end(), 0.0);
    double farthest = 0.0;
    const double e = energy(&num, &den, it == 0 ? &farthest : nullptr);
    if (it == 0) {
      result.energy_before = e;
      farthest = std::max(farthest, *std::max_element(vertex_dist.begin(), vertex_dist.end()));
      result.start_reach = farthest;
      for (std::size_t v = 0; v < nv; ++v)
        vertex_reach[v] = std::max(vertex_dist[v], params.max_vertex_distance_fraction * farthest);
    }
    last_energy = e;
    ++result.steps;
    const std::vector<Vec3> before = output.positions;
    for (std::size_t i = 0; i < out_tris.size(); ++i) area_step[i] = area_vector(before, out_tris[i]);
    std::vector<std::uint8_t> moved(nv, 0);
    for (std::size_t v = 0; v < nv; ++v) {
      if (fixed[v] || !(den[v] > 0.0) || vertex_tris[v].empty()) continue;
      Vec3 d = params.step * num[v] / den[v];
      double shortest = std::numeric_limits<double>::infinity();
      for (Index i : vertex_tris[v])
        for (int k = 0; k < 3; ++k)
          if (out_tris[i].v[k] != v) shortest = std::min(shortest, (before[out_tris[i].v[k]] - before[v]).norm());
      const double cap = params.max_step_edge_fraction * shortest;
      if (d.norm() > cap) d *= cap / d.norm();
      // A vertex on a strict line slides along the input's line (issue 32): its step is
      // projected onto it, never off it.
      if (lines && lines->vertex_kinds[v]) d = onto_line(*lines->reference, lines->vertex_kinds[v], before[v] + d) - before[v];
      if (d.squaredNorm() == 0.0) continue;
      output.positions[v] = before[v] + d;
      moved[v] = 1;
    }
    // Symmetry (issue 34): a pair moves by the mean of its two steps, mirrored; a vertex on the
    // plane stays in it; a pair with a fixed member stays.
    const std::vector<Index>* partner = params.mirror && params.mirror->partner.size() == nv ? &params.mirror->partner : nullptr;
    if (partner) {
      const MirrorPlane& plane = params.mirror->plane;
      for (std::size_t v = 0; v < nv; ++v) {
        const Index w = (*partner)[v];
        if (w == kInvalidIndex || w < v) continue;
        if (w == v) {
          if (moved[v]) output.positions[v][plane.axis] = plane.centre;
          continue;
        }
        if (!moved[v] && !moved[w]) continue;
        if (fixed[v] || fixed[w]) {
          output.positions[v] = before[v];
          output.positions[w] = before[w];
          moved[v] = moved[w] = 0;
          continue;
        }
        output.positions[v] = 0.5 * (output.positions[v] + plane.reflect(output.positions[w]));
        output.positions[w] = plane.reflect(output.positions[v]);
        moved[v] = moved[w] = 1;
      }
    }
    // Undoes v's move and its partner's (with symmetry).
    auto undo = [&](Index v) {
      if (moved[v]) {
        output.positions[v] = before[v];
        moved[v] = 0;
        ++result.refused_moves;
      }
      if (!partner) return;
      const Index w = (*partner)[v];
      if (w == kInvalidIndex || w == v || !moved[w]) return;
      output.positions[w] = before[w];
      moved[w] = 0;
      ++result.refused_moves;
    };
    // The Hausdorff guard (above), for every moved vertex on all threads; each decides alone.
    parallel_chunks(nv, params.threads, 4096, [&](std::size_t begin, std::size_t end, std::size_t) {
      for (std::size_t v = begin; v < end; ++v) {
        if (!moved[v]) continue;
        const NearestHit h = in_bvh.nearest(output.positions[v], vertex_hint[v]);
        if (std::sqrt(h.distance_sq) <= vertex_reach[v]) continue;
        output.positions[v] = before[v];
        moved[v] = 2;  // refused here; counted below, in vertex order
      }
    });
    for (std::size_t v = 0; v < nv; ++v)
      if (moved[v] == 2) {
        moved[v] = 0;
        ++result.refused_moves;
        ++result.refused_far;
        if (partner) undo(Index(v));
      }
    // Undo the moves of every vertex of a face that turned or shrank too much, until none does
    // (undoing only returns vertices to where they were, so this ends).
    for (bool changed = true; changed;) {
      changed = false;
      // A line edge that left its input line (eval's seams_torn rule): both ends go back.
      if (lines)
        for (const FitLines::Edge& le : lines->edges) {
          if (!moved[le.v] && !moved[le.w]) continue;
          if (on_input_lines(*lines->reference, le.kinds, output.positions[le.v], output.positions[le.w],
                             lines->line_tolerance, line_slack))
            continue;
          for (Index v : {le.v, le.w})
            if (moved[v]) {
              undo(v);
              ++result.refused_line;
              changed = true;
            }
        }
      for (std::size_t i = 0; i < out_tris.size(); ++i) {
        if (face_ok(static_cast<Index>(i))) continue;
        for (Index v : out_tris[i].v)
          if (moved[v]) {
            undo(v);
            changed = true;
          }
      }
      if (changed) continue;  // the cheap checks first; the orientation once they hold
      // The face-by-face sweep below, with every face's test run first on all threads against
      // the positions as they are; a face whose vertex an earlier face of the sweep put back is
      // tested again there, so the sweep decides as if it ran alone.
      auto needs_test = [&](Index f) {
        const auto fv = output.face_vertices(f);
        return face_tol[f] >= 0.0 && std::any_of(fv.begin(), fv.end(), [&](Index v) { return moved[v] != 0; });
      };
      parallel_chunks(std::size_t(output.num_faces()), params.threads, 4096, [&](std::size_t begin, std::size_t end, std::size_t) {
        for (Index f = Index(begin); f < Index(end); ++f) faces_ok[f] = !needs_test(f) || faces_input(f, face_tol[f]);
      });
      std::fill(put_back.begin(), put_back.end(), 0);
      for (Index f = 0; f < output.num_faces(); ++f) {
        const auto fv = output.face_vertices(f);
        const bool again = std::any_of(fv.begin(), fv.end(), [&](Index v) { return put_back[v] != 0; });
        if (!needs_test(f) || (again ? faces_input(f, face_tol[f]) : faces_ok[f])) continue;
        for (Index v : fv)
          if (moved[v]) {
            undo(v);
            put_back[v] = 1;
            if (partner && (*partner)[v] != kInvalidIndex) put_back[(*partner)[v]] = 1;
            changed = true;
          }
      }
    }
    // Nothing moved (every residual zero, or every move refused): the same positions again.
    settled = std::none_of(moved.begin(), moved.end(), [](std::uint8_t m) { return m != 0; });
  }
  result.energy_last_step = last_energy;
  if (params.measure_after) result.energy_after = params.iterations == 0 ? 0.0 : settled ? last_energy : energy(nullptr, nullptr, nullptr);
  for (std::size_t v = 0; v < nv; ++v) result.moved_vertices += output.positions[v] != start[v];
  return result;
}

}  // namespace quadlod
