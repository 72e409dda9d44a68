// quadlod — mesh readers and writers: Wavefront OBJ, PLY (ascii / binary little / big endian), OFF.
//
// Errors are values: every function returns a result whose `error` is empty on success and is
// otherwise one line naming the file and, where there is one, the line (text formats) or the
// element (binary formats): "mesh.obj:42: face refers to vertex 17 but only 12 are defined".
// Nothing throws across this interface.
#pragma once

#include "quadlod/mesh.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace quadlod {

enum class MeshFormat { Obj, Ply, Off };
enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct ReadOptions {
  /// Faces that use one vertex twice are an error unless this is set (`quadlod info` sets it so
  /// it can count them as degenerate).
  bool allow_repeated_vertex = false;
};

struct ReadResult {
  PolyMesh mesh;
  std::string error;  ///< empty on success
  double seconds = 0.0;  ///< wall time spent reading and parsing
  /// Records read but not represented in the mesh: OBJ `l`, `p`, `vp`, free-form geometry and
  /// unknown statements. Informational (`quadlod info` can show it); not an error.
  std::uint64_t ignored_records = 0;
  bool ok() const { return error.empty(); }
};

struct WriteOptions {
  PlyEncoding ply_encoding = PlyEncoding::BinaryLittleEndian;
  /// Significant digits for text formats; 17 round-trips doubles exactly, 9 floats.
  int precision = 9;
};

struct WriteResult {
  std::string error;  ///< empty on success
  /// What the format could not hold and was dropped (e.g. UV sets beyond the first in OBJ);
  /// the CLI prints them. Empty when everything was written.
  std::vector<std::string> warnings;
  bool ok() const { return error.empty(); }
};

/// Format from the file extension (.obj, .ply, .off, case-insensitive); false if unknown.
bool format_from_path(const std::filesystem::path& path, MeshFormat& format);

/// Reads a mesh; the format comes from the extension. Rejects: unreadable/missing files,
/// truncated or malformed records, non-finite coordinates, out-of-range or zero indices, faces
/// with fewer than 3 corners, repeated vertices in a face (see ReadOptions), an empty mesh
/// (no faces). A failed read returns an empty mesh.
///
/// What each format fills in:
///   * OBJ: positions, vertex_colors (`v x y z r g b`), the uv/normal pools and per-corner
///     indices exactly as the `f` records give them (one UV set, uv_sets[0], present only when a
///     face uses `vt`), o/g/usemtl/s tags and mtllib lines. The per-corner and per-face arrays
///     exist only if the file uses them (has_uvs() is meaningful).
///     Positive indices may refer forward; negative ones are relative to what precedes them.
///   * PLY: positions; per-vertex normals and UVs become pools indexed by the corner's vertex;
///     a per-face `texcoord` list (MeshLab, 2 floats per corner) becomes one pool entry per
///     corner and wins over per-vertex UVs; lists `texcoord1`, `texcoord2`, … become further UV
///     sets; red/green/blue become vertex_colors in [0,1].
///   * OFF: positions and faces (ST/C/N/4 variants are read, their extra values skipped).
ReadResult read_mesh(const std::filesystem::path& path, const ReadOptions& options = {});
ReadResult read_obj(const std::filesystem::path& path, const ReadOptions& options = {});
ReadResult read_ply(const std::filesystem::path& path, const ReadOptions& options = {});
ReadResult read_off(const std::filesystem::path& path, const ReadOptions& options = {});

/// Parses OBJ text held in memory (`name` is used in error messages only).
ReadResult parse_obj(std::string_view text, const std::string& name, const ReadOptions& options = {});

/// Writes a mesh; the format comes from the extension. The file appears atomically: data goes
/// to a temporary file in the target directory which is renamed over the target only after a
/// complete, flushed write, so a failure leaves no partial file behind. Callers that must not
/// overwrite an input compare paths before calling (the CLI does). A mesh failing
/// check_layout() is refused.
///
///   * OBJ: read → write → read reproduces the PolyMesh exactly when `precision` covers the
///     input's digits (17 always does); tags are emitted where they change between faces.
///     OBJ has one UV set: further sets are dropped with a warning.
///   * PLY: float x y z (so coordinates round to float; double when a coordinate is beyond float's
///     range, likewise normals and each UV set), nx ny nz only when every vertex has one
///     normal shared by all its corners, uchar colours, per-corner UVs as a `texcoord` list per
///     UV set (`texcoord`, `texcoord1`, …; set names are not kept).
///     Face tags have no PLY form and are dropped.
///   * OFF: positions and faces only.
WriteResult write_mesh(const PolyMesh& mesh, const std::filesystem::path& path,
                       const WriteOptions& options = {});
WriteResult write_obj(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options = {});
WriteResult write_ply(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options = {});
WriteResult write_off(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options = {});

/// OBJ `mtllib` paths are resolved from the directory of the OBJ file that names them. When a
/// mesh read from `input` is written to `output` in another directory, every relative library
/// path that names an existing file next to `input` is rewritten to resolve from the directory
/// of `output` (a relative path; absolute when no relative one exists). The MTL file itself is
/// not copied: it names its textures relative to itself, so a copy elsewhere would lose them.
/// Absolute paths stay as they are; a library that does not exist next to `input` is left
/// unchanged and reported in the returned warnings (one line each). An `mtllib` line naming
/// several files is rewritten file by file. Nothing changes when both files share a directory.
std::vector<std::string> rebase_material_libraries(PolyMesh& mesh, const std::filesystem::path& input,
                                                   const std::filesystem::path& output);

/// What a mesh file holds, found before reading it (issue 23: refuse an input that would exceed
/// `--max-memory` before allocating for it). PLY and OFF: the header's element counts (corners
/// assumed 4 per face: the header has none). OBJ: one streaming pass counting `v` and `f`
/// records and the corners of the `f` records. Counts are what the file claims, not validated.
struct InputSizeEstimate {
  std::uint64_t file_bytes = 0;
  std::uint64_t vertices = 0;
  std::uint64_t faces = 0;
  std::uint64_t corners = 0;
  std::string error;  ///< empty on success (unreadable file, unknown format)
};
InputSizeEstimate estimate_input_size(const std::filesystem::path& path);

/// Peak memory of `quadlod simplify` as a function of the input: base + the file (held whole
/// while parsing) + a cost per triangle-equivalent. Defaults measured on generated grids
/// (docs/hostile_input.md, "Memory"), rounded up.
struct MemoryModel {
  std::uint64_t base_bytes = std::uint64_t{64} << 20;
  double bytes_per_tri_equivalent = 800.0;
};
std::uint64_t estimate_simplify_peak_bytes(const InputSizeEstimate& input, const MemoryModel& model = {});

/// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove the temporary files
/// write_file_atomically() is writing and then let the signal end the process, so an
/// interrupted run leaves no partial output and no stray temp file (the CLI calls it first).
void install_interrupt_cleanup();

/// Writes `contents` to `path` atomically (temp file in the same directory + rename).
/// Shared by the mesh writers and by every JSON/CSV report the tool writes.
WriteResult write_file_atomically(const std::filesystem::path& path, std::string_view contents);

}  // namespace quadlod
