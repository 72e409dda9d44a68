// quadlod — Wavefront OBJ reader and writer.
//
// Reader: the whole file is parsed in memory in one pass, statement by statement, with
// std::from_chars for numbers and no allocation per face (corners go straight into the mesh's
// CSR arrays). Kept: v (x y z [w] | x y z r g b), vt (u [v [w]]), vn, f/fo in all four corner
// forms with absolute or negative (relative) indices, and the o / g / usemtl / s / mtllib
// statements as per-face tags so a read → write → read round trip reproduces the PolyMesh.
// Skipped and counted in ReadResult::ignored_records: l, p, vp, free-form geometry and any
// unknown statement.
//
// Positive indices may refer forward (to elements defined later in the file); they are checked
// once the whole file is read, and the error names the line of the first offending face.
// Negative indices are relative to what is defined so far and are checked immediately.
//
// Writer: the inverse; tags are emitted where they change between consecutive faces.
#include "io/io_common.h"
#include "util/parallel.h"

#include <algorithm>
#include <unordered_map>

namespace quadlod {

using namespace io_detail;

namespace {

// OBJ cannot say "no material" (or group, object) for a face after one that has one: usemtl
// holds until the next usemtl, and Blender 3.4's importer keeps the previous material even for an
// empty `usemtl` (checked: `usemtl A`, face, `usemtl`, face → both faces A). Blender's own OBJ
// exporter (io_scene_obj, export_obj.py) writes `usemtl (null)` for faces without a material, so
// the writer does the same for all three tags and the reader reads "(null)" as no tag. Blender
// imports `usemtl (null)` as a separate slot named "(null)": not the previous material.
constexpr std::string_view kNullTag = "(null)";

// A per-face name tag (o, g, usemtl). The name is interned when the first face after the
// statement is read, so the name table lists names in order of first use by a face and a
// name that no face uses never enters it; that is what makes the round trip exact.
// The name kNullTag ends the tag: the faces after it have none (kInvalidIndex).
struct NameTag {
  std::string pending;
  bool dirty = false;
  Index current = kInvalidIndex;
  std::unordered_map<std::string, Index> ids;

  void set(std::string_view name) {
    pending.assign(name);
    dirty = true;
  }
  void apply(std::vector<std::string>& names, std::vector<Index>& per_face, Index face) {
    if (dirty) {
      dirty = false;
      if (pending == kNullTag) {
        current = kInvalidIndex;
      } else {
        const auto [it, inserted] = ids.try_emplace(pending, static_cast<Index>(names.size()));
        if (inserted) names.push_back(pending);
        current = it->second;
      }
    }
    if (current == kInvalidIndex) return;
    if (per_face.size() < face) per_face.resize(face, kInvalidIndex);  // first tagged face
    per_face.push_back(current);
  }
};

// Largest 1-based indices of a face that referred past what was defined when it was read.
struct ForwardReference {
  std::uint64_t line;
  std::uint64_t vertex, uv, normal;  // 0 when that kind did not refer forward
};

std::string_view shorten(const char* p, const char* end) {
  const auto n = std::min<std::ptrdiff_t>(end - p, 40);
  return {p, static_cast<std::size_t>(n)};
}

class ObjParser {
 public:
  ObjParser(std::string_view text, const std::string& name, const ReadOptions& options,
            ReadResult& result)
      : text_(text), name_(name), options_(options), mesh_(result.mesh), result_(result) {}

  bool run();

 private:
  bool fail(const std::string& message) {
    result_.error = name_ + ":" + std::to_string(line_) + ": " + message;
    return false;
  }
  void reserve(const char* p, const char* end);
  bool statement(const char* p, const char* end);
  bool vertex(const char* p, const char* end);
  bool texcoord(const char* p, const char* end);
  bool normal(const char* p, const char* end);
  bool face(const char* p, const char* end);
  bool smoothing(std::string_view arg);
  bool resolve(std::int64_t raw, std::size_t defined, const char* kind, Index& out,
               std::uint64_t& forward) {
    if (raw > 0 && static_cast<std::uint64_t>(raw) <= defined) {  // the common case
      out = static_cast<Index>(raw - 1);
      return true;
    }
    return resolve_rare(raw, defined, kind, out, forward);
  }
  bool resolve_rare(std::int64_t raw, std::size_t defined, const char* kind, Index& out,
                    std::uint64_t& forward);
  bool check_forward_references();

