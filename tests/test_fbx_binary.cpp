// The binary FBX reader (src/io/fbx_binary.h) and the FBX control points behind assimp's meshes
// (src/io/fbx_control_points.h): hand-made FBX bytes (tests/fbx_test_util.h), refusals of bad
// bytes, parts whose boundaries coincide staying apart through read_scene, and a Blender export.
#include "cli_runner.h"
#include "fbx_test_util.h"
#include "scene_test_util.h"

#include "io/fbx_binary.h"
#include "io/fbx_control_points.h"
#include "quadlod/io.h"
#include "quadlod/scene.h"

#include <gtest/gtest.h>

using namespace quadlod;
using namespace quadlod::fbx_test;
using namespace quadlod::testing;
namespace fs = std::filesystem;

namespace {

Rec sample_tree() {
  return {"Top", {Y(-7), C(true), I(-123456), F(1.5f), D(0.1), L(-(std::int64_t{1} << 40)), S("name"), S(std::string("raw\0x", 5), 'R')},
          {{"Reals", {array('d', std::vector<double>{0.1, -2.5, 1e300}, true), array('f', std::vector<float>{0.25f, 3.0f})}, {}},
           {"Ints", {array('i', std::vector<std::int32_t>{0, -1, 7}, true), array('l', std::vector<std::int64_t>{std::int64_t{1} << 50}),
                     array('b', std::vector<std::uint8_t>{1, 0, 1})},
            {{"Leaf", {}, {}}}}}};
}

// The one mesh of an FBX read back as `polygons` (control-point vertices, file polygon order).
const PolyMesh& expect_control_point_mesh(const SceneReadResult& r,
                                          const std::vector<std::vector<std::int32_t>>& polygons) {
  EXPECT_EQ(r.scene.meshes.size(), 1u);
  EXPECT_EQ(r.scene.fbx_control_point_meshes, 1u) << r.scene.fbx_note;
  const PolyMesh& m = r.scene.meshes.at(0).mesh;
  EXPECT_EQ(m.num_faces(), Index(polygons.size()));
  EXPECT_EQ(m.num_vertices(), 8u);
  for (Index f = 0; f < std::min(m.num_faces(), Index(polygons.size())); ++f) {
    const std::vector<Index> got(m.face_vertices(f).begin(), m.face_vertices(f).end());
    EXPECT_EQ(got, std::vector<Index>(polygons[f].begin(), polygons[f].end())) << "face " << f;
  }
  return m;
}

}  // namespace

TEST(FbxBinary, ReadsEveryPropertyTypeInBothVersions) {
  for (std::uint32_t version : {7400u, 7500u}) {
    const std::string bytes = file({sample_tree(), {"Second", {I(2)}, {}}}, version);
    ASSERT_TRUE(fbx::is_binary_fbx(bytes));
    const fbx::ParseResult r = fbx::parse_binary_fbx(bytes);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.document.version, version);
    ASSERT_EQ(r.document.records.size(), 2u);
    const fbx::Record& top = r.document.records[0];
    EXPECT_EQ(top.name, "Top");
    ASSERT_EQ(top.properties.size(), 8u);
    EXPECT_EQ(top.properties[0].integers, std::vector<std::int64_t>{-7});
    EXPECT_EQ(top.properties[1].integers, std::vector<std::int64_t>{1});
    EXPECT_EQ(top.properties[2].integers, std::vector<std::int64_t>{-123456});
    EXPECT_EQ(top.properties[3].reals, std::vector<double>{1.5});
    EXPECT_EQ(top.properties[4].reals, std::vector<double>{0.1});  // float64 exactly
    EXPECT_EQ(top.properties[5].integers, std::vector<std::int64_t>{-(std::int64_t{1} << 40)});
    EXPECT_EQ(top.string_property(6), "name");
    EXPECT_EQ(top.string_property(7), std::string("raw\0x", 5));
    ASSERT_EQ(top.children.size(), 2u);
    EXPECT_EQ(top.find("Reals")->properties[0].reals, (std::vector<double>{0.1, -2.5, 1e300}));
    EXPECT_EQ(top.find("Reals")->properties[1].reals, (std::vector<double>{0.25, 3.0}));
    const fbx::Record& ints = *top.find("Ints");
    EXPECT_EQ(ints.properties[0].integers, (std::vector<std::int64_t>{0, -1, 7}));
    EXPECT_EQ(ints.properties[1].integers, (std::vector<std::int64_t>{std::int64_t{1} << 50}));
    EXPECT_EQ(ints.properties[2].integers, (std::vector<std::int64_t>{1, 0, 1}));
    ASSERT_EQ(ints.children.size(), 1u);
    EXPECT_EQ(ints.children[0].name, "Leaf");
    EXPECT_EQ(r.document.records[1].properties[0].integers, std::vector<std::int64_t>{2});
  }
}

