// quadlod — helpers shared by the OBJ, PLY and OFF readers and writers (private to src/io/):
// whole-file loading, number scanning and formatting, face validation, and the in-memory parse
// entry points the tests and fuzz loops drive without touching the file system.
#pragma once

#include "quadlod/io.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace quadlod::io_detail {

class Stopwatch {
 public:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// A whole file in memory. The buffer is left uninitialised before read() fills it: zeroing
/// 100 MB first costs as much as a tenth of parsing it.
struct FileBuffer {
  std::unique_ptr<char[]> data;
  std::size_t size = 0;
  std::string_view view() const { return {data.get(), size}; }
};

/// Reads the whole file. On failure returns false and sets `error` to one line naming the path
/// ("cannot read a.obj: No such file or directory").
bool read_whole_file(const std::filesystem::path& path, FileBuffer& out, std::string& error);

/// The temp-file registry of install_interrupt_cleanup() (interrupt_cleanup.cpp): a temporary
/// file registered here is removed when SIGINT / SIGTERM / SIGHUP ends the process. Returns a
/// slot for unregister_temporary() (-1: not registered, e.g. too many at once).
int register_temporary(const char* path);
void unregister_temporary(int slot);

/// Reads the file at `path` and runs `parse(text, name, options)`; `seconds` covers both.
template <class Parse>
ReadResult read_and_parse(const std::filesystem::path& path, const ReadOptions& options, Parse parse) {
  const Stopwatch clock;
  FileBuffer file;
  std::string error;
  if (!read_whole_file(path, file, error)) {
    ReadResult result;
    result.error = std::move(error);
    return result;
  }
  ReadResult result = parse(file.view(), path.string(), options);
  result.seconds = clock.seconds();
  return result;
}

/// In-memory counterparts of read_ply / read_off (`name` is used in error messages only).
ReadResult parse_ply(std::string_view data, const std::string& name, const ReadOptions& options = {});
ReadResult parse_off(std::string_view text, const std::string& name, const ReadOptions& options = {});

/// Serialisers behind write_obj / write_ply / write_off. They return false with `error` set
/// (without the path) when the mesh cannot be written, e.g. when check_layout() fails.
bool format_obj(const PolyMesh& mesh, const WriteOptions& options, std::string& out,
                std::string& error);
bool format_ply(const PolyMesh& mesh, const WriteOptions& options, std::string& out,
                std::string& error);
bool format_off(const PolyMesh& mesh, const WriteOptions& options, std::string& out,
                std::string& error);

/// Appends to `warnings` one line per per-face tag kind (materials, groups, objects, smoothing
/// groups) that `mesh` carries and a format without tags (PLY, OFF) drops: issue 7's "no silent
/// loss" — a reduced mesh written as PLY must not lose its material assignment unnoticed.
inline void warn_dropped_tags(const PolyMesh& mesh, const std::filesystem::path& path, const char* format,
                              std::vector<std::string>& warnings) {
  const auto tagged = [](const std::vector<Index>& tags) {
    return static_cast<std::size_t>(std::count_if(tags.begin(), tags.end(), [](Index t) { return t != kInvalidIndex; }));
  };
  const auto warn = [&](std::size_t faces, std::size_t names, const char* kind) {
    if (faces == 0) return;
    warnings.push_back(path.string() + ": " + format + " has no per-face " + kind + "; " + std::to_string(names) +
                       " on " + std::to_string(faces) + " face(s) dropped (write OBJ to keep them)");
  };
  warn(tagged(mesh.face_material), mesh.material_names.size(), "materials (usemtl)");
  warn(tagged(mesh.face_group), mesh.group_names.size(), "groups (g)");
  warn(tagged(mesh.face_object), mesh.object_names.size(), "objects (o)");
  std::vector<Index> groups(mesh.face_smoothing);
  std::sort(groups.begin(), groups.end());
  warn(mesh.face_smoothing.size(), static_cast<std::size_t>(std::unique(groups.begin(), groups.end()) - groups.begin()),
       "smoothing groups (s; 'off' counts as one)");
}

/// Runs `format` and writes its result atomically to `path`; the shared tail of every writer.
template <class Format>
WriteResult format_and_write(const PolyMesh& mesh, const std::filesystem::path& path,
                             const WriteOptions& options, Format format) {
  std::string out, error;
  if (!format(mesh, options, out, error)) return {"cannot write " + path.string() + ": " + error, {}};
  return write_file_atomically(path, out);
}

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
inline bool is_space(char c) { return is_blank(c) || c == '\n'; }

inline const char* skip_blanks(const char* p, const char* end) {
  while (p < end && is_blank(*p)) ++p;
  return p;
}
inline const char* skip_token(const char* p, const char* end) {
  while (p < end && !is_space(*p)) ++p;
  return p;
}

/// Parses a double that must fill [p, end) up to the next blank. Accepts a leading '+', which
/// std::from_chars does not. Returns false for malformed or out-of-range text; non-finite
/// values ("nan", "inf") parse and are left to the caller, which knows what to call them.
///
/// Plain decimals with at most 19 digits and a decimal exponent within ±22 (virtually every
/// coordinate in a mesh file) take Clinger's fast path: the digits form an integer m < 2^53 and
/// 10^|e| is exact, so the one IEEE multiply or divide is correctly rounded and the result
/// equals std::from_chars'. Everything else goes to std::from_chars.
inline bool parse_double_token(const char* p, const char* end, double& value, const char*& next) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const bool plus = p < end && *p == '+';
  p += plus;
  if (plus && p < end && *p == '-') return false;
  const char* s = p;
  const bool negative = !plus && s < end && *s == '-';
  s += negative;
  std::uint64_t m = 0;
  int digits = 0, fraction = 0;
  while (s < end && static_cast<unsigned char>(*s - '0') <= 9) {
    m = m * 10 + static_cast<unsigned>(*s++ - '0');
    ++digits;
  }
  if (s < end && *s == '.') {
    ++s;
    while (s < end && static_cast<unsigned char>(*s - '0') <= 9) {
      m = m * 10 + static_cast<unsigned>(*s++ - '0');
      ++digits;
      ++fraction;
    }
  }
  int exponent = 0;
  bool simple = digits > 0 && digits <= 19;
  if (simple && s < end && (*s == 'e' || *s == 'E')) {
    const char* e = s + 1;
    const bool e_negative = e < end && *e == '-';
    if (e < end && (*e == '-' || *e == '+')) ++e;
    int n = 0;
    while (e < end && static_cast<unsigned char>(*e - '0') <= 9 && n < 4) {
      exponent = exponent * 10 + (*e++ - '0');
      ++n;
    }
    if (e_negative) exponent = -exponent;
    simple = n > 0 && n < 4;
    s = e;
  }
  exponent -= fraction;
  if (simple && m <= (std::uint64_t{1} << 53) && exponent >= -22 && exponent <= 22 &&
      (s == end || is_space(*s))) {
    double v = static_cast<double>(m);
    v = exponent < 0 ? v / kPow10[-exponent] : v * kPow10[exponent];
    value = negative ? -v : v;
    next = s;
    return true;
  }
  const auto [ptr, ec] = std::from_chars(p, end, value, std::chars_format::general);
  if (ec != std::errc() || (ptr < end && !is_space(*ptr))) return false;
  next = ptr;
  return true;
}

