// quadlod — what the libFuzzer targets check (issue 23), shared with the GoogleTest that replays
// every input that ever failed (tests/test_fuzz_regressions.cpp, tests/fuzz_regressions/*).
//
// Each check takes the raw fuzz input and returns an empty string when every property holds,
// else one line saying which property broke. The fuzz drivers (fuzz/fuzz_*.cpp) abort on a
// non-empty answer so that libFuzzer keeps the input; the regression test asserts it is empty.
// Crashes, sanitizer reports and hangs are caught by libFuzzer itself (-timeout=2).
#pragma once

#include "quadlod/io.h"
#include "quadlod/mesh.h"
#include "quadlod/simplify.h"

#include <cstdint>
#include <string>
#include <string_view>

namespace quadlod::fuzz {

/// Parses `bytes` as a file of `format` (in memory) and checks the reader's contract
/// (include/quadlod/io.h): a failure is one line naming the file with an empty mesh; a success
/// is a mesh that passes check_layout() with faces and finite coordinates, and that survives a
/// write → read round trip in the same format with the same vertex and face counts. PLY inputs
/// are also written and re-read in the other PLY encodings.
std::string check_reader(MeshFormat format, std::string_view bytes);

/// The whole pipeline on a small mesh decoded from `bytes` (decode_pipeline_case): simplify
/// either refuses with a one-line error or returns a mesh that passes check_layout(), has
/// finite coordinates, the tri-equivalent count it reports, and no more non-manifold edges and
/// repeated-vertex faces than its input.
std::string check_pipeline(std::string_view bytes);

/// The pipeline case encoded in a fuzz input. Layout (every field optional: missing bytes
/// read as 0, so every input decodes to something):
///   byte 0        ratio = (b + 1) / 256
///   byte 1        flags: bit 0 features off, bit 1 objective "paper" (greedy, no MIP),
///                 bit 2 no segmentation, bit 3 no dual repair, bit 4 one pass only (else
///                 at most kMaxPipelinePasses passes)
///   byte 2        vertex count - 3 (3..258)
///   per vertex    3 × int16 little endian, coordinates in units of 1/256
///   then faces    one byte degree - 3 (degree 3..10, b % 8), then `degree` bytes, each a
///                 vertex index modulo the vertex count (16-bit when there are > 256 vertices)
///                 until the input ends or kMaxFaces faces are read
struct PipelineCase {
  PolyMesh mesh;
  SimplifyOptions options;
};
inline constexpr Index kMaxPipelineFaces = 512;
inline constexpr int kMaxPipelinePasses = 3;
PipelineCase decode_pipeline_case(std::string_view bytes);

/// The inverse of decode_pipeline_case for seeds: positions are rounded to the 1/256 grid
/// (after scaling into int16 range), faces above degree 10 or vertices above 258 do not fit
/// (false).
bool encode_pipeline_case(const PolyMesh& mesh, double ratio, std::uint8_t flags, std::string& out);

/// The assimp front end (issue 21), where it exists (QUADLOD_FUZZ_HAS_SCENE: include/quadlod/
/// scene.h is in the tree): read_scene_from_memory(bytes, hint) either fails with one line or
/// returns meshes that pass check_layout() and nodes whose parents precede them and whose mesh
/// indices exist. `hint` is the format's extension without the dot ("glb", "dae", "fbx").
std::string check_scene(std::string_view hint, std::string_view bytes);

/// The binary FBX reader (src/io/fbx_control_points.h, issue 21): read_mesh_geometries either
/// refuses with one line starting "FBX " (and no geometries) or returns geometries whose polygons
/// name existing control points, with finite positions and one material slot per polygon if any.
std::string check_fbx_binary(std::string_view bytes);

}  // namespace quadlod::fuzz
