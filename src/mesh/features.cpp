// Feature edges, feature corners, feature lines and UV islands (issue 7; contract in features.h).
//
// Everything is one pass over the edges (classification), one over the feature edges (vertex
// valence, a vertex → feature-edge CSR, corners) and one walk per feature line, so the cost is
// linear in the corners.
//
// Matching corners across an edge. Corner c0 of face f0 runs a → b. The other corner c1 of a
// manifold edge runs b → a when the two faces are consistently oriented, a → b when one is
// flipped. The attribute compared at endpoint a is the one at f0's corner sitting at a (c0) and at
// f1's corner sitting at a:
//
//        b ───────── ...        consistent:  c1 at b, next(c1) at a  → pair (c0, next c1), (next c0, c1)
//        │ ↑c0      │ f1        flipped:     c1 at a, next(c1) at b  → pair (c0, c1), (next c0, next c1)
//        │ f0   c1↓ │
//        a ───────── ...
#include "mesh/features.h"

#include "mesh/union_find.h"
#include "util/parallel.h"

#include <algorithm>
#include <cmath>
#include <cmath>
#include <limits>
#include <numbers>

namespace quadlod {

namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

/// True when corners c0 and c1 of one edge run the same way (their faces are inconsistently
/// oriented). A zero-length edge (both ends one vertex) counts as consistent.
bool same_direction(const Connectivity& conn, Index c0, Index c1) {
  return conn.corner_vertex[c1] == conn.corner_vertex[c0] && conn.corner_vertex[c0] != conn.tip_vertex(c0);
}

/// The corners of f1 facing c0's two endpoints (see the diagram above): {at tail of c0, at tip}.
std::array<Index, 2> facing_corners(const Connectivity& conn, Index c0, Index c1) {
  const Index n1 = conn.corner_next[c1];
  return same_direction(conn, c0, c1) ? std::array<Index, 2>{c1, n1} : std::array<Index, 2>{n1, c1};
}

/// Two per-corner pool references differ "by value": exactly one is missing, or both exist and
/// their values differ.
template <class Pool>
bool differ(const Pool& pool, Index a, Index b) {
  const bool ha = a != kInvalidIndex, hb = b != kInvalidIndex;
  if (ha != hb) return true;
  if (!ha) return false;
  return a != b && pool[a] != pool[b];
}

/// Does corner attribute (pool, corner index) differ across the manifold edge of c0 / c1?
template <class Pool>
bool seam_across(const Connectivity& conn, const Pool& pool, const std::vector<Index>& corner_ref,
                 Index c0, Index c1) {
  const std::array<Index, 2> f = facing_corners(conn, c0, c1);
  return differ(pool, corner_ref[c0], corner_ref[f[0]]) ||
         differ(pool, corner_ref[conn.corner_next[c0]], corner_ref[f[1]]);
}

/// Same material by name, so two table entries with one name do not make a border.
bool same_material(const PolyMesh& m, Index f0, Index f1) {
  const Index a = m.face_material[f0], b = m.face_material[f1];
  if (a == b) return true;
  if (a == kInvalidIndex || b == kInvalidIndex) return false;
  return m.material_names[a] == m.material_names[b];
}

/// Angle in degrees between two non-zero vectors, atan2 form (accurate near 0° and 180°).
double angle_deg(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)) * kDeg; }

}  // namespace

