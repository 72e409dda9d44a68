// Materials and UVs through `quadlod simplify` (issue 7): the output's `mtllib` still finds the
// input's MTL from another directory, and Blender (when installed) imports the output with the
// input's material slots, their MTL colours and one UV layer.
#include "cli_runner.h"
#include "quadlod/generators.h"
#include "quadlod/io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <set>
#include <sstream>

using namespace quadlod;
using namespace quadlod::testing;
namespace fs = std::filesystem;

namespace {

const char* const kMaterials[3] = {"paint_red", "chrome", "rubber_black"};
const char* const kMtl =
    "newmtl paint_red\nKd 0.8 0.1 0.1\n\n"
    "newmtl chrome\nKd 0.7 0.7 0.75\n\n"
    "newmtl rubber_black\nKd 0.05 0.05 0.05\n";

/// A UV-mapped open cylinder (24 × 12 quads, one UV seam) in three material bands of 4 rings,
/// written as DIR/cyl.obj with `mtllib cyl.mtl` and DIR/cyl.mtl.
fs::path write_banded_cylinder(const fs::path& dir) {
  const Index n = 24, m = 12;
  PolyMesh cyl = make_cylinder(n, m, 0.5, 2.0);
  cyl.material_names.assign(std::begin(kMaterials), std::end(kMaterials));
  cyl.face_material.resize(cyl.num_faces());
  for (Index f = 0; f < cyl.num_faces(); ++f) cyl.face_material[f] = (f / n) / 4;
  cyl.material_libraries = {"cyl.mtl"};
  fs::create_directories(dir);
  const fs::path obj = dir / "cyl.obj";
  EXPECT_TRUE(write_obj(cyl, obj).ok());
  write_text(dir / "cyl.mtl", kMtl);
  return obj;
}

/// Runs simplify at ratio 0.5 and returns the output mesh (read back).
PolyMesh simplify_to(const fs::path& input, const fs::path& output, const fs::path& scratch) {
  const CliRun run = run_cli("-q simplify '" + input.string() + "' -o '" + output.string() + "' --ratio 0.5", scratch);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  const ReadResult rr = read_obj(output);
  EXPECT_TRUE(rr.ok()) << rr.error;
  return rr.mesh;
}

bool blender_on_path() { return std::system("command -v blender > /dev/null 2>&1") == 0; }

class MaterialsRoundTrip : public ScratchDirTest {};

}  // namespace

TEST_F(MaterialsRoundTrip, MtllibResolvesFromTheOutputDirectory) {
  const fs::path input = write_banded_cylinder(dir / "in");
  // Same directory: the line is kept as written.
  EXPECT_EQ(simplify_to(input, dir / "in" / "lod.obj", dir).material_libraries,
            std::vector<std::string>{"cyl.mtl"});
  // Another directory: rewritten relative to it, and it names the input's MTL.
  fs::create_directories(dir / "out" / "deep");
  const PolyMesh out = simplify_to(input, dir / "out" / "deep" / "lod.obj", dir);
  ASSERT_EQ(out.material_libraries.size(), 1u);
  EXPECT_EQ(out.material_libraries[0], "../../in/cyl.mtl");
  EXPECT_TRUE(fs::equivalent(dir / "out" / "deep" / out.material_libraries[0], dir / "in" / "cyl.mtl"));
  // The materials themselves survive the reduction.
  EXPECT_EQ(out.material_names.size(), 3u);
  std::set<std::string> used;
  for (Index f = 0; f < out.num_faces(); ++f) used.insert(out.material_names[out.face_material[f]]);
  EXPECT_EQ(used, (std::set<std::string>{"paint_red", "chrome", "rubber_black"}));
  EXPECT_TRUE(out.has_uvs());
}

