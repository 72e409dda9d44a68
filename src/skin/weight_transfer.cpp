// Skin weights by projection onto a skinned surface (issue 24; include/quadlod/skin.h,
// docs/skinning.md "Why projection").
//
//   target vertex p ──closest point──► q on source triangle (a, b, c), q = αa + βb + γc
//   w(p) = canonical(α w(a) + β w(b) + γ w(c))        (≤ the source's influence count, sum 1)
//
// The closest triangle is looked for first among those facing p's way (source face normal within
// max_normal_angle_deg of p's area-weighted normal): two surfaces close to each other (a leg
// against the belly, upper and lower lip) usually face apart, and a vertex must follow the bones
// of its own surface, and only on the input part (connected piece) its own part of the LOD lies
// on (docs/skinning.md, "Parts keep to their part").
#include "quadlod/skin.h"

#include "geometry/bvh.h"
#include "skin/surface_projection.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace quadlod {

namespace {

// Barycentric coordinates of q (on or near triangle a, b, c), clamped into the triangle; for a
// degenerate triangle, all weight on the nearest corner.
Vec3 barycentric(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e0 = b - a, e1 = c - a, d = q - a;
  const double d00 = e0.dot(e0), d01 = e0.dot(e1), d11 = e1.dot(e1);
  const double d20 = d.dot(e0), d21 = d.dot(e1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 1e-300) || den < 1e-14 * d00 * d11) {
    const double da = (q - a).squaredNorm(), db = (q - b).squaredNorm(), dc = (q - c).squaredNorm();
    if (da <= db && da <= dc) return Vec3(1, 0, 0);
    return db <= dc ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
  }
  double v = (d11 * d20 - d01 * d21) / den;
  double w = (d00 * d21 - d01 * d20) / den;
  v = std::max(0.0, v);
  w = std::max(0.0, w);
  double u = std::max(0.0, 1.0 - v - w);
  const double s = u + v + w;
  return Vec3(u, v, w) / s;
}

