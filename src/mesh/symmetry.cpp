// Mirror symmetry about a bbox-centred axis plane: see symmetry.h (issue 34, docs/symmetry.md).
#include "mesh/symmetry.h"

#include "mesh/connectivity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace quadlod {

const char* axis_name(int axis) {
  switch (axis) {
    case 0: return "x";
    case 1: return "y";
    case 2: return "z";
    default: return "none";
  }
}

namespace {

bool finite(const Vec3& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }

// Points bucketed in cubes of side `cell`; a query within `cell` of a point looks at the 27 cubes
// around it.
class HashGrid {
 public:
  HashGrid(const std::vector<Vec3>& points, double cell) : inv_(1.0 / cell) {
    cells_.reserve(points.size());
    for (Index i = 0; i < Index(points.size()); ++i)
      if (finite(points[i])) cells_[key(cell_of(points[i]))].push_back(i);
  }
  // Calls visit(i) for every point within the 27 cubes around p (a superset of those within `cell`).
  template <class F>
  void near(const Vec3& p, F&& visit) const {
    const auto c = cell_of(p);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (Index i : it->second) visit(i);
        }
  }

 private:
  // Clamped before the cast (a coordinate 1e30 times the cell would overflow it); cells that far
  // out only share buckets.
  static std::int64_t cell(double v) { return std::int64_t(std::clamp(std::floor(v), -4e18, 4e18)); }
  std::array<std::int64_t, 3> cell_of(const Vec3& p) const {
    return {cell(p.x() * inv_), cell(p.y() * inv_), cell(p.z() * inv_)};
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    // 21 bits per axis (wrapping): collisions only merge buckets, the distance test decides.
    const std::uint64_t m = (1u << 21) - 1;
    return (std::uint64_t(c[0]) & m) | ((std::uint64_t(c[1]) & m) << 21) | ((std::uint64_t(c[2]) & m) << 42);
  }
  double inv_;
  std::unordered_map<std::uint64_t, std::vector<Index>> cells_;
};

}  // namespace

VertexMirror match_mirror_vertices(const std::vector<Vec3>& positions, const MirrorPlane& plane, double tolerance) {
  VertexMirror out;
  out.plane = plane;
  const Index n = Index(positions.size());
  out.partner.assign(n, kInvalidIndex);
  if (!plane.valid() || !(tolerance > 0.0)) {
    out.unmatched = n;
    return out;
  }
  const HashGrid grid(positions, tolerance);
  const double tol2 = tolerance * tolerance;
  for (Index v = 0; v < n; ++v) {
    if (out.partner[v] != kInvalidIndex || !finite(positions[v])) continue;
    const Vec3 q = plane.reflect(positions[v]);
    Index best = kInvalidIndex;
    double best_d2 = tol2;
    grid.near(q, [&](Index w) {
      if (out.partner[w] != kInvalidIndex) return;
      const double d2 = (positions[w] - q).squaredNorm();
      if (d2 < best_d2 || (d2 == best_d2 && (best == kInvalidIndex || w < best))) {
        best = w;
        best_d2 = d2;
      }
    });
    if (best == kInvalidIndex) continue;
    out.partner[v] = best;
    out.partner[best] = v;
  }
  for (Index v = 0; v < n; ++v) {
    if (out.partner[v] == kInvalidIndex) ++out.unmatched;
    else if (out.partner[v] == v) ++out.on_plane;
    else ++out.pairs;
  }
  return out;
}

SymmetryDetection detect_symmetry(const PolyMesh& mesh, int axis, const SymmetryDetectParams& params) {
  SymmetryDetection out;
  const BoundingBox box = bounding_box(mesh);
  const double diag = box.diagonal();
  out.tolerance = params.tolerance * diag;
  if (mesh.positions.empty() || !(out.tolerance > 0.0)) return out;
  const Vec3 centre = 0.5 * (box.min + box.max);
  const Vec3 extent = box.extent();
  VertexMirror best;
  for (int a = 0; a < 3; ++a) {
    if (axis >= 0 && a != axis) continue;
    if (!(extent[a] > out.tolerance)) continue;  // flat along a: no mirror plane
    // A centre that is zero to rounding is zero: the mirror is then an exact negation.
    const double c = std::abs(centre[a]) <= 1e-12 * diag ? 0.0 : centre[a];
    VertexMirror m = match_mirror_vertices(mesh.positions, MirrorPlane{a, c}, out.tolerance);
    const double f = m.matched_fraction();
    const bool better = best.empty() || f > best.matched_fraction() ||
                        (f == best.matched_fraction() && m.on_plane < best.on_plane);
    if (better) best = std::move(m);
  }
  if (best.empty()) return out;
  out.best_fraction = best.matched_fraction();
  out.best_axis = best.plane.axis;
  if (out.best_fraction >= params.min_matched_fraction) out.mirror = std::move(best);
  return out;
}

