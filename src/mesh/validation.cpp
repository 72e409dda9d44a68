#include "mesh/validation.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace quadlod {

namespace {

// FNV-1a over the sorted vertex list: duplicate detection must not depend on corner order or
// orientation (a face and its flipped copy are duplicates for rendering and for the pipeline).
std::uint64_t hash_sorted(const std::vector<Index>& vs) {
  std::uint64_t h = 1469598103934665603ull;
  for (Index v : vs) {
    h ^= v;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

MeshStats compute_stats(const PolyMesh& mesh, const Connectivity& conn,
                        const MeshStatsParams& params) {
  MeshStats s;
  s.vertices = mesh.num_vertices();
  s.faces = mesh.num_faces();
  s.bbox = bounding_box(mesh);
  s.edges = conn.num_edges;
  s.has_normals = mesh.has_normals();
  s.materials = static_cast<Index>(mesh.material_names.size());
  s.groups = static_cast<Index>(mesh.group_names.size());

  for (const Vec3& p : mesh.positions)
    if (!p.allFinite()) ++s.nonfinite_vertices;

  std::vector<bool> used(mesh.num_vertices(), false);
  for (Index v : mesh.corner_vertex) used[v] = true;
  s.unused_vertices = static_cast<Index>(std::count(used.begin(), used.end(), false));

  const double diag = s.bbox.diagonal();
  const double zero_area = params.zero_area_epsilon * diag * diag;
  std::unordered_map<std::uint64_t, std::vector<Index>> seen;  // hash → faces with that hash
  seen.reserve(mesh.num_faces());
  std::vector<Index> sorted, other;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Index k = mesh.face_size(f);
    if (k == 3) ++s.triangles;
    else if (k == 4) ++s.quads;
    else ++s.ngons;
    s.tri_equivalent += tri_equivalent(k);
    s.max_face_degree = std::max(s.max_face_degree, k);
    ++s.faces_by_degree[k];

    const auto vs = mesh.face_vertices(f);
    sorted.assign(vs.begin(), vs.end());
    std::sort(sorted.begin(), sorted.end());
    const bool repeated = std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end();
    const bool flat = !(face_area_vector(mesh, f).norm() > zero_area);
    s.repeated_index_faces += repeated;
    s.zero_area_faces += flat;
    s.degenerate_faces += repeated || flat;

    auto& bucket = seen[hash_sorted(sorted)];
    bool duplicate = false;
    for (Index g : bucket) {
      const auto ws = mesh.face_vertices(g);
      other.assign(ws.begin(), ws.end());
      std::sort(other.begin(), other.end());
      if (other == sorted) {
        duplicate = true;
        break;
      }
    }
    if (duplicate) ++s.duplicate_faces;
    else bucket.push_back(f);
  }

  const double zero_length = params.zero_length_epsilon * diag;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    s.zero_length_edges += !((mesh.positions[a] - mesh.positions[b]).norm() > zero_length);
    s.boundary_edges += conn.is_boundary_edge(e);
    s.nonmanifold_edges += conn.is_nonmanifold_edge(e);
  }
  s.boundary_loops = static_cast<Index>(boundary_loops(conn).size());
  const auto nm = nonmanifold_vertices(conn);
  s.nonmanifold_vertices = static_cast<Index>(std::count(nm.begin(), nm.end(), true));
  s.components = face_components(conn).count;

  s.uv_sets = static_cast<Index>(mesh.uv_sets.size());
  if (mesh.has_uvs()) {
    const auto& corner = mesh.uv_sets[0].corner;
    const auto missing = std::count(corner.begin(), corner.end(), kInvalidIndex);
    s.has_uvs = missing == 0;
    s.has_partial_uvs = missing > 0 && missing < static_cast<long>(corner.size());
  }
  return s;
}

nlohmann::json to_json(const MeshStats& s) {
  nlohmann::json by_degree = nlohmann::json::object();
  for (const auto& [degree, count] : s.faces_by_degree) by_degree[std::to_string(degree)] = count;
  auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  nlohmann::json bbox = nullptr;
  if (!s.bbox.empty())
    bbox = {{"min", vec(s.bbox.min)}, {"max", vec(s.bbox.max)}, {"diagonal", s.bbox.diagonal()}};
  return {
      {"vertices", s.vertices},
      {"unused_vertices", s.unused_vertices},
      {"faces", s.faces},
      {"triangles", s.triangles},
      {"quads", s.quads},
      {"ngons", s.ngons},
      {"faces_by_degree", by_degree},
      {"tri_equivalent", s.tri_equivalent},
      {"edges", s.edges},
      {"boundary_edges", s.boundary_edges},
      {"boundary_loops", s.boundary_loops},
      {"nonmanifold_edges", s.nonmanifold_edges},
      {"nonmanifold_vertices", s.nonmanifold_vertices},
      {"degenerate_faces", s.degenerate_faces},
      {"repeated_index_faces", s.repeated_index_faces},
      {"zero_area_faces", s.zero_area_faces},
      {"duplicate_faces", s.duplicate_faces},
      {"zero_length_edges", s.zero_length_edges},
      {"components", s.components},
      {"nonfinite_vertices", s.nonfinite_vertices},
      {"has_uvs", s.has_uvs},
      {"uv_sets", s.uv_sets},
      {"has_partial_uvs", s.has_partial_uvs},
      {"has_normals", s.has_normals},
      {"materials", s.materials},
      {"groups", s.groups},
      {"bbox", bbox},
  };
}

std::string check_pipeline_input(const PolyMesh& mesh) {
  if (std::string layout = mesh.check_layout(); !layout.empty()) return layout;
  if (mesh.num_faces() == 0) return "the mesh has no faces";
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (!mesh.positions[v].allFinite())
      return "vertex " + std::to_string(v + 1) + " (1-based) has a non-finite coordinate";
  return {};
}

nlohmann::json validity_json(const MeshStats& output, const MeshStats& input) {
  return {
      {"nonmanifold_edges", output.nonmanifold_edges},
      {"nonmanifold_vertices", output.nonmanifold_vertices},
      {"degenerate_faces", output.degenerate_faces},
      {"duplicate_faces", output.duplicate_faces},
      {"zero_length_edges", output.zero_length_edges},
      {"zero_length_edges_in", input.zero_length_edges},
      {"boundary_edges", output.boundary_edges},
      {"components", output.components},
      {"new_nonmanifold_edges", std::max<long>(0, long(output.nonmanifold_edges) - long(input.nonmanifold_edges))},
  };
}

}  // namespace quadlod
