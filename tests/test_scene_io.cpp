// Scenes through assimp (issue 21): write → read round trips of .glb / .fbx / .dae (counts,
// materials, UV ranges, node names, instances), reading from memory, assimp errors, an empty
// scene, a camera-only scene, the FBX repair, and Blender reading our FBX with its quads.
#include "cli_runner.h"
#include "scene_test_util.h"

#include "quadlod/lod.h"
#include "quadlod/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>

using namespace quadlod;
using namespace quadlod::scene_test;
using namespace quadlod::testing;
namespace fs = std::filesystem;

namespace {

class SceneRoundTrip : public ScratchDirTest, public ::testing::WithParamInterface<std::string> {};

std::set<std::string> node_names(const Scene& scene) {
  std::set<std::string> names;
  for (const SceneNode& n : scene.nodes) names.insert(n.name);
  return names;
}

}  // namespace

TEST_P(SceneRoundTrip, KeepsCountsMaterialsUvsAndNodes) {
  const std::string ext = GetParam();
  const bool triangulated = ext == ".glb";
  const Scene scene = make_test_scene();
  const fs::path file = dir / ("scene" + ext);
  const WriteResult w = write_scene(scene, file);
  ASSERT_TRUE(w.ok()) << w.error;
  const SceneReadResult r = read_scene(file);
  ASSERT_TRUE(r.ok()) << r.error;
  const Scene& back = r.scene;

  const std::set<std::string> names = node_names(back);
  for (const char* n : {"grid_a", "grid_b", "torus_c"}) EXPECT_TRUE(names.count(n)) << ext << ": node " << n;
  const SceneMesh* grid_a = mesh_of_node(back, "grid_a");
  const SceneMesh* grid_b = mesh_of_node(back, "grid_b");
  const SceneMesh* torus = mesh_of_node(back, "torus_c");
  ASSERT_TRUE(grid_a && grid_b && torus) << ext;
  // The instance comes back as one mesh referenced twice.
  EXPECT_EQ(grid_a, grid_b) << ext;
  EXPECT_EQ(back.meshes.size(), 2u) << ext;

  // Counts: polygons stay quads (FBX, Collada) or become two triangles each (glTF); welding
  // restores the shared vertices.
  const FaceTally g = tally(grid_a->mesh), t = tally(torus->mesh);
  if (triangulated) {
    EXPECT_EQ(g.tris, 96u);
    EXPECT_EQ(t.tris, 192u);
  } else {
    EXPECT_EQ(g.quads, 48u) << ext;
    EXPECT_EQ(t.quads, 96u) << ext;
  }
  EXPECT_EQ(grid_a->mesh.num_vertices(), 9u * 7u) << ext;
  EXPECT_EQ(torus->mesh.num_vertices(), 12u * 8u) << ext;
  EXPECT_EQ(tri_equivalent_count(grid_a->mesh), 96u);

  // Materials by name, face counts per material.
  const auto by_material = faces_by_material(grid_a->mesh);
  const std::uint64_t per_quad = triangulated ? 2 : 1;
  EXPECT_EQ(by_material.count("red") ? by_material.at("red") : 0, 24u * per_quad) << ext;
  EXPECT_EQ(by_material.count("blue") ? by_material.at("blue") : 0, 24u * per_quad) << ext;
  std::set<std::string> materials;
  for (const SceneMaterial& m : back.materials) materials.insert(m.name);
  EXPECT_TRUE(materials.count("red") && materials.count("blue")) << ext;
  for (const SceneMaterial& m : back.materials)
    if (m.name == "red") {
      EXPECT_NEAR(m.base_color[0], 0.8, 1e-5) << ext;
    }

  // Both UV sets with their ranges.
  ASSERT_EQ(grid_a->mesh.uv_sets.size(), 2u) << ext;
  const auto [lo0, hi0] = uv_range(grid_a->mesh, 0);
  const auto [lo1, hi1] = uv_range(grid_a->mesh, 1);
  EXPECT_NEAR(lo0.x(), 0.0, 1e-6);
  EXPECT_NEAR(hi0.x(), 1.0, 1e-6);
  EXPECT_NEAR(lo0.y(), 0.0, 1e-6);
  EXPECT_NEAR(hi0.y(), 1.0, 1e-6);
  EXPECT_NEAR(lo1.x(), 0.25, 1e-6) << ext;
  EXPECT_NEAR(hi1.x(), 0.75, 1e-6) << ext;
  EXPECT_NEAR(lo1.y(), 0.5, 1e-6) << ext;
  EXPECT_NEAR(hi1.y(), 1.0, 1e-6) << ext;
  EXPECT_TRUE(grid_a->mesh.has_normals()) << ext;
  // Vertex colours follow their vertices.
  ASSERT_EQ(grid_a->mesh.vertex_colors.size(), grid_a->mesh.num_vertices()) << ext;
  for (Index v = 0; v < grid_a->mesh.num_vertices(); ++v) {
    const Vec3& p = grid_a->mesh.positions[v];
    EXPECT_TRUE(grid_a->mesh.vertex_colors[v].isApprox(Vec3(p.x() / 2.0, 0.25, p.y() / 1.5), 1e-5)) << ext << " vertex " << v;
  }

  // World placement: the flattened scene spans the instances and the scaled torus.
  const BoundingBox box = bounding_box(flatten_scene(back));
  EXPECT_NEAR(box.max.z(), 2.0, 1e-4) << ext;  // grid_b at z = 2
  EXPECT_NEAR(box.max.x(), std::max(3.0, 2.0 * 1.35), 1e-4) << ext;
}