/// Signed decimal integer with optional sign; stops at the first non-digit and leaves checking
/// what follows to the caller (OBJ corners continue with '/'). False when there are no digits
/// or the magnitude exceeds 2^62, far beyond any 32-bit index.
[[gnu::always_inline]] inline bool parse_int64(const char* p, const char* end, std::int64_t& value, const char*& next) {
  bool negative = false;
  if (p < end && (*p == '-' || *p == '+')) negative = *p++ == '-';
  if (p == end || static_cast<unsigned char>(*p - '0') > 9) return false;
  std::uint64_t v = 0;
  while (p < end && static_cast<unsigned char>(*p - '0') <= 9) {
    if (v > (std::uint64_t{1} << 62)) return false;
    v = v * 10 + static_cast<unsigned>(*p - '0');
    ++p;
  }
  value = negative ? -static_cast<std::int64_t>(v) : static_cast<std::int64_t>(v);
  next = p;
  return true;
}

/// Appends `value` with `precision` significant digits (printf %g style, shortest form).
inline void append_double(std::string& out, double value, int precision) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::general, precision);
  out.append(buf, r.ptr);
}
/// Appends the shortest text that reads back as exactly `value` (PLY float properties).
inline void append_float(std::string& out, float value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, r.ptr);
}
inline void append_uint(std::string& out, std::uint64_t value) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, r.ptr);
}

enum class FaceProblem { None, TooFewCorners, RepeatedVertex };

/// Validates the corners of one face: >= 3 corners and, unless allowed, no vertex used twice
/// (`repeated` receives that vertex). `scratch` is reused across calls so that large n-gons do
/// not allocate per face.
FaceProblem check_face(const Index* corners, std::size_t count, bool allow_repeated_vertex,
                       std::vector<Index>& scratch, Index& repeated);

/// "has 2 corners (at least 3 needed)" / "uses vertex 7 more than once"; `base` is
/// added to the vertex id so OBJ messages can speak 1-based like the file.
std::string describe_face_problem(FaceProblem problem, std::size_t count, Index repeated,
                                  Index base);

/// Clamps WriteOptions::precision to what a double can carry.
inline int clamp_precision(int p) { return p < 1 ? 1 : (p > 17 ? 17 : p); }

}  // namespace quadlod::io_detail