FeatureEdges find_feature_edges(const PolyMesh& mesh, const Connectivity& conn,
                                const FeatureParams& params) {
  FeatureEdges fe;
  const Index ne = conn.num_edges, nv = conn.num_vertices;
  fe.edge_bits.assign(ne, 0);
  fe.edge_uv_seam_sets.assign(ne, 0);
  fe.vertex_bits.assign(nv, 0);
  fe.vertex_valence.assign(nv, 0);
  fe.vertex_corner.assign(nv, 0);
  fe.edge_line.assign(ne, kInvalidIndex);

  const bool use_smoothing = params.smoothing_groups && !mesh.face_smoothing.empty();
  const bool has_materials = !mesh.face_material.empty();
  const std::size_t uv_sets = std::min<std::size_t>(mesh.uv_sets.size(), 32);
  // Face normals of every face, then each edge's bits, on all threads (each item written by one
  // chunk); the counts below run in edge order, so the result does not depend on the threads.
  std::vector<Vec3> normal(mesh.num_faces());
  parallel_chunks(std::size_t(mesh.num_faces()), params.threads, params.min_parallel_edges, [&](std::size_t b, std::size_t e, std::size_t) {
    for (Index f = Index(b); f < Index(e); ++f) normal[f] = face_normal(mesh, f);
  });

  // --- classify every edge -------------------------------------------------------------------
  parallel_chunks(std::size_t(ne), params.threads, params.min_parallel_edges, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (Index e = Index(begin); e < Index(end); ++e) {
      const Index count = conn.edge_face_count(e);
      std::uint8_t bits = 0;
      std::uint32_t seam_sets = 0;
      if (count == 1) {
        bits = kFeatureBoundary;
      } else if (count > 2) {
        bits = kFeatureNonManifold;
      } else {
        const auto cs = conn.corners_of_edge(e);
        const Index c0 = cs[0], c1 = cs[1];
        const Index f0 = conn.corner_face[c0], f1 = conn.corner_face[c1];
        for (std::size_t k = 0; k < uv_sets; ++k)
          if (seam_across(conn, mesh.uv_sets[k].values, mesh.uv_sets[k].corner, c0, c1))
            seam_sets |= std::uint32_t{1} << k;
        if (seam_sets) bits |= kFeatureUvSeam;
        if (mesh.has_normals() && seam_across(conn, mesh.normals, mesh.corner_normal, c0, c1))
          bits |= kFeatureNormalSeam;
        if (has_materials && !same_material(mesh, f0, f1)) bits |= kFeatureMaterialBorder;
        // Smoothing groups (OBJ `s`): normals are shared within a group, so an edge between two
        // groups is a crease. Group 0 (`s off`) is flat shading (Blender imports it as a face with
        // use_smooth off, not as sharp edges): between a flat and a smooth face the shading breaks,
        // but between two flat faces it is per face on both sides anyway — no crease line, and
        // marking it would make every edge of a faceted model a feature. The dihedral rule below
        // still catches real creases there.
        if (use_smoothing && mesh.face_smoothing[f0] != mesh.face_smoothing[f1]) bits |= kFeatureHardEdge;
        // Dihedral angle = angle between the face normals, with the second normal reversed when the
        // faces are inconsistently oriented (else a flat but flipped pair would read as 180°).
        // A zero-area face has no normal and never makes a hard edge.
        const Vec3& n0 = normal[f0];
        const Vec3& n1 = normal[f1];
        if (!n0.isZero(0.0) && !n1.isZero(0.0)) {
          if (angle_deg(n0, same_direction(conn, c0, c1) ? Vec3(-n1) : n1) >= params.hard_angle_deg) bits |= kFeatureHardEdge;
        }
      }
      bits &= params.enabled;
      if (!(bits & kFeatureUvSeam)) seam_sets = 0;
      fe.edge_bits[e] = bits;
      fe.edge_uv_seam_sets[e] = seam_sets;
    }
  });
  for (Index e = 0; e < ne; ++e) {
    const std::uint8_t bits = fe.edge_bits[e];
    if (!bits) continue;
    ++fe.feature_edges;
    for (int b = 0; b < 6; ++b)
      if (bits & (1u << b)) ++fe.edges_with_bit[b];
    for (Index v : conn.edge_vertices[e]) {
      fe.vertex_bits[v] |= bits;
      ++fe.vertex_valence[v];
    }
  }

  // --- vertex → incident feature edges (CSR) ---------------------------------------------------
  std::vector<Index> offsets(nv + 1, 0);
  for (Index v = 0; v < nv; ++v) offsets[v + 1] = offsets[v] + fe.vertex_valence[v];
  std::vector<Index> incident(offsets[nv]);
  {
    std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
    for (Index e = 0; e < ne; ++e)
      if (fe.edge_bits[e])
        for (Index v : conn.edge_vertices[e]) incident[fill[v]++] = e;
  }

  // --- corners --------------------------------------------------------------------------------
  const auto& pos = mesh.positions;
  for (Index v = 0; v < nv; ++v) {
    const Index valence = fe.vertex_valence[v];
    if (valence == 0) continue;
    bool corner = valence != 2;
    if (!corner) {
      const Index e1 = incident[offsets[v]], e2 = incident[offsets[v] + 1];
      if (fe.edge_bits[e1] != fe.edge_bits[e2] || fe.edge_uv_seam_sets[e1] != fe.edge_uv_seam_sets[e2]) {
        corner = true;
      } else {
        // Turn angle: between the incoming direction (a → v) and the outgoing one (v → b), 0 when
        // the line runs straight on. A zero-length edge has no direction and does not turn.
        const Vec3 in = pos[v] - pos[conn.other_vertex(e1, v)];
        const Vec3 out = pos[conn.other_vertex(e2, v)] - pos[v];
        if (!in.isZero(0.0) && !out.isZero(0.0) && angle_deg(in, out) > params.corner_angle_deg) corner = true;
      }
    }
    fe.vertex_corner[v] = corner ? 1 : 0;
  }

  // --- lines: walk from corners through valence-2 non-corners ----------------------------------
  // Returns the feature edge at non-corner vertex w other than e (w has exactly two).
  auto other_edge = [&](Index w, Index e) {
    const Index a = incident[offsets[w]], b = incident[offsets[w] + 1];
    return a == e ? b : a;
  };
  auto walk = [&](Index v, Index e, Index line) {
    for (;;) {
      fe.edge_line[e] = line;
      const Index w = conn.other_vertex(e, v);
      if (fe.vertex_corner[w]) return;
      const Index next = other_edge(w, e);
      if (fe.edge_line[next] != kInvalidIndex) return;  // closed loop, back at the start
      v = w;
      e = next;
    }
  };
  for (Index v = 0; v < nv; ++v) {
    if (!fe.vertex_corner[v]) continue;
    for (Index k = offsets[v]; k < offsets[v + 1]; ++k)
      if (fe.edge_line[incident[k]] == kInvalidIndex) walk(v, incident[k], fe.num_lines++);
  }
  // Closed loops made only of non-corner vertices: anchor each at its smallest vertex.
  for (Index e = 0; e < ne; ++e) {
    if (!fe.edge_bits[e] || fe.edge_line[e] != kInvalidIndex) continue;
    Index smallest = conn.edge_vertices[e][0];
    for (Index v = conn.edge_vertices[e][0], f = e;;) {  // first pass: find the smallest vertex
      const Index w = conn.other_vertex(f, v);
      smallest = std::min(smallest, w);
      const Index next = other_edge(w, f);
      if (next == e) break;
      v = w;
      f = next;
    }
    fe.vertex_corner[smallest] = 1;
    walk(smallest, incident[offsets[smallest]], fe.num_lines++);
  }
  for (Index v = 0; v < nv; ++v) fe.corners += fe.vertex_corner[v];

  // --- strictness ----------------------------------------------------------------------------
  // A UV set whose islands are mostly single faces (more than per_face_layout_fraction of its
  // faces are alone in their island: the OpenSubdiv cages' per-face UVs) can only be reduced by
  // letting islands vanish, so its seams are placement seams, not strict ones.
  std::uint32_t strict_sets = 0;
  if (params.strict & kFeatureUvSeam)
    for (std::size_t k = 0; k < mesh.uv_sets.size() && k < 32; ++k) {
      const UvIslands islands = find_uv_islands(mesh, conn, static_cast<Index>(k));
      std::vector<Index> size(islands.num_islands, 0);
      Index with_uv = 0, alone = 0;
      for (Index f = 0; f < mesh.num_faces(); ++f)
        if (islands.face_island[f] != kInvalidIndex) ++size[islands.face_island[f]];
      for (Index f = 0; f < mesh.num_faces(); ++f) {
        if (islands.face_island[f] == kInvalidIndex) continue;
        ++with_uv;
        alone += size[islands.face_island[f]] == 1;
      }
      if (!(double(alone) > params.per_face_layout_fraction * double(with_uv))) strict_sets |= 1u << k;
    }
  fe.edge_strict.assign(ne, 0);
  fe.vertex_strict.assign(nv, 0);
  for (Index e = 0; e < ne; ++e) {
    std::uint8_t strict = fe.edge_bits[e] & params.strict;
    if ((strict & kFeatureUvSeam) && !(fe.edge_uv_seam_sets[e] & strict_sets))
      strict &= static_cast<std::uint8_t>(~kFeatureUvSeam);
    if (!strict) continue;
    fe.edge_strict[e] = 1;
    ++fe.strict_edges;
    for (Index v : conn.edge_vertices[e]) fe.vertex_strict[v] = 1;
  }
  return fe;
}