INSTANTIATE_TEST_SUITE_P(Formats, SceneRoundTrip, ::testing::Values(".glb", ".fbx", ".dae"),
                         [](const auto& info) { return info.param.substr(1); });

TEST_P(SceneRoundTrip, SimplifyCliKeepsTheSceneTogether) {
  const std::string ext = GetParam();
  const fs::path in = dir / ("scene" + ext), out = dir / ("reduced" + ext);
  ASSERT_TRUE(write_scene(make_test_scene(), in).ok());
  // Symmetry off: the file's vertex order differs from memory's, and on this 48-quad grid one tie
  // taken differently moves a pair of mirrored collapses (13 points of quad fraction, issue 34).
  const CliRun run = run_cli("-q simplify '" + in.string() + "' -o '" + out.string() + "' --ratio 0.5 --symmetry off", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // A .glb holds triangles only, so its meshes have their pairs joined into quads first (quad
  // recovery, docs/scenes.md) and the summary says so; FBX and Collada keep their quads.
  if (ext == ".glb")
    EXPECT_NE(run.out.find("quads: all-triangle meshes had "), std::string::npos) << run.out;
  else
    EXPECT_EQ(run.out.find("quads:"), std::string::npos) << run.out;
  const SceneReadResult r = read_scene(out);
  ASSERT_TRUE(r.ok()) << r.error;
  const std::set<std::string> names = node_names(r.scene);
  for (const char* n : {"grid_a", "grid_b", "torus_c"}) EXPECT_TRUE(names.count(n)) << ext << ": node " << n;
  EXPECT_EQ(r.scene.meshes.size(), 2u);
  // Reduced towards half the triangle-equivalents. Polygons: within 10 % (the pipeline's band
  // plus small-mesh slack). glTF's triangles (every quad split in two, its diagonal a hard
  // choice for the chord analysis) reduce less on meshes this small.
  const double te = double(r.scene.tri_equivalent_count());
  if (ext == ".glb")
    EXPECT_LT(te, 0.9 * (96 + 192));
  else
    EXPECT_NEAR(te, 0.5 * (96 + 192), 0.1 * (96 + 192)) << ext;
  const SceneMesh* grid = mesh_of_node(r.scene, "grid_a");
  ASSERT_TRUE(grid);
  const auto by_material = faces_by_material(grid->mesh);
  EXPECT_GT(by_material.count("red") ? by_material.at("red") : 0, 0u);
  EXPECT_GT(by_material.count("blue") ? by_material.at("blue") : 0, 0u);
  ASSERT_EQ(grid->mesh.uv_sets.size(), 2u);
  const auto [lo1, hi1] = uv_range(grid->mesh, 1);
  EXPECT_GE(lo1.x(), 0.25 - 1e-6);
  EXPECT_LE(hi1.x(), 0.75 + 1e-6);
  if (ext != ".glb") {
    // Quads kept: the grid's quad fraction is the one the same reduction gives in memory
    // (the file's vertex order may differ, so within 5 points rather than exactly).
    SceneSimplifyParams params;
    params.options.ratio = 0.5;
    params.options.symmetry = SimplifyOptions::Symmetry::Off;
    const SceneSimplifyResult direct = simplify_scene(make_test_scene(), params);
    ASSERT_TRUE(direct.ok()) << direct.error;
    const FaceTally t = tally(grid->mesh), ref = tally(direct.scene.meshes[0].mesh);
    EXPECT_NEAR(double(t.quads) / double(t.faces()), double(ref.quads) / double(ref.faces()), 0.05) << ext;
    EXPECT_GT(t.quads, 0u);
  }
}

TEST(SceneIo, ReadFromMemoryMatchesTheFile) {
  const fs::path dir = scratch_dir("scene-memory");
  const fs::path file = dir / "scene.glb";
  ASSERT_TRUE(write_scene(make_test_scene(), file).ok());
  const std::string bytes = slurp(file);
  const SceneReadResult a = read_scene(file);
  const SceneReadResult b = read_scene_from_memory(bytes.data(), bytes.size(), "glb", "buffer");
  ASSERT_TRUE(a.ok() && b.ok()) << a.error << b.error;
  ASSERT_EQ(a.scene.meshes.size(), b.scene.meshes.size());
  for (std::size_t m = 0; m < a.scene.meshes.size(); ++m) {
    EXPECT_EQ(a.scene.meshes[m].mesh.corner_vertex, b.scene.meshes[m].mesh.corner_vertex);
    EXPECT_EQ(a.scene.meshes[m].mesh.positions, b.scene.meshes[m].mesh.positions);
  }
  const SceneReadResult bad = read_scene_from_memory("garbage", 7, "fbx", "buffer");
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.error.find("buffer"), std::string::npos) << bad.error;
  fs::remove_all(dir);
}

