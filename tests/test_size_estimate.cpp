// estimate_input_size / estimate_simplify_peak_bytes and `simplify --max-memory` (issue 23):
// counts read before the mesh is, and a clean refusal over the limit.
#include "quadlod/generators.h"
#include "quadlod/io.h"

#include "cli_runner.h"

#include <gtest/gtest.h>

namespace quadlod {
namespace {

using testing::run_cli;
using testing::write_text;

class SizeEstimate : public testing::ScratchDirTest {};

TEST_F(SizeEstimate, ObjCountsVertexAndFaceRecordsAndCorners) {
  const auto path = dir / "a.obj";
  write_text(path,
             "# v 9 9 9 in a comment\nv 0 0 0\n  v 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
             "f 1 2 3 4\n\tf 1/1 2/1 3/1\nfo 1 2 3\nl 1 2\n");
  const InputSizeEstimate e = estimate_input_size(path);
  EXPECT_EQ(e.error, "");
  EXPECT_EQ(e.vertices, 4u);
  EXPECT_EQ(e.faces, 2u);
  EXPECT_EQ(e.corners, 7u);
  EXPECT_EQ(e.file_bytes, std::filesystem::file_size(path));
}

TEST_F(SizeEstimate, PlyAndOffTakeTheHeaderCounts) {
  const auto ply = dir / "a.ply";
  write_text(ply, "ply\nformat ascii 1.0\nelement vertex 2147483648\nproperty float x\nelement face 17\n"
                  "property list uchar int vertex_indices\nend_header\n");
  InputSizeEstimate e = estimate_input_size(ply);
  EXPECT_EQ(e.vertices, 2147483648u);
  EXPECT_EQ(e.faces, 17u);
  EXPECT_EQ(e.corners, 68u);  // 4 per face: the header has no corner count
  const auto off = dir / "a.off";
  write_text(off, "# comment\nOFF # trailing\n# another\n12 34 0\n");
  e = estimate_input_size(off);
  EXPECT_EQ(e.vertices, 12u);
  EXPECT_EQ(e.faces, 34u);
  EXPECT_NE(estimate_input_size(dir / "missing.obj").error, "");
}

TEST_F(SizeEstimate, PeakGrowsWithTriangleEquivalentsAndFileSize) {
  InputSizeEstimate e;
  e.faces = 1000;
  e.corners = 4000;  // 2000 tri-equivalents
  e.file_bytes = 5000;
  MemoryModel model;
  model.base_bytes = 100;
  model.bytes_per_tri_equivalent = 10.0;
  EXPECT_EQ(estimate_simplify_peak_bytes(e, model), 100u + 5000u + 20000u);
}

TEST_F(SizeEstimate, SimplifyRefusesOverMaxMemoryInOneLineAndWritesNothing) {
  const auto in = dir / "grid.obj";
  ASSERT_TRUE(write_mesh(make_grid(40, 40), in).ok());
  const auto out = dir / "out.obj";
  const testing::CliRun refused = run_cli("-q simplify '" + in.string() + "' -o '" + out.string() + "' --ratio 0.5 --max-memory 1MB", dir);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_NE(refused.err.find("grid.obj"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--max-memory"), std::string::npos) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  const testing::CliRun ok = run_cli("-q simplify '" + in.string() + "' -o '" + out.string() + "' --ratio 0.5 --max-memory 1GiB", dir);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(read_mesh(out).ok());
}

}  // namespace
}  // namespace quadlod