TEST(FbxBinary, RefusesBadBytesWithOneLineNamingTheOffset) {
  const std::string good = file({sample_tree()});
  const auto refused = [](const std::string& bytes, const std::string& words) {
    const fbx::ParseResult r = fbx::parse_binary_fbx(bytes);
    EXPECT_FALSE(r.ok()) << words;
    EXPECT_NE(r.error.find("FBX byte"), std::string::npos) << r.error;
    EXPECT_NE(r.error.find(words), std::string::npos) << r.error;
    EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
    EXPECT_TRUE(r.document.records.empty());
  };
  refused("Kaydara FBX Ascii  " + std::string(20, '\0'), "not a binary FBX");
  // The first record's end offset past the file.
  std::string past = good;
  const std::uint32_t huge = 1u << 30;
  std::memcpy(past.data() + 27, &huge, 4);
  refused(past, "outside its enclosing record");
  // An unknown property type code: the first property of "Top" is at 27 + 13 + 3.
  std::string code = good;
  code[27 + 13 + 3] = 'Z';
  refused(code, "unknown property type 0x5a");
  // A raw array whose stored length disagrees with its count.
  refused(file({{"A", {array('i', std::vector<std::int32_t>{1, 2})}, {}}}).replace(27 + 13 + 1 + 1 + 8, 4, std::string("\x07\0\0\0", 4)),
          "stores 7 bytes, not 8");
  // zlib data that is not zlib, and a count zlib cannot reach from so few bytes.
  std::string corrupt = file({{"A", {array('d', std::vector<double>(64, 1.0), true)}, {}}});
  corrupt[27 + 13 + 1 + 1 + 12 + 2] ^= 0x55;
  refused(corrupt, "zlib data");
  std::string lie = file({{"A", {array('d', std::vector<double>(4, 1.0), true)}, {}}});
  const std::uint32_t billion = 1000000000u;
  std::memcpy(lie.data() + 27 + 13 + 1 + 1, &billion, 4);
  refused(lie, "cannot inflate");
  // Nesting deeper than ParseParams::max_depth.
  Rec deep{"N", {}, {}};
  for (int i = 0; i < 40; ++i) deep = Rec{"N", {}, {deep}};
  refused(file({deep}), "nested deeper than 32");
  // Every truncation of a good file either parses (cut between top-level records) or is refused
  // with one line: never a crash, never a read past the end (the ASan tree checks the latter).
  for (std::size_t n = 0; n < good.size(); ++n) {
    const fbx::ParseResult r = fbx::parse_binary_fbx(std::string_view(good.data(), n));
    if (!r.ok()) {
      EXPECT_EQ(r.error.find('\n'), std::string::npos);
    }
    if (n > 27 && n < good.size() - 13) {
      EXPECT_FALSE(r.ok()) << "cut at " << n;
    }
  }
}