TEST(SceneIo, NativeFormatsAreOneMeshScenes) {
  const fs::path dir = scratch_dir("scene-native");
  PolyMesh grid = make_grid(3, 2);
  ASSERT_TRUE(write_mesh(grid, dir / "g.obj").ok());
  const SceneReadResult r = read_scene(dir / "g.obj");
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  EXPECT_EQ(r.scene.nodes.at(0).name, "g");
  EXPECT_EQ(r.scene.meshes[0].mesh.corner_vertex, grid.corner_vertex);
  // Written back as OBJ: the mesh unchanged (no flattening of a one-mesh identity scene).
  ASSERT_TRUE(write_scene(r.scene, dir / "h.obj").ok());
  EXPECT_EQ(slurp(dir / "g.obj"), slurp(dir / "h.obj"));
  fs::remove_all(dir);
}

TEST(SceneIo, FlattenAppliesWorldTransformsPerInstance) {
  const Scene scene = make_test_scene();
  const PolyMesh flat = flatten_scene(scene);
  // Two grid instances + the torus.
  EXPECT_EQ(flat.num_faces(), 48u * 2 + 96u);
  ASSERT_EQ(flat.object_names.size(), 3u);
  EXPECT_EQ(flat.object_names[0], "grid_a");
  EXPECT_EQ(flat.object_names[1], "grid_b");
  // grid_b = translate(1,0,0) · translate(0,0,2): its first vertex (0,0,0) lands at (1,0,2).
  EXPECT_TRUE(flat.positions[63].isApprox(Vec3(1, 0, 2)));
  EXPECT_TRUE(flat.positions[0].isApprox(Vec3(1, 0, 0)));
}

// --- errors and empty scenes ------------------------------------------------------------------

class SceneErrors : public ScratchDirTest {};

TEST_F(SceneErrors, AssimpFailureIsExitCode2NamingTheFile) {
  const fs::path bad = dir / "broken.fbx";
  write_text(bad, "Kaydara FBX Binary  \0\x1a\0 this is not an FBX file at all");
  const SceneReadResult r = read_scene(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error.find("broken.fbx"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("assimp"), std::string::npos) << r.error;
  const CliRun run = run_cli("-q simplify '" + bad.string() + "' -o '" + (dir / "o.glb").string() + "' --ratio 0.5", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("broken.fbx"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir / "o.glb"));
  const CliRun missing = run_cli("-q lod '" + (dir / "missing.dae").string() + "' -o '" + (dir / "lods").string() + "'", dir);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("missing.dae"), std::string::npos) << missing.err;
}

TEST_F(SceneErrors, EmptySceneIsReadAndRefusedForReduction) {
  const fs::path empty = dir / "empty.gltf";
  write_text(empty, R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                       "nodes": [{"name": "nothing"}]})");
  // Reading succeeds (an empty scene is a scene); reducing it is refused.
  const SceneReadResult r = read_scene(empty);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_TRUE(r.scene.meshes.empty());
  EXPECT_EQ(r.scene.nodes.size(), 1u);
  const CliRun run = run_cli("-q simplify '" + empty.string() + "' -o '" + (dir / "o.glb").string() + "' --ratio 0.5", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("empty.gltf"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir / "o.glb"));
}

