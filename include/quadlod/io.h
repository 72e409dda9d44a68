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
  bool ok() const { return error.empty(); }
};

/// Format from the file extension (.obj, .ply, .off, case-insensitive); false if unknown.
bool format_from_path(const std::filesystem::path& path, MeshFormat& format);

/// Reads a mesh; the format comes from the extension. Rejects: unreadable/missing files,
/// truncated or malformed records, non-finite coordinates, out-of-range or zero indices, faces
/// with fewer than 3 corners, repeated vertices in a face (see ReadOptions), an empty mesh
/// (no faces).
ReadResult read_mesh(const std::filesystem::path& path, const ReadOptions& options = {});
ReadResult read_obj(const std::filesystem::path& path, const ReadOptions& options = {});
ReadResult read_ply(const std::filesystem::path& path, const ReadOptions& options = {});
ReadResult read_off(const std::filesystem::path& path, const ReadOptions& options = {});

/// Parses OBJ text held in memory (`name` is used in error messages only).
ReadResult parse_obj(std::string_view text, const std::string& name, const ReadOptions& options = {});

/// Writes a mesh; the format comes from the extension. The file appears atomically: data goes
/// to a temporary file in the target directory which is renamed over the target only after a
/// complete, flushed write, so a failure leaves no partial file behind. Callers that must not
/// overwrite an input compare paths before calling (the CLI does).
WriteResult write_mesh(const PolyMesh& mesh, const std::filesystem::path& path,
                       const WriteOptions& options = {});
WriteResult write_obj(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options = {});
WriteResult write_ply(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options = {});
WriteResult write_off(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options = {});

/// Writes `contents` to `path` atomically (temp file in the same directory + rename).
/// Shared by the mesh writers and by every JSON/CSV report the tool writes.
WriteResult write_file_atomically(const std::filesystem::path& path, std::string_view contents);

}  // namespace quadlod
