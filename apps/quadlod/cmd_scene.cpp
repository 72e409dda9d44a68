// `quadlod simplify` on scenes: FBX / glTF / Collada / … in, .glb / .fbx / .dae / OBJ / PLY / OFF
// out, every mesh reduced (include/quadlod/lod.h, simplify_scene).
#include "commands.h"
#include "protect_cli.h"
#include "symmetry_cli.h"

#include "quadlod/lod.h"
#include "quadlod/scene.h"
#include "util/progress.h"

#include <algorithm>
#include <cstdio>

namespace quadlod::cli {

int simplify_scene_file(const std::string& input, const std::string& output, const std::string& report,
                        const SimplifyOptions& options, bool per_mesh, const SkinPoseChoice& poses,
                        const std::string& protect_file) {
  SceneFormat format;
  if (!scene_format_from_path(output, format))
    return fail(output + ": unknown output format (use .obj, .ply, .off, .glb, .fbx or .dae)");
  Stopwatch clock;
  const SceneReadResult in = read_scene(input);
  if (!in.ok()) return fail(in.error);
  if (in.scene.meshes.empty())
    return fail(input + ": the scene has no mesh to reduce (" + std::to_string(in.scene.cameras) + " cameras, " +
                std::to_string(in.scene.lights) + " lights)");
  const double read_seconds = clock.seconds();
  SceneSimplifyParams params;
  params.options = options;
  // Issue 34: one weight per vertex of the scene, mesh after mesh (docs/protect.md).
  std::size_t vertices = 0;
  for (const SceneMesh& m : in.scene.meshes) vertices += m.mesh.num_vertices();
  if (std::string bad = load_protect_file(protect_file, params.options, vertices); !bad.empty()) return fail(bad);
  params.per_mesh = per_mesh;
  // The skinned meshes' weights index the scene's rig, and pose_mesh with its skinning matrices
  // poses them where eval --animation does (docs/skinning.md, "Scenes"); unskinned meshes ignore them.
  const bool skinned = std::any_of(in.scene.meshes.begin(), in.scene.meshes.end(),
                                   [](const SceneMesh& m) { return !m.mesh.skin.empty(); });
  if (skinned && !in.scene.rig.empty()) params.options.skin_poses = chosen_poses(in.scene.rig, poses);
  clock = Stopwatch();
  SceneSimplifyResult r = simplify_scene(in.scene, params);
  if (!r.ok()) return fail(input + ": " + r.error);
  for (SceneMesh& mesh : r.scene.meshes)
    if (!mesh.mesh.material_libraries.empty())
      for (const std::string& w : rebase_material_libraries(mesh.mesh, input, output)) std::fprintf(stderr, "warning: %s\n", w.c_str());
  const double reduce_seconds = clock.seconds();
  clock = Stopwatch();
  const WriteResult written = write_scene(r.scene, output);
  if (!written.ok()) return fail(written.error);
  for (const std::string& w : written.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  const double write_seconds = clock.seconds();
  r.report["input"] = input;
  r.report["output"] = output;
  r.report["read_seconds"] = read_seconds;
  r.report["seconds"] = reduce_seconds;
  r.report["write_seconds"] = write_seconds;
  if (!report.empty()) {
    const WriteResult rep = write_file_atomically(report, r.report.dump(2) + "\n");
    if (!rep.ok()) return fail(rep.error);
  }
  std::printf("simplify: %zu mesh%s, target %llu, achieved %llu, %u quads, %u tris, %u n-gons; read %.2f s, "
              "reduce %.2f s, write %.2f s\n",
              r.scene.meshes.size(), r.scene.meshes.size() == 1 ? "" : "es",
              static_cast<unsigned long long>(r.target), static_cast<unsigned long long>(r.achieved), r.quads,
              r.triangles, r.ngons, read_seconds, reduce_seconds, write_seconds);
  std::uint64_t joined = 0;
  for (const auto& m : r.report["meshes"])
    if (m.contains("simplify") && m["simplify"].contains("quad_recovery")) joined += m["simplify"]["quad_recovery"]["quads_made"].get<std::uint64_t>();
  if (joined > 0)
    std::printf("quads: all-triangle meshes had %llu pairs joined into quads first (--recover-quads off keeps them)\n",
                static_cast<unsigned long long>(joined));
  // Symmetry (issue 34): the plane of each mesh, or why none.
  for (const auto& m : r.report["meshes"])
    if (m.contains("simplify")) print_symmetry_line(m["simplify"], m.value("name", std::string()) + ": ");
  if (format == SceneFormat::Glb) std::printf("note: glTF holds triangles only: %s has its polygons triangulated\n", output.c_str());
  return kExitOk;
}

}  // namespace quadlod::cli