TEST_F(SceneErrors, CameraOnlySceneHasNoMeshToReduce) {
  const fs::path camera = dir / "camera.gltf";
  write_text(camera, R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                        "nodes": [{"name": "cam", "camera": 0, "translation": [0, 0, 5]}],
                        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100}}]})");
  const SceneReadResult r = read_scene(camera);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_TRUE(r.scene.meshes.empty());
  EXPECT_EQ(r.scene.cameras, 1u);
  for (const std::string& cmd : {"simplify '" + camera.string() + "' -o '" + (dir / "o.fbx").string() + "' --ratio 0.5",
                                 "lod '" + camera.string() + "' -o '" + (dir / "lods").string() + "'"}) {
    const CliRun run = run_cli("-q " + cmd, dir);
    EXPECT_EQ(run.exit_code, 2) << cmd;
    EXPECT_NE(run.err.find("camera.gltf"), std::string::npos) << run.err;
  }
  EXPECT_FALSE(fs::exists(dir / "o.fbx"));
}

TEST_F(SceneErrors, UnknownOutputExtensionIsRefused) {
  const WriteResult w = write_scene(make_test_scene(), dir / "scene.xyz");
  EXPECT_FALSE(w.ok());
  EXPECT_NE(w.error.find("scene.xyz"), std::string::npos);
}

// --- FBX ---------------------------------------------------------------------------------------

TEST(SceneFbx, WrittenFileHasItsNullRecords) {
  // Every record with nested records ends with 25 zero bytes (FBX 7.5): assimp 5.2's writer
  // leaves them out, write_scene puts them back. Walk the records and check.
  const fs::path dir = scratch_dir("scene-fbx-records");
  ASSERT_TRUE(write_scene(make_test_scene(), dir / "s.fbx").ok());
  const std::string d = slurp(dir / "s.fbx");
  ASSERT_GT(d.size(), 27u);
  const auto u64 = [&](std::size_t p) {
    std::uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(d[p + i]);
    return v;
  };
  std::size_t nested = 0;
  std::function<void(std::size_t, std::size_t)> walk = [&](std::size_t pos, std::size_t limit) {
    while (pos < limit) {
      const std::uint64_t end = u64(pos);
      if (end == 0) return;
      ASSERT_LE(end, limit);
      const std::size_t props_end = pos + 25 + static_cast<unsigned char>(d[pos + 24]) + u64(pos + 16);
      if (props_end < end) {
        ++nested;
        ASSERT_GE(end - props_end, 25u);
        EXPECT_EQ(d.substr(end - 25, 25), std::string(25, '\0')) << "record at " << pos;
        walk(props_end, end - 25);
      }
      pos = end;
    }
  };
  walk(27, d.size());
  EXPECT_GT(nested, 10u);
  fs::remove_all(dir);
}

TEST(SceneFbx, BlenderImportsOurFbxWithItsQuads) {
  if (!blender_available()) GTEST_SKIP() << "blender not on PATH";
  const fs::path dir = scratch_dir("scene-fbx-blender");
  ASSERT_TRUE(write_scene(make_test_scene(), dir / "s.fbx").ok());
  const fs::path script = dir / "count.py";
  write_text(script,
             "import bpy, sys\n"
             "bpy.ops.wm.read_factory_settings(use_empty=True)\n"
             "bpy.ops.import_scene.fbx(filepath=sys.argv[sys.argv.index('--') + 1])\n"
             "q = t = n = 0\n"
             "names = sorted(o.name for o in bpy.context.scene.objects)\n"
             "mats = sorted({m.name for o in bpy.context.scene.objects if o.type == 'MESH' for m in o.data.materials if m})\n"
             "for o in bpy.context.scene.objects:\n"
             "    if o.type != 'MESH': continue\n"
             "    for p in o.data.polygons:\n"
             "        k = len(p.vertices)\n"
             "        if k == 4: q += 1\n"
             "        elif k == 3: t += 1\n"
             "        else: n += 1\n"
             "print('QUADLOD_COUNTS', q, t, n, ','.join(names), ','.join(mats))\n");
  const std::string cmd = "blender -b --factory-startup --python '" + script.string() + "' -- '" +
                          (dir / "s.fbx").string() + "' > '" + (dir / "log").string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  const std::string log = slurp(dir / "log");
  const auto at = log.find("QUADLOD_COUNTS");
  ASSERT_NE(at, std::string::npos) << log;
  std::istringstream in(log.substr(at + 14));
  std::uint64_t q = 0, t = 0, n = 0;
  std::string names, materials;
  in >> q >> t >> n >> names >> materials;
  // Two grid instances (48 quads each) and the torus (96), all quads.
  EXPECT_EQ(q, 48u * 2 + 96u) << log.substr(at);
  EXPECT_EQ(t, 0u);
  EXPECT_EQ(n, 0u);
  for (const char* node : {"grid_a", "grid_b", "torus_c"}) EXPECT_NE(names.find(node), std::string::npos) << names;
  EXPECT_NE(materials.find("red"), std::string::npos) << materials;
  EXPECT_NE(materials.find("blue"), std::string::npos) << materials;
  fs::remove_all(dir);
}