  // Reads up to `max` numbers of a v/vt/vn statement into `values`; returns the count or -1.
  int numbers(const char* p, const char* end, double* values, int max, const char* what);

  std::string_view text_;
  const std::string& name_;
  const ReadOptions& options_;
  PolyMesh& mesh_;
  ReadResult& result_;

  std::uint64_t line_ = 0;
  std::string joined_;          // a statement continued over several lines ('\' at line end)
  std::vector<Index> scratch_;  // check_face on large n-gons
  NameTag object_, group_, material_;
  bool smoothing_seen_ = false;
  Index smoothing_ = 0;
  std::vector<ForwardReference> forward_;
  UvSet uv_;  // `vt` pool and per-corner indices; becomes uv_sets[0] when a face uses it
};

bool ObjParser::run() {
  const char* p = text_.data();
  const char* const end = p + text_.size();

  // Binary data in a text format would otherwise come out as a puzzling "no faces".
  if (const void* nul = std::memchr(p, '\0', text_.size())) {
    line_ = 1 + static_cast<std::uint64_t>(std::count(p, static_cast<const char*>(nul), '\n'));
    return fail("NUL byte: not a text file");
  }
  if (end - p >= 3 && std::memcmp(p, "\xEF\xBB\xBF", 3) == 0) p += 3;  // UTF-8 byte order mark

  reserve(p, end);

  std::uint64_t next_line = 1;
  while (p < end) {
    line_ = next_line++;
    const char* eol = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    if (!eol) eol = end;

    // Continuation: a backslash ending the line joins the next one. Comment lines are exempt
    // so that a comment quoting a Windows directory ("# from C:\models\") cannot swallow the
    // statement after it.
    const char* last = eol;
    while (last > p && is_blank(last[-1])) --last;
    const char* first = skip_blanks(p, eol);
    if (last > first && last[-1] == '\\' && *first != '#') {
      joined_.assign(first, last - 1);
      const char* q = eol;
      while (q < end) {
        q += 1;  // past '\n'
        const char* e = static_cast<const char*>(std::memchr(q, '\n', static_cast<std::size_t>(end - q)));
        if (!e) e = end;
        ++next_line;
        const char* l = e;
        while (l > q && is_blank(l[-1])) --l;
        joined_ += ' ';
        if (l > q && l[-1] == '\\') {
          joined_.append(q, l - 1);
          q = e;
          continue;
        }
        joined_.append(q, e);
        q = e;
        break;
      }
      if (!statement(joined_.data(), joined_.data() + joined_.size())) return false;
      p = q < end ? q + 1 : end;
      continue;
    }
    if (!statement(first, eol)) return false;
    p = eol < end ? eol + 1 : end;
  }

  if (!check_forward_references()) return false;
  if (mesh_.num_faces() == 0) {
    result_.error = name_ + ": no faces";
    return false;
  }
  // Corners after the last one with a value have none.
  if (!uv_.corner.empty()) {
    uv_.corner.resize(mesh_.num_corners(), kInvalidIndex);
    mesh_.uv_sets.push_back(std::move(uv_));
  }
  if (!mesh_.corner_normal.empty()) mesh_.corner_normal.resize(mesh_.num_corners(), kInvalidIndex);
  // Faces after a tag was ended (kNullTag) have none.
  for (std::vector<Index>* tags : {&mesh_.face_object, &mesh_.face_group, &mesh_.face_material})
    if (!tags->empty()) tags->resize(mesh_.num_faces(), kInvalidIndex);
  return true;
}

// Sizes the arrays from a quick count of statement keywords at line starts: letting them grow
// by doubling copies each about twice over and faults in pages that are then thrown away. The
// count is an estimate (indented statements are missed) and only affects capacity.
void ObjParser::reserve(const char* p, const char* end) {
  const char* const begin = p;
  std::size_t v = 0, vt = 0, vn = 0, f = 0;
  while (p < end) {
    if (*p == 'v' && p + 1 < end) {
      const char c = p[1];
      v += c == ' ' || c == '\t';
      vt += c == 't';
      vn += c == 'n';
    } else {
      f += *p == 'f';
    }
    p = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    if (!p) break;
    ++p;
  }
  mesh_.positions.reserve(v);
  uv_.values.reserve(vt);
  mesh_.normals.reserve(vn);
  mesh_.face_offsets.reserve(f + 1);
  // Quad-dominant input; a corner takes at least 2 bytes, which bounds what junk can reserve.
  mesh_.corner_vertex.reserve(std::min(4 * f, static_cast<std::size_t>(end - begin) / 2));
}

bool ObjParser::statement(const char* p, const char* end) {
  p = skip_blanks(p, end);
  if (p == end || *p == '#') return true;
  const char* kw_end = skip_token(p, end);
  const std::string_view kw(p, static_cast<std::size_t>(kw_end - p));
  const char* args = skip_blanks(kw_end, end);

  if (kw == "v") return vertex(args, end);
  if (kw == "f") return face(args, end);
  if (kw == "vt") return texcoord(args, end);
  if (kw == "vn") return normal(args, end);

  // Name-like arguments keep everything up to the end of the line: material and group names
  // exported by 3ds Max and others contain '#' and spaces.
  const char* rest_end = end;
  while (rest_end > args && is_blank(rest_end[-1])) --rest_end;
  const std::string_view rest(args, static_cast<std::size_t>(rest_end - args));

  if (kw == "fo") return face(args, end);  // pre-3.0 spelling of f
  if (kw == "o") object_.set(rest);
  else if (kw == "g") group_.set(rest);
  else if (kw == "usemtl") material_.set(rest);
  else if (kw == "s") return smoothing(rest);
  else if (kw == "mtllib") {
    if (!rest.empty()) mesh_.material_libraries.emplace_back(rest);
  } else ++result_.ignored_records;  // l, p, vp, curves, surfaces, unknown statements
  return true;
}

int ObjParser::numbers(const char* p, const char* end, double* values, int max, const char* what) {
  int n = 0;
  for (;;) {
    p = skip_blanks(p, end);
    if (p == end || *p == '#') return n;
    if (n == max) {
      fail(std::string("too many values in ") + what + " (at most " + std::to_string(max) + ")");
      return -1;
    }
    const char* token_end = skip_token(p, end);
    const char* next = nullptr;
    if (!parse_double_token(p, token_end, values[n], next)) {
      fail(std::string("bad number '") + std::string(shorten(p, token_end)) + "' in " + what);
      return -1;
    }
    if (!std::isfinite(values[n])) {
      fail(std::string("non-finite value '") + std::string(shorten(p, token_end)) + "' in " + what);
      return -1;
    }
    ++n;
    p = next;
  }
}

bool ObjParser::vertex(const char* p, const char* end) {
  double v[7];
  const int n = numbers(p, end, v, 6, "vertex");
  if (n < 0) return false;
  if (n < 3) return fail("vertex has " + std::to_string(n) + " coordinates (3 needed)");
  if (n == 5) return fail("vertex has 5 values (expected x y z [w] or x y z r g b)");
  if (mesh_.positions.size() + 1 >= kInvalidIndex) return fail("too many vertices for 32-bit indices");
  mesh_.positions.emplace_back(v[0], v[1], v[2]);
  if (n == 6) {
    // Vertices before the first coloured one get white, the usual default of OBJ viewers.
    if (mesh_.vertex_colors.size() + 1 < mesh_.positions.size())
      mesh_.vertex_colors.resize(mesh_.positions.size() - 1, Vec3::Ones());
    mesh_.vertex_colors.emplace_back(v[3], v[4], v[5]);
  } else if (!mesh_.vertex_colors.empty()) {
    mesh_.vertex_colors.emplace_back(Vec3::Ones());
  }
  return true;
}

bool ObjParser::texcoord(const char* p, const char* end) {
  double v[3] = {0.0, 0.0, 0.0};
  const int n = numbers(p, end, v, 3, "texture coordinate");
  if (n < 0) return false;
  if (n < 1) return fail("texture coordinate has no values");
  uv_.values.emplace_back(v[0], v[1]);  // w (3D textures) is dropped
  return true;
}

bool ObjParser::normal(const char* p, const char* end) {
  double v[3];
  const int n = numbers(p, end, v, 3, "normal");
  if (n < 0) return false;
  if (n != 3) return fail("normal has " + std::to_string(n) + " values (3 needed)");
  mesh_.normals.emplace_back(v[0], v[1], v[2]);
  return true;
}

bool ObjParser::smoothing(std::string_view arg) {
  std::int64_t value = 0;
  const char* next = nullptr;
  if (arg == "off") value = 0;
  else if (arg == "on") value = 1;  // not in the specification, but some exporters write it
  else if (!parse_int64(arg.data(), arg.data() + arg.size(), value, next) ||
           next != arg.data() + arg.size() || value < 0 || value > 0xFFFFFFFFll)
    return fail("bad smoothing group '" + std::string(arg.substr(0, 40)) + "'");
  smoothing_seen_ = true;
  smoothing_ = static_cast<Index>(value);
  return true;
}

// Turns a 1-based or negative OBJ index into a 0-based one. Positive indices beyond what is
// defined so far are legal OBJ only if the element appears later; `forward` records the
// largest such 1-based index for the end-of-file check.
bool ObjParser::resolve_rare(std::int64_t raw, std::size_t defined, const char* kind, Index& out,
                             std::uint64_t& forward) {
  if (raw > 0) {
    if (raw >= static_cast<std::int64_t>(kInvalidIndex))
      return fail(std::string("face refers to ") + kind + " " + std::to_string(raw) +
                  ", beyond the 32-bit index range");
    out = static_cast<Index>(raw - 1);
    if (static_cast<std::uint64_t>(raw) > defined)
      forward = std::max(forward, static_cast<std::uint64_t>(raw));
    return true;
  }
  if (raw == 0) return fail(std::string("face refers to ") + kind + " 0 (OBJ indices start at 1)");
  if (static_cast<std::uint64_t>(-raw) > defined)
    return fail(std::string("face refers to ") + kind + " " + std::to_string(raw) + " but only " +
                std::to_string(defined) + " are defined before it");
  out = static_cast<Index>(static_cast<std::int64_t>(defined) + raw);
  return true;
}

bool ObjParser::face(const char* p, const char* end) {
  PolyMesh& m = mesh_;
  const std::size_t first = m.corner_vertex.size();
  if (first + (static_cast<std::size_t>(end - p) / 2 + 1) >= kInvalidIndex)
    return fail("too many face corners for 32-bit indices");
  ForwardReference fwd{line_, 0, 0, 0};

  for (;;) {
    p = skip_blanks(p, end);
    if (p == end || *p == '#') break;
    const char* token = p;
    const auto bad_corner = [&] {
      return fail("bad face corner '" + std::string(shorten(token, skip_token(token, end))) + "'");
    };

    // v | v/vt | v//vn | v/vt/vn; an empty field ("v/", "v/vt/") means absent.
    std::int64_t raw = 0;
    Index v = kInvalidIndex, vt = kInvalidIndex, vn = kInvalidIndex;
    if (!parse_int64(p, end, raw, p)) return bad_corner();
    if (!resolve(raw, m.positions.size(), "vertex", v, fwd.vertex)) return false;
    if (p < end && *p == '/') {
      ++p;
      if (p < end && *p != '/' && !is_blank(*p)) {
        if (!parse_int64(p, end, raw, p)) return bad_corner();
        if (!resolve(raw, uv_.values.size(), "texture coordinate", vt, fwd.uv)) return false;
      }
      if (p < end && *p == '/') {
        ++p;
        if (p < end && !is_blank(*p)) {
          if (!parse_int64(p, end, raw, p)) return bad_corner();
          if (!resolve(raw, m.normals.size(), "normal", vn, fwd.normal)) return false;
        }
      }
    }
    if (p < end && !is_blank(*p)) return bad_corner();

    // The per-corner arrays appear with the first corner that has a value; earlier corners
    // are back-filled with kInvalidIndex (resize is a no-op once the array has caught up).
    const std::size_t c = m.corner_vertex.size();
    m.corner_vertex.push_back(v);
    if (vt != kInvalidIndex || !uv_.corner.empty()) {
      if (uv_.corner.empty()) uv_.corner.reserve(m.corner_vertex.capacity());
      uv_.corner.resize(c, kInvalidIndex);
      uv_.corner.push_back(vt);
    }
    if (vn != kInvalidIndex || !m.corner_normal.empty()) {
      if (m.corner_normal.empty()) m.corner_normal.reserve(m.corner_vertex.capacity());
      m.corner_normal.resize(c, kInvalidIndex);
      m.corner_normal.push_back(vn);
    }
  }

  const std::size_t count = m.corner_vertex.size() - first;
  Index repeated = kInvalidIndex;
  const FaceProblem problem = check_face(m.corner_vertex.data() + first, count,
                                         options_.allow_repeated_vertex, scratch_, repeated);
  if (problem != FaceProblem::None) return fail("face " + describe_face_problem(problem, count, repeated, 1));
  if (m.face_offsets.size() >= kInvalidIndex) return fail("too many faces for 32-bit indices");

  const Index f = m.num_faces();
  m.face_offsets.push_back(static_cast<Index>(m.corner_vertex.size()));
  object_.apply(m.object_names, m.face_object, f);
  group_.apply(m.group_names, m.face_group, f);
  material_.apply(m.material_names, m.face_material, f);
  if (smoothing_seen_) {
    if (m.face_smoothing.size() < f) m.face_smoothing.resize(f, 0);
    m.face_smoothing.push_back(smoothing_);
  }
  if (fwd.vertex | fwd.uv | fwd.normal) forward_.push_back(fwd);
  return true;
}

bool ObjParser::check_forward_references() {
  const auto check = [&](std::uint64_t ref, std::size_t defined, const char* kind) {
    if (ref <= defined) return true;
    return fail(std::string("face refers to ") + kind + " " + std::to_string(ref) + " but only " +
                std::to_string(defined) + " are defined");
  };
  for (const ForwardReference& r : forward_) {
    line_ = r.line;
    if (!check(r.vertex, mesh_.positions.size(), "vertex") ||
        !check(r.uv, uv_.values.size(), "texture coordinate") ||
        !check(r.normal, mesh_.normals.size(), "normal"))
      return false;
  }
  return true;
}

// --- writer -------------------------------------------------------------------------------

bool writable_name(std::string_view s) {
  // A line break would end the statement early; a trailing backslash would join the next line.
  return s.find_first_of("\r\n") == std::string_view::npos && (s.empty() || s.back() != '\\');
}

}  // namespace

ReadResult parse_obj(std::string_view text, const std::string& name, const ReadOptions& options) {
  const Stopwatch clock;
  ReadResult result;
  ObjParser parser(text, name, options, result);
  if (!parser.run()) result.mesh = PolyMesh{};
  result.seconds = clock.seconds();
  return result;
}

ReadResult read_obj(const std::filesystem::path& path, const ReadOptions& options) {
  return read_and_parse(path, options, parse_obj);
}

namespace io_detail {

// Below this many lines of a kind, one thread formats them (a thread costs more than it saves).
constexpr std::size_t kMinParallelLines = 100000;

bool format_obj(const PolyMesh& mesh, const WriteOptions& options, std::string& out,
                std::string& error) {
  if (std::string e = mesh.check_layout(); !e.empty()) {
    error = "invalid mesh: " + e;
    return false;
  }
  for (const auto* table : {&mesh.object_names, &mesh.group_names, &mesh.material_names,
                            &mesh.material_libraries})
    for (const std::string& s : *table)
      if (!writable_name(s)) {
        error = "name '" + s.substr(0, 40) + "' cannot be written to OBJ (line break or trailing backslash)";
        return false;
      }

  const int precision = clamp_precision(options.precision);
  const bool colors = !mesh.vertex_colors.empty();
  out.clear();
  out.reserve(mesh.positions.size() * (colors ? 6 : 3) * (precision + 8) +
              (mesh.has_uvs() ? mesh.uv_sets[0].values.size() : 0) * 2 * (precision + 8) + mesh.normals.size() * 3 * (precision + 8) +
              mesh.corner_vertex.size() * 24 + mesh.face_offsets.size() * 4 + 256);

  out += "# quadlod: ";
  append_uint(out, mesh.num_vertices());
  out += " vertices, ";
  append_uint(out, mesh.num_faces());
  out += " faces\n";
  for (const std::string& lib : mesh.material_libraries) {
    out += "mtllib ";
    out += lib;
    out += '\n';
  }
  // Lines in chunks on all threads, joined in order: the same bytes for any thread count (a
  // 1M-face mesh's text is 50 MB; formatting its numbers was most of its 0.75 s write, issue 20).
  const auto append_vec = [precision](std::string& to, const char* keyword, const double* v, int n) {
    to += keyword;
    for (int i = 0; i < n; ++i) {
      to += ' ';
      append_double(to, v[i], precision);
    }
  };
  const auto in_chunks = [&out](std::size_t n, auto&& line) {
    std::vector<std::string> parts(thread_count(0));
    const std::size_t chunks = parallel_chunks(n, 0, kMinParallelLines, [&](std::size_t b, std::size_t e, std::size_t k) {
      std::string& to = k == 0 ? out : parts[k];  // chunk 0 straight into the output
      for (std::size_t i = b; i < e; ++i) line(to, i);
    });
    for (std::size_t k = 1; k < chunks; ++k) out += parts[k];
  };
  in_chunks(mesh.positions.size(), [&](std::string& to, std::size_t i) {
    append_vec(to, "v", mesh.positions[i].data(), 3);
    if (colors) append_vec(to, "", mesh.vertex_colors[i].data(), 3);
    to += '\n';
  });
  // OBJ has one texture-coordinate set; further sets need PLY (write_mesh warns).
  if (mesh.has_uvs())
    in_chunks(mesh.uv_sets[0].values.size(), [&](std::string& to, std::size_t i) {
      append_vec(to, "vt", mesh.uv_sets[0].values[i].data(), 2);
      to += '\n';
    });
  in_chunks(mesh.normals.size(), [&](std::string& to, std::size_t i) {
    append_vec(to, "vn", mesh.normals[i].data(), 3);
    to += '\n';
  });

  // A name statement where a face's tag differs from the face before it (none before the first:
  // untagged leading faces need no statement), so a chunk needs only the tag before its start.
  const auto emit_name = [](std::string& to, const std::vector<Index>& tags, const std::vector<std::string>& names,
                            std::size_t f, const char* keyword) {
    if (tags.empty()) return;
    const Index t = tags[f];
    const Index previous = f == 0 ? kInvalidIndex : tags[f - 1];
    if (t == previous) return;
    to += keyword;
    const std::string_view name = t == kInvalidIndex ? kNullTag : std::string_view(names[t]);
    if (!name.empty()) {
      to += ' ';
      to += name;
    }
    to += '\n';
  };
  const bool uvs = mesh.has_uvs(), normals = mesh.has_normals();
  in_chunks(std::size_t(mesh.num_faces()), [&](std::string& to, std::size_t fi) {
    const Index f = Index(fi);
    emit_name(to, mesh.face_object, mesh.object_names, fi, "o");
    emit_name(to, mesh.face_group, mesh.group_names, fi, "g");
    emit_name(to, mesh.face_material, mesh.material_names, fi, "usemtl");
    if (!mesh.face_smoothing.empty() && (f == 0 || mesh.face_smoothing[f] != mesh.face_smoothing[f - 1])) {
      to += "s ";
      if (mesh.face_smoothing[f] == 0) to += "off";
      else append_uint(to, mesh.face_smoothing[f]);
      to += '\n';
    }
    to += 'f';
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) {
      to += ' ';
      append_uint(to, std::uint64_t{mesh.corner_vertex[c]} + 1);
      const Index t = uvs ? mesh.uv_sets[0].corner[c] : kInvalidIndex;
      const Index n = normals ? mesh.corner_normal[c] : kInvalidIndex;
      if (t != kInvalidIndex) {
        to += '/';
        append_uint(to, std::uint64_t{t} + 1);
      }
      if (n != kInvalidIndex) {
        to += t != kInvalidIndex ? "/" : "//";
        append_uint(to, std::uint64_t{n} + 1);
      }
    }
    to += '\n';
  });
  return true;
}

}  // namespace io_detail

