// The catalogue of hostile meshes (issue 23): each case writes one file, streamed to disk (the
// 2 GB line is never held in memory), and says what the CLI must do with it. Used by
// tests/test_hostile_meshes.cpp; the table of outcomes is docs/hostile_input.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace quadlod::hostile {

enum class Expect {
  Refusal,           ///< exit 2 with one line naming the file and what is wrong
  RefusalOrOutput,   ///< either that or a valid output: both are correct answers
};

struct HostileCase {
  std::string name;         ///< also the file stem
  std::string extension;    ///< ".obj", ".ply", ".off"
  std::string description;  ///< one line for the docs table
  Expect expect = Expect::RefusalOrOutput;
  std::string message_has;  ///< for refusals: a word the one-line message must contain
  std::uint64_t faces = 0;  ///< faces the file holds (the memory bound is per input face)
  /// Vertices when there are more than faces (disconnected faces): most of the pipeline's memory
  /// is per vertex, and the bound is taken per max(faces, vertices) (docs/hostile_input.md).
  std::uint64_t vertices = 0;
  std::function<void(const std::filesystem::path&)> write;
};

/// Every case of the catalogue, in table order. `components` is the count of the case of separate
/// one-quad components (named `components_<count/1000>k`): 100 000 in the table; the sanitizer
/// tree takes fewer, since every one of them is a part the reduction works on in every pass
/// (measured under load: 100 000 took 241 s there, 20 000 took 58 s, against 4.7 s for 100 000 in
/// Release).
std::vector<HostileCase> catalogue(int components = 100000);

}  // namespace quadlod::hostile