// --- welding ------------------------------------------------------------------------------------

namespace {

/// Two quads sharing an edge; face 0's corners have normal +Z, face 1's +Z tilted by `degrees`
/// about Y. Written as Collada and read back: the corner normals of the shared vertices.
std::pair<Index, Index> shared_vertex_normals(double degrees, const SceneReadOptions& options) {
  PolyMesh mesh = make_grid(2, 1);
  const double a = degrees * 3.14159265358979323846 / 180.0;
  mesh.normals = {Vec3(0, 0, 1), Vec3(std::sin(a), 0, std::cos(a))};
  mesh.corner_normal.resize(mesh.num_corners());
  for (Index f = 0; f < 2; ++f)
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) mesh.corner_normal[c] = f;
  const fs::path dir = scratch_dir("scene-normal-weld");
  EXPECT_TRUE(write_scene(scene_from_mesh(mesh, "two"), dir / "two.dae").ok());
  const SceneReadResult r = read_scene(dir / "two.dae", options);
  fs::remove_all(dir);
  EXPECT_TRUE(r.ok()) << r.error;
  if (!r.ok() || r.scene.meshes.size() != 1) return {kInvalidIndex, kInvalidIndex};
  const PolyMesh& back = r.scene.meshes[0].mesh;
  EXPECT_EQ(back.num_vertices(), 6u);
  // Vertex 1 of the grid, (0.5, 0, 0), is in both faces: its corner in each.
  Index in_face[2] = {kInvalidIndex, kInvalidIndex};
  for (Index f = 0; f < back.num_faces(); ++f)
    for (Index c = back.face_begin(f); c < back.face_end(f); ++c)
      if (back.positions[back.corner_vertex[c]].isApprox(Vec3(0.5, 0, 0))) in_face[f] = back.corner_normal[c];
  return {in_face[0], in_face[1]};
}

}  // namespace

TEST(SceneWeld, NormalsWithinTheWeldAngleShareAnEntry) {
  const auto [a, b] = shared_vertex_normals(0.01, {});
  EXPECT_NE(a, kInvalidIndex);
  EXPECT_EQ(a, b);  // 0.01° < 0.1°: one normal, no seam
  const auto [c, d] = shared_vertex_normals(5.0, {});
  EXPECT_NE(c, d);  // a crease stays
  SceneReadOptions exact;
  exact.normal_weld_degrees = 0.0;
  const auto [e, f] = shared_vertex_normals(0.01, exact);
  EXPECT_NE(e, f);
}

TEST(SceneWeld, SurfacesOnTopOfEachOtherStayApart) {
  // Two copies of a 3×2 grid at the same place (a doubled hair card) in one mesh: welding by
  // position alone would make every face of the second copy a repeat of the first's.
  PolyMesh doubled = make_grid(3, 2);
  const PolyMesh copy = make_grid(3, 2);
  const Index base = doubled.num_vertices();
  for (const Vec3& p : copy.positions) doubled.add_vertex(p);
  for (Index f = 0; f < copy.num_faces(); ++f) {
    std::vector<Index> face;
    for (Index v : copy.face_vertices(f)) face.push_back(base + v);
    doubled.add_face(face);
  }
  const fs::path dir = scratch_dir("scene-doubled");
  ASSERT_TRUE(write_scene(scene_from_mesh(doubled, "doubled"), dir / "d.dae").ok());
  const SceneReadResult r = read_scene(dir / "d.dae");
  fs::remove_all(dir);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  const PolyMesh& back = r.scene.meshes[0].mesh;
  EXPECT_EQ(back.num_faces(), 12u);
  EXPECT_EQ(back.num_vertices(), 24u);
  std::set<std::vector<Index>> faces;
  for (Index f = 0; f < back.num_faces(); ++f) {
    std::vector<Index> key(back.face_vertices(f).begin(), back.face_vertices(f).end());
    std::sort(key.begin(), key.end());
    EXPECT_TRUE(faces.insert(key).second) << "face " << f << " repeats an earlier face";
  }
}