std::vector<std::uint8_t> texture_line_edges(const FeatureEdges& features) {
  std::vector<std::uint8_t> lines(features.edge_bits.size(), 0);
  for (std::size_t e = 0; e < lines.size(); ++e)
    lines[e] = features.edge_strict[e] && (features.edge_bits[e] & (kFeatureUvSeam | kFeatureMaterialBorder)) &&
               !(features.edge_bits[e] & (kFeatureBoundary | kFeatureNonManifold));
  return lines;
}

UvIslands find_uv_islands(const PolyMesh& mesh, const Connectivity& conn, Index uv_set) {
  const UvSet& set = mesh.uv_sets[uv_set];
  const Index nf = mesh.num_faces();
  std::vector<char> has_uv(nf, 1);
  for (Index f = 0; f < nf; ++f)
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c)
      if (set.corner[c] == kInvalidIndex) has_uv[f] = 0;

  UnionFind uf(nf);
  for (Index e = 0; e < conn.num_edges; ++e) {
    if (conn.edge_face_count(e) != 2) continue;
    const auto cs = conn.corners_of_edge(e);
    const Index f0 = conn.corner_face[cs[0]], f1 = conn.corner_face[cs[1]];
    if (!has_uv[f0] || !has_uv[f1]) continue;
    if (!seam_across(conn, set.values, set.corner, cs[0], cs[1])) uf.unite(f0, f1);
  }

  UvIslands r;
  r.face_island.assign(nf, kInvalidIndex);
  std::vector<Index> island_of_root(nf, kInvalidIndex);
  for (Index f = 0; f < nf; ++f) {
    if (!has_uv[f]) continue;
    Index& id = island_of_root[uf.find(f)];
    if (id == kInvalidIndex) {
      id = r.num_islands++;
      r.uv_min.push_back(Vec2::Constant(std::numeric_limits<double>::infinity()));
      r.uv_max.push_back(Vec2::Constant(-std::numeric_limits<double>::infinity()));
      r.area_3d.push_back(0.0);
    }
    r.face_island[f] = id;
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) {
      const Vec2& uv = set.values[set.corner[c]];
      r.uv_min[id] = r.uv_min[id].cwiseMin(uv);
      r.uv_max[id] = r.uv_max[id].cwiseMax(uv);
    }
    r.area_3d[id] += face_area_vector(mesh, f).norm();
  }
  return r;
}