std::vector<std::string> rebase_material_libraries(PolyMesh& mesh, const std::filesystem::path& input,
                                                   const std::filesystem::path& output) {
  namespace fs = std::filesystem;
  std::vector<std::string> warnings;
  std::error_code ec;
  const fs::path from = fs::weakly_canonical(fs::absolute(input, ec).parent_path(), ec);
  const fs::path to = fs::weakly_canonical(fs::absolute(output, ec).parent_path(), ec);
  if (ec || from == to) return warnings;
  // One library: relative to `to` when it exists next to the input, else unchanged.
  auto rebase = [&](const std::string& lib) -> std::string {
    const fs::path p(lib);
    if (p.is_absolute()) return lib;
    std::error_code e;
    const fs::path target = fs::weakly_canonical(from / p, e);
    if (e || !fs::is_regular_file(target, e)) {
      warnings.push_back("material library '" + lib + "' not found next to " + input.string() +
                         "; the output's mtllib line keeps it unchanged");
      return lib;
    }
    const fs::path rel = target.lexically_relative(to);
    return (rel.empty() ? target : rel).generic_string();
  };
  for (std::string& line : mesh.material_libraries) {
    std::error_code e;
    // The whole argument first (a file name with spaces), then its space-separated names.
    if (fs::is_regular_file(from / fs::path(line), e) || line.find_first_of(" \t") == std::string::npos) {
      line = rebase(line);
      continue;
    }
    std::string rebuilt;
    std::size_t i = 0;
    while (i < line.size()) {
      const std::size_t b = line.find_first_not_of(" \t", i);
      if (b == std::string::npos) break;
      const std::size_t e2 = std::min(line.find_first_of(" \t", b), line.size());
      if (!rebuilt.empty()) rebuilt += ' ';
      rebuilt += rebase(line.substr(b, e2 - b));
      i = e2;
    }
    line = rebuilt;
  }
  return warnings;
}

WriteResult write_obj(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options) {
  WriteResult r = format_and_write(mesh, path, options, format_obj);
  if (r.ok() && mesh.uv_sets.size() > 1)
    r.warnings.push_back(path.string() + ": OBJ holds one UV set; " +
                         std::to_string(mesh.uv_sets.size() - 1) + " further set(s) dropped (write PLY to keep them)");
  return r;
}

}  // namespace quadlod
