#include "quadlod/mesh.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace quadlod {

Index PolyMesh::add_face(std::span<const Index> vertices) {
  const Index f = num_faces();
  corner_vertex.insert(corner_vertex.end(), vertices.begin(), vertices.end());
  face_offsets.push_back(static_cast<Index>(corner_vertex.size()));
  for (UvSet& set : uv_sets) set.corner.resize(corner_vertex.size(), kInvalidIndex);
  if (has_normals()) corner_normal.resize(corner_vertex.size(), kInvalidIndex);
  if (!face_object.empty()) face_object.push_back(kInvalidIndex);
  if (!face_group.empty()) face_group.push_back(kInvalidIndex);
  if (!face_material.empty()) face_material.push_back(kInvalidIndex);
  if (!face_smoothing.empty()) face_smoothing.push_back(0);
  return f;
}

namespace {

std::string check_pool(const std::vector<Index>& per_corner, std::size_t pool, Index corners,
                       const char* what) {
  if (per_corner.empty()) return {};
  if (per_corner.size() != corners)
    return std::string(what) + ": " + std::to_string(per_corner.size()) + " entries for " +
           std::to_string(corners) + " corners";
  for (Index c = 0; c < corners; ++c)
    if (per_corner[c] != kInvalidIndex && per_corner[c] >= pool)
      return std::string(what) + ": corner " + std::to_string(c) + " refers to entry " +
             std::to_string(per_corner[c]) + " of " + std::to_string(pool);
  return {};
}

std::string check_tags(const std::vector<Index>& tags, std::size_t names, Index faces,
                       const char* what, bool is_name_index) {
  if (tags.empty()) return {};
  if (tags.size() != faces)
    return std::string(what) + ": " + std::to_string(tags.size()) + " entries for " +
           std::to_string(faces) + " faces";
  if (!is_name_index) return {};
  for (Index f = 0; f < faces; ++f)
    if (tags[f] != kInvalidIndex && tags[f] >= names)
      return std::string(what) + ": face " + std::to_string(f) + " refers to name " +
             std::to_string(tags[f]) + " of " + std::to_string(names);
  return {};
}

}  // namespace

std::string PolyMesh::check_layout() const {
  if (face_offsets.empty() || face_offsets.front() != 0) return "face offsets must start at 0";
  if (face_offsets.back() != corner_vertex.size())
    return "face offsets end at " + std::to_string(face_offsets.back()) + " but there are " +
           std::to_string(corner_vertex.size()) + " corners";
  for (Index f = 0; f < num_faces(); ++f)
    if (face_offsets[f + 1] < face_offsets[f] + 3)
      return "face " + std::to_string(f) + ": fewer than 3 corners";
  for (Index c = 0; c < num_corners(); ++c)
    if (corner_vertex[c] >= num_vertices())
      return "corner " + std::to_string(c) + ": vertex index " + std::to_string(corner_vertex[c]) +
             " out of range (" + std::to_string(num_vertices()) + " vertices)";
  if (!vertex_colors.empty() && vertex_colors.size() != positions.size())
    return "vertex colors: " + std::to_string(vertex_colors.size()) + " entries for " +
           std::to_string(positions.size()) + " vertices";
  for (std::size_t k = 0; k < uv_sets.size(); ++k) {
    const std::string what = "uv set " + std::to_string(k);
    if (uv_sets[k].corner.size() != num_corners())
      return what + ": " + std::to_string(uv_sets[k].corner.size()) + " entries for " +
             std::to_string(num_corners()) + " corners";
    if (std::string s = check_pool(uv_sets[k].corner, uv_sets[k].values.size(), num_corners(), what.c_str());
        !s.empty())
      return s;
  }
  for (const std::string& s :
       {check_pool(corner_normal, normals.size(), num_corners(), "normal"),
        check_tags(face_object, object_names.size(), num_faces(), "object", true),
        check_tags(face_group, group_names.size(), num_faces(), "group", true),
        check_tags(face_material, material_names.size(), num_faces(), "material", true),
        check_tags(face_smoothing, 0, num_faces(), "smoothing", false), skin.check(num_vertices())})
    if (!s.empty()) return s;
  // Blend shapes (issue 34): one finite displacement per vertex.
  for (std::size_t k = 0; k < morph_targets.size(); ++k) {
    const std::vector<Vec3>& d = morph_targets[k].displacement;
    const std::string what = "morph target " + std::to_string(k) + " ('" + morph_targets[k].name + "')";
    if (d.size() != positions.size())
      return what + ": " + std::to_string(d.size()) + " displacements for " + std::to_string(positions.size()) + " vertices";
    for (std::size_t v = 0; v < d.size(); ++v)
      if (!d[v].allFinite()) return what + ": vertex " + std::to_string(v) + ": displacement is not finite";
  }
  return {};
}