IslandAreas island_areas(const PolyMesh& mesh, const Connectivity& conn, const std::vector<double>* face_island_area,
                         double per_face_layout_fraction) {
  IslandAreas r;
  if (mesh.uv_sets.empty()) return r;
  r.islands = find_uv_islands(mesh, conn, 0);
  const Index nf = mesh.num_faces(), n = r.islands.num_islands;
  if (n == 0) return r;
  std::vector<Index> size(n, 0);
  Index with_uv = 0, alone = 0;
  for (Index f = 0; f < nf; ++f)
    if (r.islands.face_island[f] != kInvalidIndex) ++size[r.islands.face_island[f]];
  for (Index f = 0; f < nf; ++f)
    if (r.islands.face_island[f] != kInvalidIndex) {
      ++with_uv;
      alone += size[r.islands.face_island[f]] == 1;
    }
  if (double(alone) > per_face_layout_fraction * double(with_uv)) return r;
  r.area = r.islands.area_3d;
  if (face_island_area && face_island_area->size() == nf)
    for (Index f = 0; f < nf; ++f)
      if (const Index i = r.islands.face_island[f]; i != kInvalidIndex) r.area[i] = std::max(r.area[i], (*face_island_area)[f]);
  r.exempt = false;
  return r;
}

std::vector<std::uint8_t> IslandAreas::faces_below(double bound) const {
  if (exempt) return {};
  std::vector<std::uint8_t> below(islands.face_island.size(), 0);
  for (std::size_t f = 0; f < below.size(); ++f)
    if (const Index i = islands.face_island[f]; i != kInvalidIndex) below[f] = area[i] > 0.0 && area[i] < bound;
  return below;
}

}  // namespace quadlod

