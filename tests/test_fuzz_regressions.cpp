// Every input that ever broke a fuzz target (tests/fuzz_regressions/TARGET/*), replayed in the
// normal build through the same checks the fuzz targets run (fuzz/fuzz_checks.h; issue 23).
#include "fuzz_checks.h"

#include "quadlod/generators.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace quadlod {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string run_target(const std::string& target, std::string_view bytes) {
  if (target == "obj") return fuzz::check_reader(MeshFormat::Obj, bytes);
  if (target == "ply") return fuzz::check_reader(MeshFormat::Ply, bytes);
  if (target == "off") return fuzz::check_reader(MeshFormat::Off, bytes);
  if (target == "pipeline") return fuzz::check_pipeline(bytes);
  if (target == "fbx_binary") return fuzz::check_fbx_binary(bytes);
#ifdef QUADLOD_FUZZ_HAS_SCENE
  if (target == "assimp") return fuzz::check_scene("glb", bytes);
  if (target == "assimp_dae") return fuzz::check_scene("dae", bytes);
  if (target == "assimp_fbx") return fuzz::check_scene("fbx", bytes);
#else
  if (target.rfind("assimp", 0) == 0) return {};  // no scene reader in this tree
#endif
  return "unknown target " + target;
}

TEST(FuzzRegressions, EveryKeptInputPassesItsTargetsChecks) {
  const fs::path root = QUADLOD_FUZZ_REGRESSIONS_DIR;
  ASSERT_TRUE(fs::is_directory(root)) << root;
  int replayed = 0;
  for (const auto& target_dir : fs::directory_iterator(root)) {
    if (!target_dir.is_directory()) continue;
    const std::string target = target_dir.path().filename().string();
    for (const auto& file : fs::directory_iterator(target_dir.path())) {
      if (!file.is_regular_file() || file.path().filename() == "README.md") continue;
      EXPECT_EQ(run_target(target, read_bytes(file.path())), "") << file.path();
      ++replayed;
    }
  }
  std::printf("replayed %d kept fuzz inputs\n", replayed);
}

// The pipeline target's decoder reads back what the seed encoder wrote: same faces, positions
// on the 1/256 grid of a box of side 128, ratio and flags as given.
TEST(FuzzRegressions, PipelineCaseEncodingRoundTrips) {
  const PolyMesh grid = make_grid(3, 2, 2.0, 1.0);
  std::string bytes;
  ASSERT_TRUE(fuzz::encode_pipeline_case(grid, 0.5, 2 | 16, bytes));
  const fuzz::PipelineCase c = fuzz::decode_pipeline_case(bytes);
  EXPECT_EQ(c.mesh.corner_vertex, grid.corner_vertex);
  EXPECT_EQ(c.mesh.face_offsets, grid.face_offsets);
  ASSERT_EQ(c.mesh.num_vertices(), grid.num_vertices());
  EXPECT_DOUBLE_EQ(c.options.ratio, 128.0 / 256.0);
  EXPECT_EQ(c.options.objective, SimplifyOptions::Objective::Paper);
  EXPECT_EQ(c.options.max_passes, 1);
  EXPECT_TRUE(c.options.features);
  // The grid spans 2 × 1: x maps to [-64, 64], y to [-32, 32].
  EXPECT_DOUBLE_EQ(c.mesh.positions[0].x(), -64.0);
  EXPECT_DOUBLE_EQ(c.mesh.positions[0].y(), -32.0);
  // A face repeating a vertex is dropped by the decoder, as the readers refuse it.
  std::string repeated = bytes;
  repeated += std::string("\x01\x00\x01\x02\x00", 5);  // degree 4: 0 1 2 0
  EXPECT_EQ(fuzz::decode_pipeline_case(repeated).mesh.num_faces(), grid.num_faces());
}

// The reader checks accept a good file and a refused one alike; they flag a contract breach.
TEST(FuzzRegressions, ReaderChecksPassOnGoodAndRefusedInput) {
  EXPECT_EQ(fuzz::check_reader(MeshFormat::Obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "");
  EXPECT_EQ(fuzz::check_reader(MeshFormat::Obj, "v 0 0 0\nf 1 2 3\n"), "");
  EXPECT_EQ(fuzz::check_reader(MeshFormat::Off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "");
  EXPECT_EQ(fuzz::check_reader(MeshFormat::Ply, "ply\nformat ascii 1.0\nelement vertex 2147483648\nend_header\n"), "");
}

}  // namespace
}  // namespace quadlod