TEST(FbxControlPoints, ReadsGeometryAndRefusesBadPolygons) {
  const std::vector<double> cps{0, 0, 0, 1, 0, 0, 1, 0.1, 0, 0, 1, 0};
  const fbx::GeometryRead g = fbx::read_mesh_geometries(mesh_file(cps, {{0, 1, 2}, {0, 2, 3}}, {1, 0}));
  ASSERT_TRUE(g.ok()) << g.error;
  EXPECT_EQ(g.creator, "quadlod test");
  EXPECT_TRUE(fbx::control_points_are_vertices(g));
  ASSERT_EQ(g.geometries.size(), 1u);
  const fbx::MeshGeometry& m = g.geometries[0];
  EXPECT_EQ(m.name, "part");
  ASSERT_EQ(m.control_points.size(), 4u);
  EXPECT_EQ(m.control_points[2], Vec3(1, 0.1, 0));
  EXPECT_EQ(m.polygon_offsets, (std::vector<Index>{0, 3, 6}));
  EXPECT_EQ(m.polygon_corners, (std::vector<Index>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(m.polygon_material, (std::vector<std::int64_t>{1, 0}));

  const auto refused = [&](const std::string& bytes, const std::string& words) {
    const fbx::GeometryRead r = fbx::read_mesh_geometries(bytes);
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.error.find(words), std::string::npos) << r.error;
    EXPECT_TRUE(r.geometries.empty());
  };
  refused(mesh_file(cps, {{0, 1, 4}}), "names control point 4 of 4");
  refused(mesh_file({0, 0, 0, 1}, {{0, 0, 0}}), "not a multiple of 3");
  refused(mesh_file(cps, {{0, 1, 2}}, {0, 1}), "Materials holds 2 entries for 1 polygons");
  // A last polygon without its negative index: the writer always closes, so build it by hand.
  std::string open = mesh_file(cps, {{0, 1, 2}});
  const std::int32_t closed = -3, unclosed = 2;
  const std::size_t at = open.rfind(std::string(reinterpret_cast<const char*>(&closed), 4));
  ASSERT_NE(at, std::string::npos);
  std::memcpy(open.data() + at, &unclosed, 4);
  refused(open, "the last polygon is not closed");
  EXPECT_FALSE(fbx::control_points_are_vertices(fbx::read_mesh_geometries(
      mesh_file(cps, {{0, 1, 2}}, {}, "Open Asset Import Library (Assimp) 5.2.5"))));
}

namespace {

/// Two unit quads side by side; the right one's left edge lies on the left one's right edge.
/// `shared`: the two share those control points (one surface) — else the right quad has its own
/// (two parts whose boundaries coincide, as an OBJ of two objects holds them). y = 0.1 for the
/// top row, which float32 cannot hold.
std::string two_quads(bool shared, const std::string& creator = "quadlod test") {
  std::vector<double> cps{0, 0, 0, 1, 0, 0, 1, 0.1, 0, 0, 0.1, 0, 2, 0, 0, 2, 0.1, 0};
  std::vector<std::vector<std::int32_t>> polygons{{0, 1, 2, 3}, {1, 4, 5, 2}};
  if (!shared) {
    cps.insert(cps.end(), {1, 0, 0, 1, 0.1, 0});  // 6, 7: copies of 1, 2
    polygons[1] = {6, 4, 5, 7};
  }
  return mesh_file(cps, polygons, {}, creator);
}

SceneReadResult read_fbx(const std::string& bytes) { return read_scene_from_memory(bytes.data(), bytes.size(), "fbx", "t.fbx"); }

}  // namespace

TEST(FbxControlPoints, PartsWhoseBoundariesCoincideStayTwoParts) {
  const SceneReadResult apart = read_fbx(two_quads(false));
  ASSERT_TRUE(apart.ok()) << apart.error;
  ASSERT_EQ(apart.scene.meshes.size(), 1u);
  EXPECT_EQ(apart.scene.fbx_control_point_meshes, 1u) << apart.scene.fbx_note;
  EXPECT_EQ(apart.scene.fbx_note, "");
  const PolyMesh& m = apart.scene.meshes[0].mesh;
  EXPECT_EQ(m.num_faces(), 2u);
  EXPECT_EQ(m.num_vertices(), 8u);  // two parts, as the file has them
  // Vertices in control-point order with the file's float64 positions (0.1, not float(0.1)).
  EXPECT_EQ(m.positions[2], Vec3(1, 0.1, 0));
  EXPECT_EQ(m.positions[7], Vec3(1, 0.1, 0));
  EXPECT_EQ(std::vector<Index>(m.face_vertices(0).begin(), m.face_vertices(0).end()), (std::vector<Index>{0, 1, 2, 3}));
  EXPECT_EQ(std::vector<Index>(m.face_vertices(1).begin(), m.face_vertices(1).end()), (std::vector<Index>{6, 4, 5, 7}));

  SceneReadOptions glue;
  glue.fbx_control_points = false;
  const std::string bytes = two_quads(false);
  const SceneReadResult off = read_scene_from_memory(bytes.data(), bytes.size(), "fbx", "t.fbx", glue);
  ASSERT_TRUE(off.ok()) << off.error;
  EXPECT_EQ(off.scene.fbx_control_point_meshes, 0u);
  EXPECT_EQ(off.scene.meshes[0].mesh.num_vertices(), 6u);  // glued: the two parts become one

  const SceneReadResult one = read_fbx(two_quads(true));
  ASSERT_TRUE(one.ok()) << one.error;
  EXPECT_EQ(one.scene.meshes[0].mesh.num_vertices(), 6u);

  // A file written by assimp's exporter: its control points are not the vertices, the corners
  // are glued along edges as before — which joins the two parts.
  const SceneReadResult glued = read_fbx(two_quads(false, "Open Asset Import Library (Assimp) 5.2.5"));
  ASSERT_TRUE(glued.ok()) << glued.error;
  EXPECT_EQ(glued.scene.fbx_control_point_meshes, 0u);
  EXPECT_NE(glued.scene.fbx_note.find("written by assimp"), std::string::npos) << glued.scene.fbx_note;
  EXPECT_EQ(glued.scene.meshes[0].mesh.num_vertices(), 6u);
  EXPECT_EQ(glued.scene.meshes[0].mesh.positions[2].y(), static_cast<double>(0.1f));
}

TEST(FbxControlPoints, MaterialSplitMeshesComeBackInFileOrder) {
  // Three quads in a strip, material slots 1, 0, 1: assimp makes one aiMesh per material (slot
  // 1's first); the mesh read back has the file's polygon order and control-point vertices.
  const std::vector<double> cps{0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0, 3, 1, 0};
  const std::vector<std::vector<std::int32_t>> polygons{{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}};
  const SceneReadResult r = read_fbx(mesh_file(cps, polygons, {1, 0, 1}));
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  const PolyMesh& m = expect_control_point_mesh(r, polygons);
  ASSERT_EQ(m.num_faces(), 3u);
  ASSERT_EQ(m.face_material.size(), 3u);
  EXPECT_EQ(m.material_names[m.face_material[0]], m.material_names[m.face_material[2]]);
  EXPECT_NE(m.face_material[0], m.face_material[1]);
  EXPECT_EQ(m.material_names[m.face_material[1]], "mata");
  EXPECT_EQ(m.material_names[m.face_material[0]], "matb");
}

TEST(FbxControlPoints, BadFbxBytesThatAssimpReadsFallBackToGluing) {
  // A control point index that is out of range for our reader: assimp refuses such a file
  // itself, or our reader refuses it and the mesh is glued; either way an answer, no crash.
  std::string bytes = two_quads(false);
  const std::int32_t seven = -8, big = -1000;  // the last corner of the right quad
  const std::size_t at = bytes.rfind(std::string(reinterpret_cast<const char*>(&seven), 4));
  ASSERT_NE(at, std::string::npos);
  std::memcpy(bytes.data() + at, &big, 4);
  const SceneReadResult r = read_fbx(bytes);
  if (r.ok()) {
    EXPECT_EQ(r.scene.fbx_control_point_meshes, 0u);
    EXPECT_NE(r.scene.fbx_note.find("names control point 999"), std::string::npos) << r.scene.fbx_note;
  } else {
    EXPECT_EQ(r.error.find('\n'), std::string::npos);
  }
}

TEST(FbxControlPoints, BlenderExportOfTwoTouchingPartsReadsAsTheObj) {
  // The bar's path (bench/scene_bar.py): Blender imports an OBJ and exports FBX. Two quads whose
  // boundaries coincide, as separate parts: read back from the FBX, the same 8 vertices in the
  // same order and the same faces as the OBJ, at the OBJ's float32 positions (Blender stores
  // float32).
  if (!scene_test::blender_available()) GTEST_SKIP() << "blender not on PATH";
  const fs::path dir = scratch_dir("fbx-blender-two-parts");
  write_text(dir / "two.obj",
             "v 0 0 0\nv 1 0 0\nv 1 0.1 0\nv 0 0.1 0\nv 1 0 0\nv 2 0 0\nv 2 0.1 0\nv 1 0.1 0\n"
             "f 1 2 3 4\nf 5 6 7 8\n");
  write_text(dir / "convert.py",
             "import bpy, sys\n"
             "a = sys.argv[sys.argv.index('--') + 1:]\n"
             "bpy.ops.wm.read_factory_settings(use_empty=True)\n"
             "bpy.ops.wm.obj_import(filepath=a[0])\n"
             "bpy.ops.export_scene.fbx(filepath=a[1])\n");
  const std::string cmd = "blender -b --factory-startup --python '" + (dir / "convert.py").string() + "' -- '" +
                          (dir / "two.obj").string() + "' '" + (dir / "two.fbx").string() + "' > '" +
                          (dir / "log").string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(dir / "log");
  const SceneReadResult r = read_scene(dir / "two.fbx");
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  EXPECT_EQ(r.scene.fbx_control_point_meshes, 1u) << r.scene.fbx_note;
  const PolyMesh& m = r.scene.meshes[0].mesh;
  const ReadResult obj = read_mesh(dir / "two.obj");
  ASSERT_TRUE(obj.ok()) << obj.error;
  ASSERT_EQ(m.num_vertices(), obj.mesh.num_vertices());
  ASSERT_EQ(m.num_faces(), obj.mesh.num_faces());
  for (Index v = 0; v < m.num_vertices(); ++v)
    EXPECT_EQ(m.positions[v], obj.mesh.positions[v].cast<float>().cast<double>()) << "vertex " << v;
  EXPECT_EQ(m.corner_vertex, obj.mesh.corner_vertex);
  fs::remove_all(dir);
}

TEST(FbxControlPoints, TrianglesAndQuadsOfTwoMaterialsComeBackInFileOrder) {
  // assimp's SortByPType splits each material's aiMesh into its triangles and its quads: four
  // aiMeshes here (slot 1 quads, slot 1 triangles, slot 0 quads, slot 0 triangles), put back
  // into the file's order.
  const std::vector<double> cps{0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0, 3, 1, 0};
  const std::vector<std::vector<std::int32_t>> polygons{{0, 1, 5}, {0, 5, 4}, {1, 2, 6, 5}, {2, 3, 7}, {2, 7, 6}};
  const SceneReadResult r = read_fbx(mesh_file(cps, polygons, {1, 0, 1, 0, 1}));
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.scene.meshes.size(), 1u);
  const PolyMesh& m = expect_control_point_mesh(r, polygons);
  ASSERT_EQ(m.num_faces(), 5u);
  for (Index f = 0; f < 5; ++f)
    EXPECT_EQ(m.material_names[m.face_material[f]], f % 2 ? "mata" : "matb") << "face " << f;
}
