// The output of the cluster collapse: Collapser::assemble builds the reduced mesh from the
// pieces of every input face once nothing is refused, and project_attributes gives moved
// vertices their UVs and normals per wedge (cluster_collapse.h, point 5). The class: collapser.h.
#include "geometry/bvh.h"
#include "mesh/union_find.h"
#include "post/collapser.h"
#include "util/parallel.h"

#include <algorithm>
#include <mutex>
#include <cmath>

namespace quadlod::collapse_detail {

// --- output mesh ---------------------------------------------------------------------------------

void Collapser::assemble(const std::vector<std::uint8_t>& edge_kept, ClusterCollapseResult& out) {
  PolyMesh& om = out.mesh;
  // Used output vertices, numbered in increasing root id.
  std::vector<Index> new_id(nv_, kInvalidIndex);
  for (Index f = 0; f < nf_; ++f) {
    Index off = piece_base(f);
    for (Index p = 0; p < piece_count_[f]; ++p) {
      const Index len = piece_buf_[off];
      for (Index i = 0; i < len; ++i) new_id[root_of_corner(piece_buf_[off + 1 + i])] = 0;
      off += len + 1;
    }
  }
  Index next = 0;
  for (Index v = 0; v < nv_; ++v)
    if (root_[v] == v && new_id[v] != kInvalidIndex) new_id[v] = next++;
  om.positions.resize(next);
  const bool colors = mesh_.vertex_colors.size() == nv_ && nv_ > 0;
  if (colors) om.vertex_colors.assign(next, Vec3::Zero());
  out.vertex_map.assign(nv_, kInvalidIndex);
  for (Index v = 0; v < nv_; ++v) {
    const Index r = root_[v];
    const Index id = new_id[r];
    if (id == kInvalidIndex) {
      ++stats_.vertices_removed_unused;
      continue;
    }
    out.vertex_map[v] = id;
    if (r == v) om.positions[id] = pos_[v];
    if (colors) om.vertex_colors[id] += mesh_.vertex_colors[v] / double(cluster_size(r));
  }

  // Faces, in input order, pieces in walk order; attributes per surviving corner: its own input
  // index, or the value projected / recomputed for its wedge when its vertex moved.
  const bool normals = mesh_.has_normals();
  const bool tag_o = !mesh_.face_object.empty(), tag_g = !mesh_.face_group.empty();
  const bool tag_m = !mesh_.face_material.empty(), tag_s = !mesh_.face_smoothing.empty();
  om.uv_sets.resize(mesh_.uv_sets.size());
  for (std::size_t k = 0; k < om.uv_sets.size(); ++k) {
    om.uv_sets[k].name = mesh_.uv_sets[k].name;
    om.uv_sets[k].values = mesh_.uv_sets[k].values;
  }
  om.normals = mesh_.normals;
  std::vector<std::vector<Index>> uv_override;
  std::vector<Index> normal_override;
  if (params_.project_attributes) project_attributes(om, uv_override, normal_override);
  auto uv_of = [&](std::size_t k, Index c) {
    const Index t = uv_override.empty() ? kInvalidIndex : uv_override[k][c];
    return t != kInvalidIndex ? t : mesh_.uv_sets[k].corner[c];
  };
  auto normal_of = [&](Index c) {
    const Index t = normal_override.empty() ? kInvalidIndex : normal_override[c];
    return t != kInvalidIndex ? t : mesh_.corner_normal[c];
  };
  om.object_names = mesh_.object_names;
  om.group_names = mesh_.group_names;
  om.material_names = mesh_.material_names;
  om.material_libraries = mesh_.material_libraries;
  om.face_offsets.assign(1, 0);
  om.corner_vertex.reserve(mesh_.num_corners());
  for (Index f = 0; f < nf_; ++f) {
    if (piece_count_[f] == 0) ++stats_.faces_dropped;
    if (face_pinched_[f]) ++stats_.faces_pinched;
    Index off = piece_base(f);
    for (Index p = 0; p < piece_count_[f]; ++p) {
      const Index len = piece_buf_[off];
      for (Index i = 0; i < len; ++i) {
        const Index c = piece_buf_[off + 1 + i];
        om.corner_vertex.push_back(new_id[root_of_corner(c)]);
        for (std::size_t k = 0; k < om.uv_sets.size(); ++k) om.uv_sets[k].corner.push_back(uv_of(k, c));
        if (normals) om.corner_normal.push_back(normal_of(c));
      }
      om.face_offsets.push_back(static_cast<Index>(om.corner_vertex.size()));
      out.face_source.push_back(f);
      if (tag_o) om.face_object.push_back(mesh_.face_object[f]);
      if (tag_g) om.face_group.push_back(mesh_.face_group[f]);
      if (tag_m) om.face_material.push_back(mesh_.face_material[f]);
      if (tag_s) om.face_smoothing.push_back(mesh_.face_smoothing[f]);
      if (len == 3) ++stats_.triangles_out;
      else if (len == 4) ++stats_.quads_out;
      else ++stats_.ngons_out;
      if (len == 3 && mesh_.face_size(f) == 4 && piece_count_[f] == 1) ++stats_.quads_to_triangles;
      stats_.tri_equivalent_out += tri_equivalent(len);
      off += len + 1;
    }
  }
  stats_.faces_in = nf_;
  stats_.faces_out = om.num_faces();

  out.edge_collapsed_final.assign(ne_, 0);
  for (Index e = 0; e < ne_; ++e) {
    const auto [a, b] = conn_.edge_vertices[e];
    if (root_[a] != root_[b] || a == b) continue;
    out.edge_collapsed_final[e] = 1;
    ++stats_.collapsed_edges_final;
    if (edge_kept[e] != 0) ++stats_.implied_collapsed_edges;
  }
  for (Index v = 0; v < nv_; ++v)
    if (root_[v] == v && cluster_size(v) > 1 && new_id[v] != kInvalidIndex) {
      ++stats_.clusters;
      stats_.clustered_vertices += cluster_size(v);
      stats_.largest_cluster = std::max(stats_.largest_cluster, cluster_size(v));
    }
  if (stats_.largest_cluster == 0 && next > 0) stats_.largest_cluster = 1;
}

// --- attributes per wedge (issue 7) ---------------------------------------------------------------
//
// A moved vertex gets new attribute values per *sector*: the input faces around its cluster
// (its star), joined across manifold edges whose two sides agree on the attribute. Each input
// corner at a member belongs to its face's sector, so corners of one wedge share one new value and
// a seam through the vertex keeps one value per side:
//
//        island A │ island B          sectors of the cluster {a, b} (a on the seam │):
//          ┌──────a──────┐            A-faces → UV of the projection into island A's faces,
//          │      ║      │            B-faces → UV of the projection into island B's faces;
//          └──────b──────┘            the vertex stays on the seam (place_on_feature), so both
//                                     projections land on the seam: no stretch across it.
//
// UVs: the closest point of the sector's input faces (fan triangles) to the new position, and the
// barycentric mix of that triangle's corner UVs (Hoppe 1999's "project into the same chart").
// Normals: the normalised sum of the area vectors of the output faces of the sector around the
// vertex — recomputed where smooth, and hard edges stay hard because they separate sectors.
void Collapser::project_attributes(PolyMesh& om, std::vector<std::vector<Index>>& uv_override,
                                   std::vector<Index>& normal_override) {
  const std::size_t sets = mesh_.uv_sets.size();
  const bool normals = mesh_.has_normals();
  if (sets == 0 && !normals) return;
  uv_override.assign(sets, std::vector<Index>(mesh_.num_corners(), kInvalidIndex));
  if (normals) normal_override.assign(mesh_.num_corners(), kInvalidIndex);

  // The corner of face(o) at vertex v, for a corner o whose edge has v as an endpoint.
  auto corner_at = [&](Index o, Index v) { return conn_.corner_vertex[o] == v ? o : conn_.corner_next[o]; };
  auto same_uv = [&](const UvSet& set, Index c, Index o) {
    const Index x = set.corner[c], y = set.corner[o];
    if (x == kInvalidIndex || y == kInvalidIndex) return x == y;
    return x == y || set.values[x] == set.values[y];
  };
  auto same_normal = [&](Index c, Index o) {
    const Index x = mesh_.corner_normal[c], y = mesh_.corner_normal[o];
    if (x == kInvalidIndex || y == kInvalidIndex) return x == y;
    return x == y || mesh_.normals[x] == mesh_.normals[y];
  };

  struct Nearest {
    double d2 = INFINITY;
    Index c0 = kInvalidIndex, c1 = kInvalidIndex, c2 = kInvalidIndex;  // input corners
    Vec3 w = Vec3::Zero();                                             // barycentric weights
  };
  // Clusters in contiguous chunks of roots on all threads. Each chunk writes the overrides of
  // its own clusters' corners and appends its new values to its own lists, numbered from 0;
  // the lists are then appended in chunk order and the chunk's overrides shifted by what came
  // before, so the output is the same for any thread count.
  struct NewValues {
    std::vector<std::vector<Vec2>> uv;
    std::vector<Vec3> normals;
  };
  std::vector<NewValues> fresh;
  std::mutex fresh_mutex;
  const std::size_t chunks = parallel_chunks(std::size_t(nv_), params_.threads, params_.min_parallel_faces,
                                             [&](std::size_t chunk_begin, std::size_t chunk_end, std::size_t chunk) {
  NewValues mine;
  mine.uv.resize(sets);
  std::vector<Index> star, star_slot(nf_, kInvalidIndex), sector(0);
  std::vector<Nearest> nearest;
  std::vector<Index> sector_value;
  for (Index r = Index(chunk_begin); r < Index(chunk_end); ++r) {
    if (root_[r] != r || cluster_size(r) < 2) continue;
    star.clear();
    for (Index m : members(r))
      for (Index c : conn_.corners_at_vertex(m)) {
        const Index f = conn_.corner_face[c];
        if (star_slot[f] != kInvalidIndex) continue;
        star_slot[f] = static_cast<Index>(star.size());
        star.push_back(f);
      }
    const Index ns = static_cast<Index>(star.size());
    const Vec3& x = pos_[r];

    // Closest point of each star face to the new position (independent of the attribute).
    nearest.assign(ns, Nearest{});
    for (Index i = 0; i < ns; ++i) {
      const Index f = star[i], b = mesh_.face_begin(f), k = mesh_.face_size(f);
      const Vec3& a = mesh_.positions[mesh_.corner_vertex[b]];
      for (Index j = 1; j + 1 < k; ++j) {
        const Vec3& p1 = mesh_.positions[mesh_.corner_vertex[b + j]];
        const Vec3& p2 = mesh_.positions[mesh_.corner_vertex[b + j + 1]];
        const TrianglePoint tp = closest_point_on_triangle(x, a, p1, p2);
        if (!(tp.distance_sq < nearest[i].d2)) continue;
        // Barycentric weights of the closest point (least squares; a sliver falls back to the
        // nearest corner).
        const Vec3 v0 = p1 - a, v1 = p2 - a, v2 = tp.point - a;
        const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
        const double d20 = v2.dot(v0), d21 = v2.dot(v1), den = d00 * d11 - d01 * d01;
        Vec3 w;
        if (den > 1e-12 * d00 * d11 && den > 0.0) {
          const double wv = (d11 * d20 - d01 * d21) / den, ww = (d00 * d21 - d01 * d20) / den;
          w = Vec3(1.0 - wv - ww, wv, ww);
        } else {
          const double da = v2.squaredNorm(), d1 = (tp.point - p1).squaredNorm(), d2 = (tp.point - p2).squaredNorm();
          w = da <= d1 && da <= d2 ? Vec3(1, 0, 0) : d1 <= d2 ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
        }
        nearest[i] = {tp.distance_sq, b, b + j, b + j + 1, w};
      }
    }
    // Does an output piece of star face i contain r? Only sectors with such a face need values.
    auto face_uses_root = [&](Index f) {
      Index off = piece_base(f);
      for (Index p = 0; p < piece_count_[f]; ++p) {
        const Index len = piece_buf_[off];
        for (Index i = 0; i < len; ++i)
          if (root_of_corner(piece_buf_[off + 1 + i]) == r) return true;
        off += len + 1;
      }
      return false;
    };

    // Sectors for one attribute, then one new value per used sector.
    auto label_sectors = [&](auto&& agree) {
      UnionFind uf(ns);
      for (Index i = 0; i < ns; ++i) {
        const Index f = star[i];
        for (Index c = mesh_.face_begin(f); c < mesh_.face_end(f); ++c) {
          const Index o = conn_.across(c);
          if (o == kInvalidIndex) continue;
          const Index j = star_slot[conn_.corner_face[o]];
          if (j == kInvalidIndex) continue;
          const Index a = conn_.corner_vertex[c], b = conn_.tip_vertex(c);
          if (agree(c, corner_at(o, a)) && agree(conn_.corner_next[c], corner_at(o, b))) uf.unite(i, j);
        }
      }
      sector.resize(ns);
      for (Index i = 0; i < ns; ++i) sector[i] = uf.find(i);
    };
    auto assign = [&](std::vector<Index>& override, auto&& value_for_sector) {
      sector_value.assign(ns, kInvalidIndex);
      for (Index i = 0; i < ns; ++i) {
        const Index s = sector[i];
        if (sector_value[s] == kInvalidIndex && face_uses_root(star[i])) sector_value[s] = value_for_sector(s);
      }
      for (Index m : members(r))
        for (Index c : conn_.corners_at_vertex(m)) override[c] = sector_value[sector[star_slot[conn_.corner_face[c]]]];
    };

    for (std::size_t k = 0; k < sets; ++k) {
      const UvSet& set = mesh_.uv_sets[k];
      label_sectors([&](Index c, Index o) { return same_uv(set, c, o); });
      assign(uv_override[k], [&](Index s) -> Index {
        const Nearest* best = nullptr;
        for (Index i = 0; i < ns; ++i) {
          if (sector[i] != s) continue;
          const Nearest& n = nearest[i];
          if (n.c0 == kInvalidIndex || set.corner[n.c0] == kInvalidIndex || set.corner[n.c1] == kInvalidIndex ||
              set.corner[n.c2] == kInvalidIndex)
            continue;
          if (!best || n.d2 < best->d2) best = &n;
        }
        if (!best) return kInvalidIndex;
        const Vec2 uv = best->w[0] * set.values[set.corner[best->c0]] + best->w[1] * set.values[set.corner[best->c1]] +
                        best->w[2] * set.values[set.corner[best->c2]];
        mine.uv[k].push_back(uv);
        return static_cast<Index>(mine.uv[k].size() - 1);
      });
    }
    if (normals) {
      label_sectors(same_normal);
      // Projected like the UVs: the barycentric mix of the input normals at the closest point of
      // the sector's input faces, so that custom normals (foliage pointing up, weighted normals)
      // travel and each side of a line keeps its own, interpolated along it (issue 32). Where
      // that mix has no direction (opposite normals, corners without one), the normal follows
      // the output faces of the sector.
      assign(normal_override, [&](Index s) -> Index {
        const Nearest* best = nullptr;
        for (Index i = 0; i < ns; ++i) {
          if (sector[i] != s) continue;
          const Nearest& n = nearest[i];
          if (n.c0 == kInvalidIndex || mesh_.corner_normal[n.c0] == kInvalidIndex ||
              mesh_.corner_normal[n.c1] == kInvalidIndex || mesh_.corner_normal[n.c2] == kInvalidIndex)
            continue;
          if (!best || n.d2 < best->d2) best = &n;
        }
        if (best) {
          const Vec3 mix = best->w[0] * mesh_.normals[mesh_.corner_normal[best->c0]] +
                           best->w[1] * mesh_.normals[mesh_.corner_normal[best->c1]] +
                           best->w[2] * mesh_.normals[mesh_.corner_normal[best->c2]];
          const double len = mix.norm();
          if (len > 1e-6 && std::isfinite(len)) {
            mine.normals.push_back(mix / len);
            return static_cast<Index>(mine.normals.size() - 1);
          }
        }
        Vec3 sum = Vec3::Zero();
        for (Index i = 0; i < ns; ++i) {
          if (sector[i] != s) continue;
          Index off = piece_base(star[i]);
          for (Index p = 0; p < piece_count_[star[i]]; ++p) {
            const Index len = piece_buf_[off];
            const Index* cs = piece_buf_.data() + off + 1;
            off += len + 1;
            bool has_r = false;
            for (Index j = 0; j < len; ++j) has_r = has_r || root_of_corner(cs[j]) == r;
            if (has_r) sum += area_vector(len, [&](Index j) -> const Vec3& { return pos_[root_of_corner(cs[j])]; });
          }
        }
        const double n = sum.norm();
        if (!(n > 0.0) || !std::isfinite(n)) return kInvalidIndex;
        mine.normals.push_back(sum / n);
        return static_cast<Index>(mine.normals.size() - 1);
      });
    }
    for (Index f : star) star_slot[f] = kInvalidIndex;
  }
  std::lock_guard lock(fresh_mutex);
  if (fresh.size() <= chunk) fresh.resize(chunk + 1);
  fresh[chunk] = std::move(mine);
  });

  const std::size_t per_chunk = (std::size_t(nv_) + chunks - 1) / std::max<std::size_t>(1, chunks);
  for (std::size_t chunk = 0; chunk < fresh.size(); ++chunk) {
    NewValues& mine = fresh[chunk];
    std::vector<Index> uv_base(sets);
    for (std::size_t k = 0; k < sets; ++k) {
      uv_base[k] = static_cast<Index>(om.uv_sets[k].values.size());
      om.uv_sets[k].values.insert(om.uv_sets[k].values.end(), mine.uv[k].begin(), mine.uv[k].end());
      stats_.uv_values_projected += static_cast<Index>(mine.uv[k].size());
    }
    const Index normal_base = static_cast<Index>(om.normals.size());
    om.normals.insert(om.normals.end(), mine.normals.begin(), mine.normals.end());
    stats_.normals_recomputed += static_cast<Index>(mine.normals.size());
    const Index begin = Index(std::min(std::size_t(nv_), chunk * per_chunk));
    const Index end = Index(std::min(std::size_t(nv_), (chunk + 1) * per_chunk));
    for (Index r = begin; r < end; ++r) {
      if (root_[r] != r || cluster_size(r) < 2) continue;
      for (Index m : members(r))
        for (Index c : conn_.corners_at_vertex(m)) {
          for (std::size_t k = 0; k < sets; ++k)
            if (uv_override[k][c] != kInvalidIndex) uv_override[k][c] += uv_base[k];
          if (normals && normal_override[c] != kInvalidIndex) normal_override[c] += normal_base;
        }
    }
  }
}

}  // namespace quadlod::collapse_detail