TEST_F(MaterialsRoundTrip, RebaseKeepsAbsoluteAndReportsMissingLibraries) {
  fs::create_directories(dir / "in");
  fs::create_directories(dir / "out");
  write_text(dir / "in" / "a.mtl", kMtl);
  write_text(dir / "in" / "b c.mtl", kMtl);
  PolyMesh m;
  m.material_libraries = {"a.mtl", "b c.mtl", "a.mtl missing.mtl", (dir / "in" / "a.mtl").string(), "gone.mtl"};
  const std::vector<std::string> warnings = rebase_material_libraries(m, dir / "in" / "x.obj", dir / "out" / "y.obj");
  EXPECT_EQ(m.material_libraries, (std::vector<std::string>{"../in/a.mtl", "../in/b c.mtl",
                                                            "../in/a.mtl missing.mtl",
                                                            (dir / "in" / "a.mtl").string(), "gone.mtl"}));
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("missing.mtl"), std::string::npos);
  EXPECT_NE(warnings[1].find("gone.mtl"), std::string::npos);
  // Same directory: nothing changes, nothing is reported.
  PolyMesh same;
  same.material_libraries = {"gone.mtl"};
  EXPECT_TRUE(rebase_material_libraries(same, dir / "in" / "x.obj", dir / "in" / "z.obj").empty());
  EXPECT_EQ(same.material_libraries, std::vector<std::string>{"gone.mtl"});
}

TEST_F(MaterialsRoundTrip, BlenderImportsTheSlotsColoursAndUvLayer) {
  if (!blender_on_path()) GTEST_SKIP() << "blender is not on PATH (Debian: apt-get install blender)";
  const fs::path input = write_banded_cylinder(dir / "in");
  fs::create_directories(dir / "out");
  const fs::path output = dir / "out" / "lod.obj";
  const PolyMesh out = simplify_to(input, output, dir);
  ASSERT_GT(out.num_faces(), 0u);

  // The import the way a user does it (Blender 3.2+ C++ importer, identity axes); one JSON line.
  const fs::path script = dir / "inspect.py";
  write_text(script,
             "import bpy, json, sys\n"
             "path = sys.argv[sys.argv.index('--') + 1]\n"
             "bpy.ops.wm.read_factory_settings(use_empty=True)\n"
             "bpy.ops.wm.obj_import(filepath=path, forward_axis='Y', up_axis='Z')\n"
             "objs = [o for o in bpy.context.scene.objects if o.type == 'MESH']\n"
             "kd = {}\n"
             "for m in bpy.data.materials:\n"
             "    for n in (m.node_tree.nodes if m.node_tree else []):\n"
             "        if n.type == 'BSDF_PRINCIPLED':\n"
             "            kd[m.name] = list(n.inputs['Base Color'].default_value)[:3]\n"
             "print('ROUNDTRIP ' + json.dumps({\n"
             "    'objects': len(objs),\n"
             "    'faces': sum(len(o.data.polygons) for o in objs),\n"
             "    'uv_layers': [len(o.data.uv_layers) for o in objs],\n"
             "    'slots': sorted({s.material.name for o in objs for s in o.material_slots if s.material}),\n"
             "    'kd': kd}), flush=True)\n");
  const fs::path log = dir / "blender.log";
  const std::string cmd = "blender -b --factory-startup --python '" + script.string() + "' -- '" +
                          output.string() + "' > '" + log.string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(log);
  std::istringstream lines(slurp(log));
  nlohmann::json j;
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("ROUNDTRIP ", 0) == 0) j = nlohmann::json::parse(line.substr(10));
  ASSERT_FALSE(j.is_null()) << slurp(log);
  EXPECT_EQ(j["objects"], 1);
  EXPECT_EQ(j["faces"], out.num_faces());
  EXPECT_EQ(j["uv_layers"], nlohmann::json::array({1}));
  EXPECT_EQ(j["slots"], nlohmann::json::array({"chrome", "paint_red", "rubber_black"}));
  // The MTL's colours arrived, so `mtllib` resolved from out/ (a missing MTL gives grey 0.8).
  ASSERT_TRUE(j["kd"].contains("chrome")) << j.dump();
  EXPECT_NEAR(j["kd"]["chrome"][2].get<double>(), 0.75, 1e-6);
  EXPECT_NEAR(j["kd"]["paint_red"][0].get<double>(), 0.8, 1e-6);
  EXPECT_NEAR(j["kd"]["paint_red"][1].get<double>(), 0.1, 1e-6);
  EXPECT_NEAR(j["kd"]["rubber_black"][0].get<double>(), 0.05, 1e-6);
}