// Connected parts: vertices joined by faces (union-find), numbered by their first vertex; a
// vertex used by no face is its own part.
std::vector<Index> vertex_parts(const PolyMesh& m, Index* count) {
  std::vector<Index> parent(m.num_vertices());
  for (Index v = 0; v < m.num_vertices(); ++v) parent[v] = v;
  auto find = [&](Index x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (Index f = 0; f < m.num_faces(); ++f) {
    const auto vs = m.face_vertices(f);
    for (std::size_t i = 1; i < vs.size(); ++i) {
      const Index a = find(vs[0]), b = find(vs[i]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<Index> part(m.num_vertices(), kInvalidIndex), id(m.num_vertices(), kInvalidIndex);
  Index n = 0;
  for (Index v = 0; v < m.num_vertices(); ++v) {
    const Index r = find(v);
    if (id[r] == kInvalidIndex) id[r] = n++;
    part[v] = id[r];
  }
  *count = n;
  return part;
}

// The source as projection target: its fan triangles with their corners, polygon normals and
// part, one BVH over all and (keep_parts) one per part.
struct SourceSurface {
  std::vector<std::array<Vec3, 3>> triangles;
  std::vector<std::array<Index, 3>> corners;
  std::vector<Vec3> normals;
  std::vector<Index> triangle_part;
  Index parts = 0;
  TriangleBvh all;
  std::vector<TriangleBvh> part_bvh;              ///< empty unless built
  std::vector<std::vector<Index>> part_triangles;  ///< a part's local triangle id → source triangle
  double cos_limit = 0.0, side_limit_sq = 0.0;

  SourceSurface(const PolyMesh& source, const SkinTransferParams& params) {
    const std::vector<Index> part = vertex_parts(source, &parts);
    for (Index f = 0; f < source.num_faces(); ++f) {
      const auto vs = source.face_vertices(f);
      const Vec3 n = face_normal(source, f);
      for (std::size_t i = 1; i + 1 < vs.size(); ++i) {
        triangles.push_back({source.positions[vs[0]], source.positions[vs[i]], source.positions[vs[i + 1]]});
        corners.push_back({vs[0], vs[i], vs[i + 1]});
        normals.push_back(n);
        triangle_part.push_back(part[vs[0]]);
      }
    }
    all = TriangleBvh(triangles);
    cos_limit = std::cos(params.max_normal_angle_deg * std::numbers::pi / 180.0);
    const double side_limit = params.max_side_distance * bounding_box(source).diagonal();
    side_limit_sq = side_limit * side_limit;
  }

  void build_part_bvhs() {
    part_triangles.assign(parts, {});
    for (Index t = 0; t < triangles.size(); ++t) part_triangles[triangle_part[t]].push_back(t);
    part_bvh.resize(parts);
    for (Index c = 0; c < parts; ++c) {
      std::vector<std::array<Vec3, 3>> tris;
      for (Index t : part_triangles[c]) tris.push_back(triangles[t]);
      if (!tris.empty()) part_bvh[c] = TriangleBvh(tris);
    }
  }

  /// The closest point to p of the whole source (part == kInvalidIndex) or of one part: among
  /// the triangles facing `area_normal`'s way first (within side_limit), then any; `same_side`
  /// says which. The primitive is a source triangle id; `hint` is the previous answer in the same
  /// search set and becomes this one.
  NearestHit project(const Vec3& p, const Vec3& area_normal, Index part, Index& hint, bool* same_side) const {
    const TriangleBvh& search = part == kInvalidIndex ? all : part_bvh[part];
    auto source_triangle = [&](Index t) { return part == kInvalidIndex ? t : part_triangles[part][t]; };
    const double len = area_normal.norm();
    NearestHit hit;
    if (len > 0.0) {
      const Vec3 n = area_normal / len;
      hit = search.nearest_if(p, [&](Index t) { return normals[source_triangle(t)].dot(n) > cos_limit; }, hint,
                              side_limit_sq);
    }
    *same_side = hit.primitive != kInvalidIndex;
    if (!*same_side) hit = search.nearest(p, hint);
    if (hit.primitive != kInvalidIndex) {
      hint = hit.primitive;
      hit.primitive = source_triangle(hit.primitive);
    }
    return hit;
  }
};

// keep_parts (skin.h): per target part, the source part it keeps to, or kInvalidIndex (every
// part). The source parts that hold at least min_part_share of the part's closest points (by
// vertex area) are its candidates; it keeps to the candidate its vertices lie closest to
// (area-weighted mean squared distance: the ram's eyeball is overlapped by two eyelid shells, and
// half its vertices lie nearest to a lid), unless a vertex lies farther from that one than
// max_part_distance_edges mean edge lengths of the part (a part a reducer joined from two: no
// one input part lies under all of it).
std::vector<Index> match_parts(const SourceSurface& source, const PolyMesh& target, const std::vector<Index>& target_part,
                               Index target_parts, const std::vector<Vec3>& vertex_normal,
                               const SkinTransferParams& params) {
  std::vector<Index> matched(target_parts, kInvalidIndex);
  // Each target part's mean edge length (every face side counted once per face).
  std::vector<double> part_edge(target_parts, 0.0), part_sides(target_parts, 0.0);
  for (Index f = 0; f < target.num_faces(); ++f) {
    const auto vs = target.face_vertices(f);
    for (std::size_t i = 0; i < vs.size(); ++i) {
      part_edge[target_part[vs[i]]] += (target.positions[vs[i]] - target.positions[vs[(i + 1) % vs.size()]]).norm();
      part_sides[target_part[vs[i]]] += 1.0;
    }
  }
  for (Index c = 0; c < target_parts; ++c) part_edge[c] = part_sides[c] > 0.0 ? part_edge[c] / part_sides[c] : 0.0;
  std::vector<std::vector<std::pair<Index, double>>> votes(target_parts);  // (source part, area)
  std::vector<std::vector<Index>> members(target_parts);
  Index hint = kInvalidIndex;
  bool same_side = false;
  for (Index v = 0; v < target.num_vertices(); ++v) {
    members[target_part[v]].push_back(v);
    const NearestHit hit = source.project(target.positions[v], vertex_normal[v], kInvalidIndex, hint, &same_side);
    if (hit.primitive != kInvalidIndex)
      votes[target_part[v]].push_back({source.triangle_part[hit.primitive], vertex_normal[v].norm()});
  }
  for (Index c = 0; c < target_parts; ++c) {
    auto& vc = votes[c];
    std::sort(vc.begin(), vc.end());
    double total = 0.0;
    for (const auto& [part, area] : vc) total += area;
    if (!(total > 0.0)) continue;
    double best = INFINITY, best_far = 0.0;
    for (std::size_t i = 0; i < vc.size();) {
      double share = 0.0;
      std::size_t j = i;
      for (; j < vc.size() && vc[j].first == vc[i].first; ++j) share += vc[j].second;
      if (share >= params.min_part_share * total) {
        double sum = 0.0, far = 0.0;
        Index h = kInvalidIndex;
        for (Index v : members[c]) {
          const NearestHit hit = source.project(target.positions[v], vertex_normal[v], vc[i].first, h, &same_side);
          sum += vertex_normal[v].norm() * hit.distance_sq;
          far = std::max(far, hit.distance_sq);
        }
        if (sum < best) {
          best = sum;
          best_far = far;
          matched[c] = vc[i].first;
        }
      }
      i = j;
    }
    const double reach = params.max_part_distance_edges * part_edge[c];
    if (!(best_far <= reach * reach)) matched[c] = kInvalidIndex;
  }
  return matched;
}

}  // namespace

namespace {

// One projection of `target` onto a built source surface (the part BVHs built when parts are
// kept and the source has several).
SurfaceProjection project_with(const SourceSurface& surface, const PolyMesh& target, const SkinTransferParams& params) {
  SurfaceProjection result;

  // Area-weighted vertex normals of the target.
  std::vector<Vec3> vertex_normal(target.num_vertices(), Vec3::Zero());
  for (Index f = 0; f < target.num_faces(); ++f) {
    const Vec3 area = face_area_vector(target, f);
    for (Index v : target.face_vertices(f)) vertex_normal[v] += area;
  }

  Index target_parts = 0;
  const std::vector<Index> target_part = vertex_parts(target, &target_parts);
  result.parts = target_parts;
  std::vector<Index> matched(target_parts, kInvalidIndex);
  if (params.keep_parts && surface.parts > 1 && !surface.triangles.empty()) {
    matched = match_parts(surface, target, target_part, target_parts, vertex_normal, params);
    for (Index m : matched) result.parts_matched += m != kInvalidIndex;
  }

  result.corners.assign(target.num_vertices(), {kInvalidIndex, kInvalidIndex, kInvalidIndex});
  result.barycentric.assign(target.num_vertices(), Vec3::Zero());
  double sum_distance = 0.0;
  Index hint = kInvalidIndex;
  std::vector<Index> part_hint(surface.part_bvh.size(), kInvalidIndex);
  for (Index v = 0; v < target.num_vertices(); ++v) {
    const Index part = matched[target_part[v]];
    bool same_side = false;
    const NearestHit hit = surface.project(target.positions[v], vertex_normal[v], part,
                                           part == kInvalidIndex ? hint : part_hint[part], &same_side);
    ++(same_side ? result.same_side : result.nearest_only);
    if (hit.primitive == kInvalidIndex) continue;  // empty source: nothing to blend
    const auto& t = surface.triangles[hit.primitive];
    result.corners[v] = surface.corners[hit.primitive];
    result.barycentric[v] = barycentric(hit.point, t[0], t[1], t[2]);
    const double d = std::sqrt(hit.distance_sq);
    result.max_distance = std::max(result.max_distance, d);
    sum_distance += d;
  }
  result.mean_distance = target.num_vertices() ? sum_distance / target.num_vertices() : 0.0;
  return result;
}

bool keeps_parts(const SourceSurface& surface, const SkinTransferParams& params) {
  return params.keep_parts && surface.parts > 1 && !surface.triangles.empty();
}

}  // namespace

SurfaceProjection project_onto_surface(const PolyMesh& source, const PolyMesh& target, const SkinTransferParams& params) {
  SourceSurface surface(source, params);
  if (keeps_parts(surface, params)) surface.build_part_bvhs();
  return project_with(surface, target, params);
}

struct SurfaceProjector::Surface : SourceSurface {
  using SourceSurface::SourceSurface;
};

SurfaceProjector::SurfaceProjector(const PolyMesh& source, const SkinTransferParams& params)
    : surface_(std::make_unique<Surface>(source, params)), params_(params) {
  if (keeps_parts(*surface_, params_)) surface_->build_part_bvhs();
}

SurfaceProjector::~SurfaceProjector() = default;

SurfaceProjection SurfaceProjector::project(const PolyMesh& target) const { return project_with(*surface_, target, params_); }

SkinTransferResult transfer_skin_weights(const PolyMesh& source, const PolyMesh& target,
                                         const SkinTransferParams& params) {
  const SurfaceProjection projection = project_onto_surface(source, target, params);
  SkinTransferResult result;
  result.same_side = projection.same_side;
  result.nearest_only = projection.nearest_only;
  result.parts = projection.parts;
  result.parts_matched = projection.parts_matched;
  result.max_distance = projection.max_distance;
  result.mean_distance = projection.mean_distance;
  const Index max_influences = params.max_influences > 0 ? params.max_influences : source.skin.max_influences();
  std::vector<std::vector<Influence>> per_vertex(target.num_vertices());
  for (Index v = 0; v < target.num_vertices(); ++v) {
    const auto& c = projection.corners[v];
    if (c[0] == kInvalidIndex) continue;
    const Vec3& bary = projection.barycentric[v];
    std::vector<Influence> blend;
    for (int k = 0; k < 3; ++k)
      if (bary[k] > 0.0)
        for (const Influence& i : influences_of(source.skin, c[k])) blend.push_back({i.joint, bary[k] * i.weight});
    per_vertex[v] = std::move(blend);
  }
  result.skin = make_skin_weights(per_vertex, max_influences, params.min_weight);
  return result;
}

}  // namespace quadlod
