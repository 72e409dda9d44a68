// The test scene of the scene / LOD / batch tests (issue 21): a quad grid with two UV sets and
// two materials, instanced by two nodes, and a torus under a third, all under a root.
#pragma once

#include "quadlod/generators.h"
#include "quadlod/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <map>
#include <set>
#include <string>

namespace quadlod::scene_test {

/// Grid: 8×6 quads over [0,2]×[0,1.5]; UV set "uvmap" = the generator's lattice in [0,1]², set
/// "lightmap" = 0.5·uv + (0.25, 0.5) in [0.25,0.75]×[0.5,1]; material "red" for the 4 columns
/// on the left (24 faces), "blue" for the rest (24); one shared +Z normal; vertex colours
/// (x / 2, 0.25, y / 1.5).
/// Torus: 12×8 quads (96), the same two UV sets, material "blue".
/// Nodes: root → grid_a (mesh 0, +1 in x) → grid_b (mesh 0 again: an instance, +2 in z);
/// root → torus_c (mesh 1, scaled by 2).
inline Scene make_test_scene() {
  const auto add_sets = [](PolyMesh& mesh) {
    mesh.uv_sets[0].name = "uvmap";
    UvSet light = mesh.uv_sets[0];
    light.name = "lightmap";
    for (Vec2& uv : light.values) uv = 0.5 * uv + Vec2(0.25, 0.5);
    mesh.uv_sets.push_back(std::move(light));
  };
  PolyMesh grid = make_grid(8, 6, 2.0, 1.5);
  add_sets(grid);
  grid.normals = {Vec3(0, 0, 1)};
  grid.corner_normal.assign(grid.num_corners(), 0);
  grid.material_names = {"red", "blue"};
  grid.face_material.resize(grid.num_faces());
  for (Index f = 0; f < grid.num_faces(); ++f) grid.face_material[f] = (f % 8) < 4 ? 0 : 1;
  // Vertex colours: red rising along x, blue along y (k/8, k/6 are exact in float for the checks).
  for (const Vec3& p : grid.positions) grid.vertex_colors.emplace_back(p.x() / 2.0, 0.25, p.y() / 1.5);
  PolyMesh torus = make_torus(12, 8);
  add_sets(torus);
  torus.material_names = {"blue"};
  torus.face_material.assign(torus.num_faces(), 0);

  Scene scene;
  scene.materials = {{"red", {0.8, 0.1, 0.1, 1.0}, ""}, {"blue", {0.1, 0.2, 0.9, 1.0}, ""}};
  scene.meshes = {{"grid", std::move(grid)}, {"torus", std::move(torus)}};
  SceneNode root{"root", kInvalidIndex, Eigen::Matrix4d::Identity(), {}};
  SceneNode a{"grid_a", 0, Eigen::Matrix4d::Identity(), {0}};
  a.local(0, 3) = 1.0;
  SceneNode b{"grid_b", 1, Eigen::Matrix4d::Identity(), {0}};
  b.local(2, 3) = 2.0;
  SceneNode c{"torus_c", 0, Eigen::Matrix4d::Identity(), {1}};
  c.local.topLeftCorner<3, 3>() *= 2.0;
  scene.nodes = {root, a, b, c};
  return scene;
}

struct FaceTally {
  std::uint64_t quads = 0, tris = 0, ngons = 0;
  std::uint64_t faces() const { return quads + tris + ngons; }
};

inline FaceTally tally(const PolyMesh& mesh) {
  FaceTally t;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Index k = mesh.face_size(f);
    (k == 3 ? t.tris : k == 4 ? t.quads : t.ngons)++;
  }
  return t;
}

/// Faces per material name.
inline std::map<std::string, std::uint64_t> faces_by_material(const PolyMesh& mesh) {
  std::map<std::string, std::uint64_t> out;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Index m = mesh.face_material.empty() ? kInvalidIndex : mesh.face_material[f];
    out[m == kInvalidIndex || m >= mesh.material_names.size() ? "" : mesh.material_names[m]]++;
  }
  return out;
}

/// The scene mesh referenced by the node called `node` (nullptr when absent).
inline const SceneMesh* mesh_of_node(const Scene& scene, const std::string& node) {
  for (const SceneNode& n : scene.nodes)
    if (n.name == node && !n.meshes.empty()) return &scene.meshes[n.meshes[0]];
  return nullptr;
}

/// Bounding box of the UVs corners of set k use.
inline std::pair<Vec2, Vec2> uv_range(const PolyMesh& mesh, std::size_t k) {
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (Index t : mesh.uv_sets[k].corner)
    if (t != kInvalidIndex) {
      lo = lo.cwiseMin(mesh.uv_sets[k].values[t]);
      hi = hi.cwiseMax(mesh.uv_sets[k].values[t]);
    }
  return {lo, hi};
}

inline bool blender_available() { return std::system("command -v blender > /dev/null 2>&1") == 0; }

}  // namespace quadlod::scene_test
