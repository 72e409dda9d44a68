// Helpers shared by the I/O tests: a self-cleaning temp directory, file helpers, a tiny
// generator, and exact mesh comparison that names the first difference.
#pragma once

#include "quadlod/io.h"
#include "quadlod/mesh.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace quadlod::io_test {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = fs::temp_directory_path() /
            ("quadlod-io-test-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  fs::path path_;
};

inline void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

inline std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// n × m quads in the z = 0 plane with a per-corner UV lattice (shared UVs, no seams).
inline PolyMesh quad_grid(Index n, Index m) {
  PolyMesh mesh;
  mesh.uv_sets.resize(1);
  for (Index j = 0; j <= m; ++j)
    for (Index i = 0; i <= n; ++i) {
      mesh.positions.emplace_back(0.1 * i, 0.1 * j, 0.0);
      mesh.uv_sets[0].values.emplace_back(double(i) / n, double(j) / m);
    }
  const auto id = [&](Index i, Index j) { return j * (n + 1) + i; };
  for (Index j = 0; j < m; ++j)
    for (Index i = 0; i < n; ++i) {
      for (const Index v : {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}) {
        mesh.corner_vertex.push_back(v);
        mesh.uv_sets[0].corner.push_back(v);
      }
      mesh.face_offsets.push_back(mesh.num_corners());
    }
  return mesh;
}

/// Empty when a and b are identical in every field; else the first difference.
inline std::string mesh_difference(const PolyMesh& a, const PolyMesh& b) {
  std::ostringstream d;
  const auto vec = [&](const char* what, const auto& x, const auto& y) {
    if (!d.str().empty()) return;
    if (x.size() != y.size()) {
      d << what << ": size " << x.size() << " vs " << y.size();
      return;
    }
    for (std::size_t i = 0; i < x.size(); ++i)
      if (!(x[i] == y[i])) {
        d << what << "[" << i << "] differs";
        return;
      }
  };
  vec("positions", a.positions, b.positions);
  vec("vertex_colors", a.vertex_colors, b.vertex_colors);
  vec("face_offsets", a.face_offsets, b.face_offsets);
  vec("corner_vertex", a.corner_vertex, b.corner_vertex);
  if (d.str().empty() && a.uv_sets.size() != b.uv_sets.size())
    d << "uv_sets: " << a.uv_sets.size() << " vs " << b.uv_sets.size();
  for (std::size_t k = 0; k < a.uv_sets.size() && k < b.uv_sets.size(); ++k) {
    vec("uv name", a.uv_sets[k].name, b.uv_sets[k].name);
    vec("uv values", a.uv_sets[k].values, b.uv_sets[k].values);
    vec("uv corner", a.uv_sets[k].corner, b.uv_sets[k].corner);
  }
  vec("normals", a.normals, b.normals);
  vec("corner_normal", a.corner_normal, b.corner_normal);
  vec("face_object", a.face_object, b.face_object);
  vec("face_group", a.face_group, b.face_group);
  vec("face_material", a.face_material, b.face_material);
  vec("face_smoothing", a.face_smoothing, b.face_smoothing);
  vec("object_names", a.object_names, b.object_names);
  vec("group_names", a.group_names, b.group_names);
  vec("material_names", a.material_names, b.material_names);
  vec("material_libraries", a.material_libraries, b.material_libraries);
  return d.str();
}

inline std::string corpus_file(const std::string& name) {
#ifdef QUADLOD_CORPUS_DIR
  const fs::path p = fs::path(QUADLOD_CORPUS_DIR) / name;
  if (fs::exists(p)) return p.string();
#endif
  return {};
}

/// The bytes write_mesh() gives `mesh` as an OBJ (through a temp file named after `tag`): what
/// the determinism tests compare.
inline std::string obj_bytes(const PolyMesh& mesh, const std::string& tag) {
  TempDir dir;
  const fs::path path = dir.path() / (tag + ".obj");
  EXPECT_TRUE(write_mesh(mesh, path.string()).ok());
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace quadlod::io_test
