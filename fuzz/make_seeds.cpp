// quadlod — writes the seed corpora of the fuzz targets from the project's generated meshes
// (`quadlod_fuzz_seeds DIR` → DIR/obj, DIR/ply, DIR/off, DIR/pipeline). Seeds are made at
// fuzz time rather than committed: they follow the writers, and no binary blob lives in git.
#include "fuzz_checks.h"

#include "io/io_common.h"
#include "quadlod/generators.h"

#ifdef QUADLOD_FUZZ_HAS_SCENE
#include "quadlod/scene.h"
#endif

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace quadlod;

namespace {

void save(const fs::path& dir, const std::string& name, const std::string& bytes) {
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << bytes;
}

// A mesh with every attribute the readers fill in: UVs, normals, colours, tags.
PolyMesh with_attributes(PolyMesh mesh) {
  UvSet uv;
  for (Index v = 0; v < mesh.num_vertices(); ++v) uv.values.emplace_back(mesh.positions[v].x(), mesh.positions[v].y());
  uv.corner = mesh.corner_vertex;
  mesh.uv_sets.push_back(uv);
  UvSet second = uv;
  second.name = "lightmap";
  mesh.uv_sets.push_back(second);
  mesh.normals.assign(mesh.num_vertices(), Vec3(0, 0, 1));
  mesh.corner_normal = mesh.corner_vertex;
  mesh.vertex_colors.assign(mesh.num_vertices(), Vec3(0.25, 0.5, 1.0));
  mesh.material_names = {"red", "blue"};
  mesh.group_names = {"left"};
  mesh.object_names = {"thing"};
  mesh.material_libraries = {"thing.mtl"};
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    mesh.face_material.push_back(f % 2);
    mesh.face_group.push_back(0);
    mesh.face_object.push_back(0);
    mesh.face_smoothing.push_back(f % 3);
  }
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: quadlod_fuzz_seeds DIR\n");
    return 1;
  }
  const fs::path root = argv[1];
  PolyMesh mixed = make_grid(2, 2);
  mixed.add_face({0, 4, 1});  // a triangle and a pentagon beside the quads
  mixed.add_face({2, 5, 8, 7, 6});
  const std::vector<std::pair<std::string, PolyMesh>> meshes = {
      {"grid3", make_grid(3, 3)},        {"torus6x4", make_torus(6, 4)},  {"cube2", make_cube(2)},
      {"cylinder5x2", make_cylinder(5, 2)}, {"attributes", with_attributes(make_grid(2, 2))},
      {"mixed", mixed}};
  int written = 0;
  for (const auto& [name, mesh] : meshes) {
    std::string out, error;
    WriteOptions wo;
    wo.precision = 6;
    if (io_detail::format_obj(mesh, wo, out, error)) save(root / "obj", name + ".obj", out), ++written;
    if (io_detail::format_off(mesh, wo, out, error)) save(root / "off", name + ".off", out), ++written;
    const std::pair<PlyEncoding, const char*> encodings[] = {
        {PlyEncoding::Ascii, "ascii"}, {PlyEncoding::BinaryLittleEndian, "le"}, {PlyEncoding::BinaryBigEndian, "be"}};
    for (const auto& [enc, tag] : encodings) {
      wo.ply_encoding = enc;
      if (io_detail::format_ply(mesh, wo, out, error)) save(root / "ply", name + "-" + tag + ".ply", out), ++written;
    }
#ifdef QUADLOD_FUZZ_HAS_SCENE
    // The assimp targets' seeds: the same meshes through quadlod's own scene writers.
    for (const auto& [target, ext] : {std::pair{"assimp", ".glb"}, {"assimp_dae", ".dae"}, {"assimp_fbx", ".fbx"}}) {
      const fs::path file = root / (std::string("scene-tmp") + ext);
      fs::create_directories(root);
      if (write_scene(scene_from_mesh(mesh, name), file).ok()) {
        std::ifstream in(file, std::ios::binary);
        const std::string bytes(std::istreambuf_iterator<char>(in), {});
        save(root / target, name + ext, bytes);
        ++written;
        if (std::string(target) == "assimp_fbx") {
          // The binary FBX reader's own target, and a copy under another Creator so that the
          // assimp target also maps corners onto control points (fbx_control_points.h skips
          // files assimp wrote).
          save(root / "fbx_binary", name + ext, bytes);
          std::string other = bytes;
          const std::string creator = "Open Asset Import Library";
          for (std::size_t at = other.find(creator); at != std::string::npos; at = other.find(creator, at))
            other.replace(at, creator.size(), "Some Other Exporter Tool!");
          save(root / target, name + "-other-creator" + ext, other);
          written += 2;
        }
      }
      fs::remove(file);
    }
#endif
    for (const auto& [ratio, flags] : {std::pair{0.5, 0}, {0.25, 1}, {0.75, 2}, {0.1, 16}})
      if (fuzz::encode_pipeline_case(mesh, ratio, static_cast<std::uint8_t>(flags), out))
        save(root / "pipeline", name + "-" + std::to_string(int(ratio * 100)) + "-" + std::to_string(flags), out), ++written;
  }
  std::printf("quadlod_fuzz_seeds: %d seeds in %s\n", written, root.c_str());
  return 0;
}