std::vector<Index> mirror_edges(const Connectivity& conn, const VertexMirror& mirror) {
  std::vector<Index> out(conn.num_edges, kInvalidIndex);
  if (mirror.partner.size() != conn.num_vertices) return out;
  // The edge between a and b, from a's corners (each corner's edge and its predecessor's).
  auto edge_between = [&](Index a, Index b) {
    for (Index c : conn.corners_at_vertex(a))
      for (Index e : {conn.corner_edge[c], conn.corner_edge[conn.corner_prev[c]]}) {
        const auto [x, y] = conn.edge_vertices[e];
        if ((x == a && y == b) || (x == b && y == a)) return e;
      }
    return kInvalidIndex;
  };
  for (Index e = 0; e < conn.num_edges; ++e) {
    if (out[e] != kInvalidIndex) continue;
    const auto [a, b] = conn.edge_vertices[e];
    const Index ma = mirror.partner[a], mb = mirror.partner[b];
    if (ma == kInvalidIndex || mb == kInvalidIndex) continue;
    const Index m = edge_between(ma, mb);
    if (m == kInvalidIndex) continue;
    out[e] = m;
    out[m] = e;
  }
  return out;
}

void symmetrize_flags_union(std::vector<std::uint8_t>& flags, const std::vector<Index>& edge_mirror) {
  if (flags.size() != edge_mirror.size()) return;
  for (std::size_t e = 0; e < flags.size(); ++e) {
    const Index m = edge_mirror[e];
    if (m == kInvalidIndex || m == e) continue;
    if (flags[e] || flags[m]) flags[e] = flags[m] = 1;
  }
}

double symmetrize_positions(std::vector<Vec3>& positions, const VertexMirror& mirror,
                            const std::vector<std::uint8_t>* fixed) {
  double moved = 0.0;
  if (!mirror.plane.valid() || mirror.partner.size() != positions.size()) return moved;
  if (fixed && fixed->size() != positions.size()) fixed = nullptr;
  const auto is_fixed = [&](Index v) { return fixed && (*fixed)[v]; };
  const int a = mirror.plane.axis;
  for (Index v = 0; v < Index(positions.size()); ++v) {
    const Index w = mirror.partner[v];
    if (w == kInvalidIndex || (is_fixed(v) && is_fixed(w))) continue;
    if (w == v) {
      moved = std::max(moved, std::abs(positions[v][a] - mirror.plane.centre));
      positions[v][a] = mirror.plane.centre;
    } else if (w > v) {
      // The smaller id is the source, unless only the other one is fixed.
      const Index from = is_fixed(w) ? w : v, to = from == v ? w : v;
      const Vec3 q = mirror.plane.reflect(positions[from]);
      moved = std::max(moved, (positions[to] - q).norm());
      positions[to] = q;
    }
  }
  return moved;
}

double mirrored_vertex_fraction(const std::vector<Vec3>& positions, const MirrorPlane& plane, double tolerance) {
  if (positions.empty()) return 1.0;
  if (!plane.valid() || !(tolerance > 0.0)) return 0.0;
  const HashGrid grid(positions, tolerance);
  const double tol2 = tolerance * tolerance;
  Index found = 0;
  for (const Vec3& p : positions) {
    if (!finite(p)) continue;
    const Vec3 q = plane.reflect(p);
    bool any = false;
    grid.near(q, [&](Index w) { any = any || (positions[w] - q).squaredNorm() <= tol2; });
    found += any;
  }
  return double(found) / double(positions.size());
}

}  // namespace quadlod
