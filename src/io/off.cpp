// quadlod — OFF reader and writer (Princeton Shape Benchmark / Geomview object file format).
//
// Reader: header keyword OFF with optional ST/C/N/4 prefixes (COFF, NOFF, STCNOFF, 4OFF...);
// the extra per-vertex values those variants add (texture coordinates, colours, normals, w)
// are skipped, as is the colour that may follow a face's indices. The counts may share the
// header line. '#' starts a comment anywhere. One vertex or face per line, indices 0-based.
// nOFF (arbitrary dimension) and OFF BINARY are rejected by name.
//
// Writer: "OFF", counts, "x y z" lines with WriteOptions::precision digits, "k i0 ... ik-1".
// Everything else (UVs, normals, colours, per-face tags) is dropped with a WriteResult warning.
#include "io/io_common.h"

#include <algorithm>

namespace quadlod {

using namespace io_detail;

namespace {

class OffParser {
 public:
  OffParser(std::string_view text, const std::string& name, const ReadOptions& options,
            ReadResult& result)
      : p_(text.data()), end_(text.data() + text.size()), name_(name), options_(options),
        mesh_(result.mesh), result_(result) {}

  bool run();

 private:
  bool fail(const std::string& message) {
    result_.error = name_ + ":" + std::to_string(line_) + ": " + message;
    return false;
  }
  // Advances to the next line holding something other than blanks and comments; [b, e) is its
  // content without the comment. False at end of file.
  bool next_line(const char*& b, const char*& e);
  // Reads one unsigned integer token from [p, e); false if there is none or it is malformed.
  bool count_token(const char*& p, const char* e, std::uint64_t& value);

  const char* p_;
  const char* end_;
  const std::string& name_;
  const ReadOptions& options_;
  PolyMesh& mesh_;
  ReadResult& result_;
  std::uint64_t line_ = 0;
};

bool OffParser::next_line(const char*& b, const char*& e) {
  while (p_ < end_) {
    ++line_;
    const char* eol = static_cast<const char*>(std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_)));
    if (!eol) eol = end_;
    b = skip_blanks(p_, eol);
    const char* hash = static_cast<const char*>(std::memchr(b, '#', static_cast<std::size_t>(eol - b)));
    e = hash ? hash : eol;
    while (e > b && is_blank(e[-1])) --e;
    p_ = eol < end_ ? eol + 1 : end_;
    if (b < e) return true;
  }
  return false;
}

bool OffParser::count_token(const char*& p, const char* e, std::uint64_t& value) {
  p = skip_blanks(p, e);
  std::int64_t v = 0;
  const char* next = nullptr;
  const char* token_end = skip_token(p, e);
  if (p == e || !parse_int64(p, token_end, v, next) || next != token_end || v < 0) return false;
  value = static_cast<std::uint64_t>(v);
  p = token_end;
  return true;
}