Index SkinWeights::max_influences() const {
  Index most = 0;
  for (Index v = 0; v < num_vertices(); ++v) most = std::max(most, influences(v));
  return most;
}

std::string SkinWeights::check(Index vertices) const {
  if (offsets.empty()) {
    if (!joint.empty() || !weight.empty()) return "skin: influences without offsets";
    return {};
  }
  if (offsets.size() != std::size_t(vertices) + 1)
    return "skin: " + std::to_string(offsets.size() - 1) + " vertices of weights for " + std::to_string(vertices) + " vertices";
  if (offsets.front() != 0 || offsets.back() != joint.size() || joint.size() != weight.size())
    return "skin: offsets do not cover the " + std::to_string(joint.size()) + " influences";
  for (Index v = 0; v < vertices; ++v) {
    const std::string what = "skin: vertex " + std::to_string(v) + ": ";
    if (offsets[v + 1] < offsets[v]) return what + "offsets decrease";
    if (offsets[v + 1] == offsets[v]) continue;
    double sum = 0.0;
    for (Index i = offsets[v]; i < offsets[v + 1]; ++i) {
      if (!(weight[i] > 0.0) || !std::isfinite(weight[i])) return what + "weight " + std::to_string(weight[i]) + " is not positive";
      if (joint[i] == kInvalidIndex) return what + "invalid joint";
      if (i > offsets[v] && (weight[i] > weight[i - 1] || (weight[i] == weight[i - 1] && joint[i] <= joint[i - 1])))
        return what + "influences not sorted by decreasing weight";
      for (Index k = offsets[v]; k < i; ++k)
        if (joint[k] == joint[i]) return what + "joint " + std::to_string(joint[i]) + " twice";
      sum += weight[i];
    }
    if (std::abs(sum - 1.0) > kSumTolerance) return what + "weights sum to " + std::to_string(sum);
  }
  return {};
}

BoundingBox bounding_box(const PolyMesh& mesh) {
  BoundingBox box;
  for (const Vec3& p : mesh.positions) box.extend(p);
  return box;
}

Vec3 face_area_vector(const PolyMesh& mesh, Index f) {
  // Newell's method, relative to the first corner for numerical stability far from the origin.
  const auto vs = mesh.face_vertices(f);
  const Vec3& o = mesh.positions[vs[0]];
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < vs.size(); ++i)
    sum += (mesh.positions[vs[i]] - o).cross(mesh.positions[vs[i + 1]] - o);
  return 0.5 * sum;
}

Vec3 face_normal(const PolyMesh& mesh, Index f) {
  const Vec3 a = face_area_vector(mesh, f);
  const double n = a.norm();
  return n > 0.0 ? Vec3(a / n) : Vec3::Zero();
}

Vec3 face_centroid(const PolyMesh& mesh, Index f) {
  Vec3 c = Vec3::Zero();
  for (Index v : mesh.face_vertices(f)) c += mesh.positions[v];
  return c / static_cast<double>(mesh.face_size(f));
}

std::uint64_t tri_equivalent_count(const PolyMesh& mesh) {
  std::uint64_t n = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) n += tri_equivalent(mesh.face_size(f));
  return n;
}

}  // namespace quadlod
