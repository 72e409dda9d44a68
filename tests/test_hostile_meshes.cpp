// The catalogue of hostile meshes (tests/hostile_meshes.h, issue 23) through `quadlod simplify`:
// each case ends in exit 2 with one line naming the file, or exit 0 with an output that reads
// back and is a valid pipeline input; never a crash (signal / exit 3), a hang (timeout) or a
// peak RSS above the bound. With QUADLOD_HOSTILE_TABLE=FILE the outcomes are written as the
// markdown table of docs/hostile_input.md.
#include "hostile_meshes.h"

#include "mesh/validation.h"
#include "quadlod/io.h"

#include "cli_runner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>

#if defined(__SANITIZE_ADDRESS__)
#define QUADLOD_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define QUADLOD_TEST_ASAN 1
#endif
#endif

namespace quadlod {
namespace {

namespace fs = std::filesystem;
using testing::run_cli;

// The bound of issue 23: 1.5 GiB per million input faces, over a base for the process itself
// (code, CBC, the allocator's arenas) that a one-face file already needs. Per max(faces,
// vertices): 100 000 separate quads have 4 vertices a face and need 498 MiB, over the per-face
// 410 MiB (measured; docs/hostile_input.md, "Memory").
constexpr double kBoundBytesPerFace = 1.5 * 1024 * 1024 * 1024 / 1e6;
constexpr double kBaseBytes = 256.0 * 1024 * 1024;
// A case running this long is hung (the slowest, 100 000 components, takes seconds).
constexpr int kTimeoutSeconds = 600;

std::string last_line(const std::string& text) {
  std::string s = text;
  while (!s.empty() && s.back() == '\n') s.pop_back();
  const auto nl = s.rfind('\n');
  return nl == std::string::npos ? s : s.substr(nl + 1);
}

class HostileMeshes : public testing::ScratchDirTest {};

TEST_F(HostileMeshes, EveryCaseIsRefusedInOneLineOrGivesAValidOutput) {
  std::ofstream table;
  if (const char* path = std::getenv("QUADLOD_HOSTILE_TABLE")) {
    table.open(path);
    table << "| case | file | outcome | message / output | peak RSS | bound | seconds |\n"
             "|---|---|---|---|---|---|---|\n";
  }
#ifdef QUADLOD_TEST_ASAN
  const int components = 10000;
#else
  const int components = 100000;
#endif
  for (const hostile::HostileCase& c : hostile::catalogue(components)) {
    SCOPED_TRACE(c.name);
    const fs::path input = dir / (c.name + c.extension);
    const fs::path output = dir / (c.name + "-out.obj");
    const fs::path rss = dir / "rss.txt";
    c.write(input);
    const auto start = std::chrono::steady_clock::now();
    const testing::CliRun run = run_cli("-q simplify '" + input.string() + "' -o '" + output.string() +
                                            "' --ratio 0.5 --max-memory 1GiB",
                                        dir, "/usr/bin/time -f %M -o '" + rss.string() + "' timeout " +
                                                 std::to_string(kTimeoutSeconds));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double peak_bytes = std::atof(last_line(testing::slurp(rss)).c_str()) * 1024.0;
    const double bound = kBaseBytes + kBoundBytesPerFace * double(std::max(c.faces, c.vertices));
    fs::remove(input);  // the 2 GiB line must not outlive its case

    ASSERT_TRUE(run.exit_code == 0 || run.exit_code == 2)
        << "exit " << run.exit_code << " (124: hang; 128+N: signal N; 3: internal error)\n" << run.err;
    std::string what;
    if (run.exit_code == 2) {
      EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
      EXPECT_NE(run.err.find(input.filename().string()), std::string::npos) << "message does not name the file: " << run.err;
      if (!c.message_has.empty()) {
        EXPECT_NE(run.err.find(c.message_has), std::string::npos) << run.err;
      }
      EXPECT_FALSE(fs::exists(output));
      what = last_line(run.err);
      const auto at = what.find(input.string());  // the table shows the file name, not the scratch path
      if (at != std::string::npos) what.replace(at, input.string().size(), input.filename().string());
    } else {
      EXPECT_EQ(c.expect, hostile::Expect::RefusalOrOutput) << "should have been refused";
      const ReadResult back = read_mesh(output);
      ASSERT_TRUE(back.ok()) << back.error;
      EXPECT_EQ(check_pipeline_input(back.mesh), "");
      what = "output: " + std::to_string(back.mesh.num_faces()) + " faces";
    }
#ifndef QUADLOD_TEST_ASAN
    // ASan's shadow memory and quarantine multiply the footprint: the bound is the release tree's.
    EXPECT_LE(peak_bytes, bound) << "peak RSS " << peak_bytes / 1048576 << " MiB";
#endif
    fs::remove(output);
    if (table.is_open()) {
      char row[256];
      std::snprintf(row, sizeof row, "| %.0f MiB | %.0f MiB | %.1f |", peak_bytes / 1048576, bound / 1048576, seconds);
      table << "| `" << c.name << "` | " << c.description << " | exit " << run.exit_code << " | " << what << " " << row
            << "\n";
    }
  }
}

}  // namespace
}  // namespace quadlod
