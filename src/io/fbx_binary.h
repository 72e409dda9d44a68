// quadlod — a reader of binary FBX's record tree (FBX 7.x, as Blender, Maya and the Autodesk SDK
// write it), for what assimp does not hand over: the control points (the mesh's vertices, with
// their identity and float64 positions) behind the per-corner vertices of assimp's aiMesh.
// See fbx_control_points.h for their use; docs/scenes.md.
//
// Layout (little endian):
//   header   "Kaydara FBX Binary  \0" 0x1A 0x00, u32 version
//   record   end offset, property count, property list bytes (u32 each before version 7500,
//            u64 from 7500), u8 name length, name, properties, nested records closed by a NULL
//            record (a record header of zeros) when there are any
//   property a type code, then: Y i16 · C bool · I i32 · F f32 · D f64 · L i64 ·
//            S / R u32 length + bytes · f d l i b arrays: u32 count, u32 encoding (0 raw,
//            1 zlib), u32 byte length, data
// The top-level record list ends at a NULL record (the footer after it is not read).
//
// The bytes are untrusted: every length and offset is checked against its enclosing record and
// the buffer, nesting is bounded, and a zlib array must inflate to exactly its declared size
// (bounded by zlib's largest ratio). A bad file is one error line naming the byte offset.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace quadlod::fbx {

/// One property of a record. Integers (Y C I L, arrays b i l) are in `integers`, reals (F D,
/// arrays f d) in `reals`, strings and raw bytes (S R) in `bytes`; a scalar is a one-element vector.
struct Property {
  char type = 0;  ///< the FBX type code
  std::vector<std::int64_t> integers;
  std::vector<double> reals;
  std::string bytes;
  bool is_array() const { return type == 'f' || type == 'd' || type == 'l' || type == 'i' || type == 'b'; }
};

struct Record {
  std::string name;
  std::vector<Property> properties;
  std::vector<Record> children;
  /// The first child named `child`, or nullptr.
  const Record* find(std::string_view child) const;
  /// Property i as a string ("" when it is absent or not S / R).
  std::string string_property(std::size_t i) const;
};

struct Document {
  std::uint32_t version = 0;
  std::vector<Record> records;  ///< the top-level records (FBXHeaderExtension, Objects, …)
  const Record* find(std::string_view name) const;
};

struct ParseParams {
  /// Deepest record nesting accepted. Real files nest 5–6 deep (Objects / Geometry /
  /// LayerElementUV / UV); the bound keeps a hostile file from exhausting the stack.
  int max_depth = 32;
  /// A zlib array may declare at most this many bytes per compressed byte: deflate's largest
  /// ratio is 1032:1, so a larger claim is a lie, refused before anything is allocated.
  std::uint64_t max_inflate_ratio = 1032;
};

struct ParseResult {
  Document document;
  std::string error;  ///< empty on success; else one line ("FBX byte N: …")
  bool ok() const { return error.empty(); }
};

/// `text` for an error message: printable ASCII kept, other bytes as \xNN, cut after
/// `max_length` bytes (names in a hostile file can hold anything, newlines included).
std::string printable(std::string_view text, std::size_t max_length = 64);

/// True when `bytes` starts with the binary FBX magic (an ASCII FBX does not).
bool is_binary_fbx(std::string_view bytes);

/// The record tree of a binary FBX.
ParseResult parse_binary_fbx(std::string_view bytes, const ParseParams& params = {});

}  // namespace quadlod::fbx