bool OffParser::run() {
  if (end_ - p_ >= 3 && std::memcmp(p_, "\xEF\xBB\xBF", 3) == 0) p_ += 3;
  if (std::memchr(p_, '\0', static_cast<std::size_t>(end_ - p_))) {
    line_ = 1;
    return fail("NUL byte: not a text file (OFF BINARY is not supported)");
  }
  const char* b = nullptr;
  const char* e = nullptr;
  if (!next_line(b, e)) {
    result_.error = name_ + ": empty file: no OFF header";
    return false;
  }

  const char* kw_end = skip_token(b, e);
  const std::string_view kw(b, static_cast<std::size_t>(kw_end - b));
  if (kw.size() < 3 || kw.substr(kw.size() - 3) != "OFF")
    return fail("not an OFF file (header '" + std::string(kw.substr(0, 40)) + "')");
  const std::string_view prefix = kw.substr(0, kw.size() - 3);
  if (prefix.find('n') != std::string_view::npos) return fail("nOFF (arbitrary dimension) is not supported");
  if (prefix.find_first_not_of("STCN4") != std::string_view::npos)
    return fail("unknown OFF variant '" + std::string(kw) + "'");
  const bool homogeneous = prefix.find('4') != std::string_view::npos;

  // Counts follow on the header line or on the next line.
  const char* q = skip_blanks(kw_end, e);
  if (q < e && std::string_view(q, static_cast<std::size_t>(skip_token(q, e) - q)) == "BINARY")
    return fail("OFF BINARY is not supported");
  if (q == e && !next_line(q, e)) return fail("missing vertex and face counts");
  std::uint64_t nv = 0, nf = 0, ne = 0;
  if (!count_token(q, e, nv) || !count_token(q, e, nf))
    return fail("bad counts line (expected: vertices faces [edges])");
  (void)count_token(q, e, ne);  // the edge count is unused and often wrong or missing
  if (nv >= kInvalidIndex || nf >= kInvalidIndex) return fail("counts exceed 32-bit indices");

  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face at least 8: cap the reservation
  // by the bytes left so that an absurd count cannot allocate.
  const auto left = static_cast<std::uint64_t>(end_ - p_);
  mesh_.positions.reserve(std::min(nv, left / 6));
  for (std::uint64_t i = 0; i < nv; ++i) {
    if (!next_line(b, e))
      return fail("file ends after " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    double xyz[4];
    const int want = homogeneous ? 4 : 3;
    for (int k = 0; k < want; ++k) {
      b = skip_blanks(b, e);
      const char* token_end = skip_token(b, e);
      const char* next = nullptr;
      if (b == e) return fail("vertex " + std::to_string(i) + " has " + std::to_string(k) + " coordinates (" + std::to_string(want) + " needed)");
      if (!parse_double_token(b, token_end, xyz[k], next))
        return fail("vertex " + std::to_string(i) + ": bad number '" +
                    std::string(b, static_cast<std::size_t>(std::min<std::ptrdiff_t>(token_end - b, 40))) + "'");
      if (!std::isfinite(xyz[k])) return fail("vertex " + std::to_string(i) + ": non-finite coordinate");
      b = token_end;
    }
    if (homogeneous) {
      if (xyz[3] == 0.0) return fail("vertex " + std::to_string(i) + ": homogeneous w is 0");
      for (int k = 0; k < 3; ++k) xyz[k] /= xyz[3];
    }
    mesh_.positions.emplace_back(xyz[0], xyz[1], xyz[2]);
  }

  PolyMesh& m = mesh_;
  m.face_offsets.reserve(std::min(nf, static_cast<std::uint64_t>(end_ - p_) / 8) + 1);
  std::vector<Index> scratch;
  for (std::uint64_t i = 0; i < nf; ++i) {
    if (!next_line(b, e))
      return fail("file ends after " + std::to_string(i) + " of " + std::to_string(nf) + " faces");
    std::uint64_t k = 0;
    if (!count_token(b, e, k)) return fail("face " + std::to_string(i) + ": bad corner count");
    if (k > static_cast<std::uint64_t>(e - b) / 2)
      return fail("face " + std::to_string(i) + ": " + std::to_string(k) + " corners announced, fewer given");
    const std::size_t first = m.corner_vertex.size();
    if (first + k >= kInvalidIndex) return fail("too many face corners for 32-bit indices");
    for (std::uint64_t j = 0; j < k; ++j) {
      std::uint64_t v = 0;
      if (!count_token(b, e, v))
        return fail("face " + std::to_string(i) + ": bad or missing vertex index (" + std::to_string(k) + " announced)");
      if (v >= nv)
        return fail("face " + std::to_string(i) + ": vertex index " + std::to_string(v) + " out of range (" +
                    std::to_string(nv) + " vertices)");
      m.corner_vertex.push_back(static_cast<Index>(v));
    }
    Index repeated = kInvalidIndex;
    const FaceProblem problem =
        check_face(m.corner_vertex.data() + first, k, options_.allow_repeated_vertex, scratch, repeated);
    if (problem != FaceProblem::None)
      return fail("face " + std::to_string(i) + " " + describe_face_problem(problem, k, repeated, 0));
    m.face_offsets.push_back(static_cast<Index>(m.corner_vertex.size()));
  }
  if (m.num_faces() == 0) {
    result_.error = name_ + ": no faces";
    return false;
  }
  return true;
}

}  // namespace

namespace io_detail {

ReadResult parse_off(std::string_view text, const std::string& name, const ReadOptions& options) {
  const Stopwatch clock;
  ReadResult result;
  OffParser parser(text, name, options, result);
  if (!parser.run()) result.mesh = PolyMesh{};
  result.seconds = clock.seconds();
  return result;
}

bool format_off(const PolyMesh& mesh, const WriteOptions& options, std::string& out,
                std::string& error) {
  if (std::string e = mesh.check_layout(); !e.empty()) {
    error = "invalid mesh: " + e;
    return false;
  }
  const int precision = clamp_precision(options.precision);
  out.clear();
  out.reserve(mesh.positions.size() * 3 * (precision + 8) + mesh.corner_vertex.size() * 8 +
              mesh.face_offsets.size() * 4 + 64);
  out += "OFF\n";
  append_uint(out, mesh.num_vertices());
  out += ' ';
  append_uint(out, mesh.num_faces());
  out += " 0\n";
  for (const Vec3& p : mesh.positions) {
    for (int k = 0; k < 3; ++k) {
      if (k) out += ' ';
      append_double(out, p[k], precision);
    }
    out += '\n';
  }
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    append_uint(out, mesh.face_size(f));
    for (const Index v : mesh.face_vertices(f)) {
      out += ' ';
      append_uint(out, v);
    }
    out += '\n';
  }
  return true;
}

}  // namespace io_detail

ReadResult read_off(const std::filesystem::path& path, const ReadOptions& options) {
  return read_and_parse(path, options, parse_off);
}

WriteResult write_off(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options) {
  WriteResult r = format_and_write(mesh, path, options, format_off);
  if (!r.ok()) return r;
  // OFF holds positions and faces only.
  if (mesh.has_uvs())
    r.warnings.push_back(path.string() + ": OFF has no texture coordinates; " + std::to_string(mesh.uv_sets.size()) +
                         " UV set(s) dropped (write OBJ or PLY to keep them)");
  if (mesh.has_normals()) r.warnings.push_back(path.string() + ": OFF has no normals; dropped (write OBJ to keep them)");
  if (!mesh.vertex_colors.empty())
    r.warnings.push_back(path.string() + ": OFF as written here has no vertex colours; dropped (write OBJ or PLY to keep them)");
  warn_dropped_tags(mesh, path, "OFF", r.warnings);
  return r;
}

}  // namespace quadlod