namespace quadlod {

UvIslandAccount account_uv_islands(const PolyMesh& input, const PolyMesh& output,
                                   const std::vector<Index>& face_origin, Index uv_set, double one_face_area) {
  UvIslandAccount acc;
  const UvIslands in = find_uv_islands(input, build_connectivity(input), uv_set);
  const UvIslands out = find_uv_islands(output, build_connectivity(output), uv_set);
  auto counted = [](const UvIslands& isl, Index f) {
    const Index i = isl.face_island[f];
    return i != kInvalidIndex && isl.area_3d[i] > 0.0 ? i : kInvalidIndex;
  };
  for (double a : in.area_3d) acc.in += a > 0.0;
  for (double a : out.area_3d) acc.out += a > 0.0;
  // Links (input island, output island), one per pair.
  std::vector<std::pair<Index, Index>> links;
  for (Index f = 0; f < output.num_faces(); ++f) {
    const Index o = counted(out, f);
    const Index src = f < face_origin.size() ? face_origin[f] : kInvalidIndex;
    if (o == kInvalidIndex || src == kInvalidIndex) continue;
    const Index i = counted(in, src);
    if (i != kInvalidIndex) links.emplace_back(i, o);
  }
  std::sort(links.begin(), links.end());
  links.erase(std::unique(links.begin(), links.end()), links.end());
  std::vector<std::vector<Index>> outs_of(in.num_islands), ins_of(out.num_islands);
  for (const auto& [i, o] : links) {
    outs_of[i].push_back(o);
    ins_of[o].push_back(i);
  }
  double output_area = 0.0;
  Index output_faces = 0;
  for (Index f = 0; f < output.num_faces(); ++f) {
    output_area += face_area_vector(output, f).norm();
    ++output_faces;
  }
  const double mean_face_area =
      one_face_area > 0.0 ? one_face_area : output_faces > 0 ? output_area / double(output_faces) : 0.0;
  std::vector<Index> faces_of(in.num_islands, 0);
  for (Index f = 0; f < input.num_faces(); ++f)
    if (in.face_island[f] != kInvalidIndex) ++faces_of[in.face_island[f]];
  for (Index i = 0; i < in.num_islands; ++i) {
    if (!(in.area_3d[i] > 0.0)) continue;
    if (outs_of[i].empty()) {
      UvIslandAccount::Vanished v;
      v.island = i;
      v.faces = faces_of[i];
      v.area = in.area_3d[i];
      v.output_faces = mean_face_area > 0.0 ? v.area / mean_face_area : INFINITY;
      acc.vanished_below_one_face += v.output_faces < 1.0;
      acc.vanished_islands.push_back(v);
    } else if (outs_of[i].size() > 1) {
      acc.split_extra += static_cast<Index>(outs_of[i].size()) - 1;
      acc.split_islands.emplace_back(i, outs_of[i]);
    }
  }
  for (Index o = 0; o < out.num_islands; ++o) {
    if (!(out.area_3d[o] > 0.0)) continue;
    if (ins_of[o].empty()) ++acc.appeared;
    else if (ins_of[o].size() > 1) {
      acc.merged_reduction += static_cast<Index>(ins_of[o].size()) - 1;
      acc.merged_islands.emplace_back(o, ins_of[o]);
    }
  }
  acc.vanished = static_cast<Index>(acc.vanished_islands.size());
  acc.merged = static_cast<Index>(acc.merged_islands.size());
  acc.split = static_cast<Index>(acc.split_islands.size());
  return acc;
}

}  // namespace quadlod
