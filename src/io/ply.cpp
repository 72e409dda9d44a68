// quadlod — PLY reader and writer (ascii, binary_little_endian, binary_big_endian).
//
// Reader: any element/property layout with the eight scalar types (and their int8/uint8/...
// aliases). Used: `vertex` x y z, nx ny nz (per-vertex normals), s t | u v | texture_u
// texture_v | texture_s texture_t (per-vertex UVs), red green blue; `face` vertex_indices (or
// vertex_index) and MeshLab's per-face `texcoord` list (2 floats per corner), plus further UV
// sets as lists `texcoord1`, `texcoord2`, … (our extension, one UV set each). Per-vertex
// attributes become per-corner pools indexed by the corner's vertex. Everything else, lists
// included, is skipped. Counts in the header are never trusted for allocation: reservations are
// capped by what the remaining bytes can hold, so a header claiming 4e9 vertices in a 100-byte
// file fails with "truncated" after a few elements.
//
// Writer: float x y z; nx ny nz when every vertex has one normal shared by all its corners
// (per-corner normals have no portable PLY form and are otherwise dropped); uchar red green
// blue; `list uchar int vertex_indices` (wider count type for faces over 255 corners) and, with
// UVs, `list uchar float texcoord` (then `texcoord1`, … for further UV sets; set names other
// than these are not kept). A face whose corners all lack UVs gets an empty texcoord list,
// a partial one gets NaN pairs for the missing corners, which the reader maps back to "no UV".
// Tags (o, g, usemtl, s) have no PLY form and are not written; the WriteResult warns per kind.
#include "io/io_common.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>

namespace quadlod {

using namespace io_detail;

namespace {

enum class PlyType : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

constexpr std::size_t type_size(PlyType t) {
  constexpr std::array<std::size_t, 8> sizes{1, 1, 2, 2, 4, 4, 4, 8};
  return sizes[static_cast<std::size_t>(t)];
}
constexpr bool is_integer(PlyType t) { return t < PlyType::Float32; }

bool type_from_name(std::string_view s, PlyType& t) {
  static constexpr std::pair<std::string_view, PlyType> kNames[] = {
      {"char", PlyType::Int8},     {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},   {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16}, {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},   {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const auto& [name, type] : kNames)
    if (name == s) {
      t = type;
      return true;
    }
  return false;
}

// Largest value of an unsigned integer type, used to map integer colour channels to [0,1].
double colour_scale(PlyType t) {
  switch (t) {
    case PlyType::Int8: return 127.0;
    case PlyType::UInt8: return 255.0;
    case PlyType::Int16: return 32767.0;
    case PlyType::UInt16: return 65535.0;
    case PlyType::Int32: return 2147483647.0;
    case PlyType::UInt32: return 4294967295.0;
    default: return 1.0;
  }
}

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;
  PlyType type = PlyType::Float32;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;

  int find(std::string_view n) const {
    for (std::size_t i = 0; i < properties.size(); ++i)
      if (properties[i].name == n) return static_cast<int>(i);
    return -1;
  }
  // Fewest bytes one element can occupy; caps reservations against the bytes left.
  std::size_t min_bytes(bool ascii) const {
    std::size_t n = 0;
    for (const PlyProperty& p : properties)
      n += ascii ? 2 : (p.is_list ? type_size(p.count_type) : type_size(p.type));
    return std::max<std::size_t>(n, 1);
  }
};

std::string plural(const std::string& element) {
  return element == "vertex" ? "vertices" : element + (element.back() == 's' ? "es" : "s");
}

enum class Status { Ok, Truncated, Malformed };

// Binary values, byte-swapped when the file's endianness differs from the machine's.
class BinaryReader {
 public:
  BinaryReader(const char* p, const char* end, bool swap) : p_(p), end_(end), swap_(swap) {}

  Status scalar(PlyType t, double& v) {
    const std::size_t n = type_size(t);
    if (static_cast<std::size_t>(end_ - p_) < n) return Status::Truncated;
    unsigned char b[8];
    std::memcpy(b, p_, n);
    if (swap_) std::reverse(b, b + n);
    p_ += n;
    switch (t) {
      case PlyType::Int8: v = static_cast<std::int8_t>(b[0]); break;
      case PlyType::UInt8: v = b[0]; break;
      case PlyType::Int16: v = load<std::int16_t>(b); break;
      case PlyType::UInt16: v = load<std::uint16_t>(b); break;
      case PlyType::Int32: v = load<std::int32_t>(b); break;
      case PlyType::UInt32: v = load<std::uint32_t>(b); break;
      case PlyType::Float32: v = load<float>(b); break;
      case PlyType::Float64: v = load<double>(b); break;
    }
    return Status::Ok;
  }
  Status skip(PlyType t, std::uint64_t count) {
    const std::uint64_t left = static_cast<std::uint64_t>(end_ - p_) / type_size(t);
    if (count > left) return Status::Truncated;
    p_ += count * type_size(t);
    return Status::Ok;
  }
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }
  std::string bad_token() const { return {}; }

 private:
  template <class T>
  static T load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return v;
  }
  const char* p_;
  const char* end_;
  bool swap_;
};

// Whitespace-separated tokens; line structure is not needed to read the values in order.
class AsciiReader {
 public:
  AsciiReader(const char* p, const char* end) : p_(p), end_(end) {}

  Status scalar(PlyType t, double& v) {
    while (p_ < end_ && is_space(*p_)) ++p_;
    if (p_ == end_) return Status::Truncated;
    token_ = p_;
    const char* token_end = skip_token(p_, end_);
    const char* next = nullptr;
    if (is_integer(t)) {
      std::int64_t i = 0;
      if (!parse_int64(p_, token_end, i, next) || next != token_end) {
        // Some writers print integer properties as "3.0"; accept integral values.
        if (!parse_double_token(p_, token_end, v, next) || v != std::floor(v) ||
            std::fabs(v) > 9007199254740992.0)  // 2^53: beyond it integers are not exact
          return Status::Malformed;
      } else {
        v = static_cast<double>(i);
      }
    } else if (!parse_double_token(p_, token_end, v, next)) {
      return Status::Malformed;
    } else if (t == PlyType::Float32 && std::isfinite(v)) {
      // A float property holds a float: "0.3" must read as 0.3f, as it does in binary files.
      // Beyond float's range: what IEEE rounding gives, without an out-of-range conversion —
      // FLT_MAX up to half an ulp above it (the shortest text of FLT_MAX, "3.4028235e+38", is
      // above it), infinite from there (a fuzz finding: FLT_MAX did not survive an ascii trip).
      constexpr double kFloatMax = std::numeric_limits<float>::max();
      constexpr double kFloatOverflow = 0x1.ffffffp127;  // FLT_MAX + half an ulp: rounds to inf
      const double a = std::fabs(v);
      v = a <= kFloatMax ? double(static_cast<float>(v))
                         : std::copysign(a < kFloatOverflow ? kFloatMax : HUGE_VAL, v);
    }
    p_ = token_end;
    return Status::Ok;
  }
  Status skip(PlyType t, std::uint64_t count) {
    double v;
    for (std::uint64_t i = 0; i < count; ++i)
      if (const Status s = scalar(t, v); s != Status::Ok) return s;
    return Status::Ok;
  }
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }
  std::string bad_token() const {
    const char* e = skip_token(token_, end_);
    return std::string(token_, static_cast<std::size_t>(std::min<std::ptrdiff_t>(e - token_, 40)));
  }

 private:
  const char* p_;
  const char* end_;
  const char* token_ = nullptr;
};

class PlyParser {
 public:
  PlyParser(std::string_view data, const std::string& name, const ReadOptions& options,
            ReadResult& result)
      : data_(data), name_(name), options_(options), mesh_(result.mesh), result_(result) {}

  bool run();

 private:
  bool fail(const std::string& message) {
    result_.error = name_ + ": " + message;
    return false;
  }
  bool header_fail(std::uint64_t line, const std::string& message) {
    result_.error = name_ + ":" + std::to_string(line) + ": " + message;
    return false;
  }
  bool parse_header();
  template <class Reader>
  bool read_body(Reader& reader);
  template <class Reader>
  bool read_vertices(Reader& reader, const PlyElement& e);
  template <class Reader>
  bool read_faces(Reader& reader, const PlyElement& e);
  template <class Reader>
  bool skip_element(Reader& reader, const PlyElement& e);
  template <class Reader>
  bool value_error(const Reader& reader, Status s, const PlyElement& e, std::uint64_t i);
  bool finish();

  std::string_view data_;
  const std::string& name_;
  const ReadOptions& options_;
  PolyMesh& mesh_;
  ReadResult& result_;

  PlyEncoding encoding_ = PlyEncoding::Ascii;
  std::vector<PlyElement> elements_;
  std::size_t body_offset_ = 0;

  // Per-vertex attributes and per-corner texcoords, turned into pools by finish().
  std::vector<Vec3> vertex_normals_;
  std::vector<Vec2> vertex_uvs_;
  // One per face list `texcoord`, `texcoord1`, …: 2 floats per corner, NaN = no UV; `values`
  // stays empty unless a face has a non-empty list.
  struct TexcoordList {
    int property = -1;
    std::string name;
    // Doubles: a `double texcoord` list (written for values beyond float's range) reads back
    // exactly; a float list's values are floats already.
    std::vector<double> values;
    std::vector<double> face;  // the current face's list (may precede vertex_indices)
    std::size_t count = 0;
  };
  std::vector<TexcoordList> corner_texcoords_;
  bool faces_seen_ = false;
};

bool PlyParser::parse_header() {
  const char* p = data_.data();
  const char* const end = p + data_.size();
  std::uint64_t line = 0;
  bool format_seen = false;
  for (;;) {
    if (p >= end) return header_fail(line, "header has no end_header line");
    ++line;
    const char* eol = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    if (!eol) eol = end;
    // Tokenise the line (the longest header line is "property list uchar int vertex_indices").
    std::string_view tok[6];
    int n = 0;
    for (const char* q = skip_blanks(p, eol); q < eol && n < 6; q = skip_blanks(q, eol)) {
      const char* t = skip_token(q, eol);
      tok[n++] = std::string_view(q, static_cast<std::size_t>(t - q));
      q = t;
    }
    p = eol < end ? eol + 1 : end;

    if (line == 1) {
      if (n != 1 || tok[0] != "ply") return header_fail(line, "not a PLY file (no 'ply' magic)");
      continue;
    }
    if (n == 0) continue;
    const std::string_view kw = tok[0];
    if (kw == "comment" || kw == "obj_info") continue;
    if (kw == "end_header") {
      if (!format_seen) return header_fail(line, "no format line before end_header");
      body_offset_ = static_cast<std::size_t>(p - data_.data());
      return true;
    }
    if (kw == "format") {
      if (n != 3) return header_fail(line, "format line needs an encoding and a version");
      if (tok[1] == "ascii") encoding_ = PlyEncoding::Ascii;
      else if (tok[1] == "binary_little_endian") encoding_ = PlyEncoding::BinaryLittleEndian;
      else if (tok[1] == "binary_big_endian") encoding_ = PlyEncoding::BinaryBigEndian;
      else return header_fail(line, "unknown format '" + std::string(tok[1]) + "'");
      format_seen = true;
    } else if (kw == "element") {
      PlyElement e;
      const char* next = nullptr;
      std::int64_t count = 0;
      if (n != 3 || !parse_int64(tok[2].data(), tok[2].data() + tok[2].size(), count, next) ||
          next != tok[2].data() + tok[2].size() || count < 0)
        return header_fail(line, "element line needs a name and a count");
      e.name = tok[1];
      e.count = static_cast<std::uint64_t>(count);
      elements_.push_back(std::move(e));
    } else if (kw == "property") {
      if (elements_.empty()) return header_fail(line, "property before any element");
      PlyProperty prop;
      if (n >= 2 && tok[1] == "list") {
        if (n != 5) return header_fail(line, "list property needs a count type, an item type and a name");
        if (!type_from_name(tok[2], prop.count_type) || !type_from_name(tok[3], prop.type))
          return header_fail(line, "unknown property type in '" + std::string(tok[2]) + " " +
                                       std::string(tok[3]) + "'");
        if (!is_integer(prop.count_type))
          return header_fail(line, "list count type must be an integer type");
        prop.is_list = true;
        prop.name = tok[4];
      } else {
        if (n != 3) return header_fail(line, "property line needs a type and a name");
        if (!type_from_name(tok[1], prop.type))
          return header_fail(line, "unknown property type '" + std::string(tok[1]) + "'");
        prop.name = tok[2];
      }
      elements_.back().properties.push_back(std::move(prop));
    } else {
      return header_fail(line, "unknown header line '" + std::string(kw.substr(0, 40)) + "'");
    }
  }
}

template <class Reader>
bool PlyParser::value_error(const Reader& reader, Status s, const PlyElement& e, std::uint64_t i) {
  if (s == Status::Truncated)
    return fail("truncated: expected " + std::to_string(e.count) + " " + plural(e.name) +
                ", file ends at " + std::to_string(i));
  return fail(e.name + " " + std::to_string(i) + ": bad number '" + reader.bad_token() + "'");
}

template <class Reader>
bool PlyParser::skip_element(Reader& reader, const PlyElement& e) {
  if (e.properties.empty()) return true;  // no data, whatever the count says
  double v = 0;
  for (std::uint64_t i = 0; i < e.count; ++i)
    for (const PlyProperty& p : e.properties) {
      if (!p.is_list) {
        if (const Status s = reader.scalar(p.type, v); s != Status::Ok) return value_error(reader, s, e, i);
        continue;
      }
      if (const Status s = reader.scalar(p.count_type, v); s != Status::Ok) return value_error(reader, s, e, i);
      if (v < 0) return fail(e.name + " " + std::to_string(i) + ": negative list length");
      if (const Status s = reader.skip(p.type, static_cast<std::uint64_t>(v)); s != Status::Ok)
        return value_error(reader, s, e, i);
    }
  return true;
}

template <class Reader>
bool PlyParser::read_vertices(Reader& reader, const PlyElement& e) {
  if (!mesh_.positions.empty()) return fail("more than one vertex element");
  const int ix = e.find("x"), iy = e.find("y"), iz = e.find("z");
  if (ix < 0 || iy < 0 || iz < 0) return fail("vertex element lacks an x, y or z property");
  const auto pick = [&](std::initializer_list<std::pair<const char*, const char*>> names, int& a, int& b) {
    for (const auto& [first, second] : names)
      if ((a = e.find(first)) >= 0 && (b = e.find(second)) >= 0) return true;
    a = b = -1;
    return false;
  };
  int inx = -1, iny = -1, inz = e.find("nz");
  const bool normals = pick({{"nx", "ny"}}, inx, iny) && inz >= 0;
  int iu = -1, iv = -1;
  const bool uvs = pick({{"s", "t"}, {"u", "v"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}}, iu, iv);
  int ir = -1, ig = -1, ib = e.find("blue");
  bool colors = pick({{"red", "green"}}, ir, ig) && ib >= 0;
  if (!colors) {
    ib = e.find("diffuse_blue");
    colors = pick({{"diffuse_red", "diffuse_green"}}, ir, ig) && ib >= 0;
  }
  for (const int i : {ix, iy, iz, inx, iny, inz, iu, iv, ir, ig, ib})
    if (i >= 0 && e.properties[static_cast<std::size_t>(i)].is_list)
      return fail("vertex property " + e.properties[static_cast<std::size_t>(i)].name + " is a list");
  if (e.count >= kInvalidIndex) return fail("too many vertices for 32-bit indices");

  const std::size_t expect = std::min<std::size_t>(e.count, reader.remaining() / e.min_bytes(encoding_ == PlyEncoding::Ascii));
  mesh_.positions.reserve(expect);
  if (normals) vertex_normals_.reserve(expect);
  if (uvs) vertex_uvs_.reserve(expect);
  if (colors) mesh_.vertex_colors.reserve(expect);
  const double cr = colour_scale(colors ? e.properties[ir].type : PlyType::Float32);
  const double cg = colour_scale(colors ? e.properties[ig].type : PlyType::Float32);
  const double cb = colour_scale(colors ? e.properties[ib].type : PlyType::Float32);

  std::vector<double> values(e.properties.size());
  for (std::uint64_t i = 0; i < e.count; ++i) {
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      if (const Status s = reader.scalar(p.is_list ? p.count_type : p.type, values[k]); s != Status::Ok)
        return value_error(reader, s, e, i);
      if (p.is_list) {
        if (values[k] < 0) return fail("vertex " + std::to_string(i) + ": negative list length");
        if (const Status s = reader.skip(p.type, static_cast<std::uint64_t>(values[k])); s != Status::Ok)
          return value_error(reader, s, e, i);
      }
    }
    const Vec3 pos(values[ix], values[iy], values[iz]);
    if (!pos.allFinite()) return fail("vertex " + std::to_string(i) + ": non-finite coordinate");
    mesh_.positions.push_back(pos);
    if (normals) vertex_normals_.emplace_back(values[inx], values[iny], values[inz]);
    if (uvs) vertex_uvs_.emplace_back(values[iu], values[iv]);
    if (colors) mesh_.vertex_colors.emplace_back(values[ir] / cr, values[ig] / cg, values[ib] / cb);
  }
  if (normals && !std::all_of(vertex_normals_.begin(), vertex_normals_.end(), [](const Vec3& n) { return n.allFinite(); }))
    return fail("vertex normals: non-finite value");
  return true;
}

template <class Reader>
bool PlyParser::read_faces(Reader& reader, const PlyElement& e) {
  if (faces_seen_) return fail("more than one face element");
  faces_seen_ = true;
  int iv = e.find("vertex_indices");
  if (iv < 0) iv = e.find("vertex_index");
  if (iv < 0 || !e.properties[static_cast<std::size_t>(iv)].is_list)
    return fail("face element has no vertex_indices list");
  for (int set = 0;; ++set) {
    const std::string name = set == 0 ? "texcoord" : "texcoord" + std::to_string(set);
    const int it = e.find(name);
    if (it < 0 || !e.properties[static_cast<std::size_t>(it)].is_list) break;
    corner_texcoords_.push_back({it, name, {}, {}, 0});
  }
  if (e.count >= kInvalidIndex) return fail("too many faces for 32-bit indices");

  PolyMesh& m = mesh_;
  const std::size_t expect = std::min<std::size_t>(e.count, reader.remaining() / e.min_bytes(encoding_ == PlyEncoding::Ascii));
  m.face_offsets.reserve(expect + 1);
  m.corner_vertex.reserve(expect * 4);  // quad-dominant input
  std::vector<Index> scratch;
  double v = 0;
  auto texcoord_list = [&](std::size_t k) -> TexcoordList* {
    for (TexcoordList& t : corner_texcoords_)
      if (t.property == static_cast<int>(k)) return &t;
    return nullptr;
  };

  for (std::uint64_t i = 0; i < e.count; ++i) {
    const std::size_t first = m.corner_vertex.size();
    for (TexcoordList& t : corner_texcoords_) t.count = 0;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      if (const Status s = reader.scalar(p.is_list ? p.count_type : p.type, v); s != Status::Ok)
        return value_error(reader, s, e, i);
      if (!p.is_list) continue;
      if (v < 0) return fail("face " + std::to_string(i) + ": negative list length");
      const auto count = static_cast<std::uint64_t>(v);
      if (static_cast<int>(k) == iv) {
        // The list must fit in the bytes left before anything is allocated for it.
        if (count > reader.remaining() / (encoding_ == PlyEncoding::Ascii ? 2 : type_size(p.type)))
          return value_error(reader, Status::Truncated, e, i);
        if (first + count >= kInvalidIndex) return fail("too many face corners for 32-bit indices");
        for (std::uint64_t j = 0; j < count; ++j) {
          if (const Status s = reader.scalar(p.type, v); s != Status::Ok) return value_error(reader, s, e, i);
          if (!(v >= 0 && v < static_cast<double>(kInvalidIndex)) || v != std::floor(v))
            return fail("face " + std::to_string(i) + ": bad vertex index " + std::to_string(v));
          m.corner_vertex.push_back(static_cast<Index>(v));
        }
      } else if (TexcoordList* t = texcoord_list(k)) {
        if (count > reader.remaining() / (encoding_ == PlyEncoding::Ascii ? 2 : type_size(p.type)))
          return value_error(reader, Status::Truncated, e, i);
        t->face.resize(count);
        for (std::uint64_t j = 0; j < count; ++j) {
          if (const Status s = reader.scalar(p.type, v); s != Status::Ok) return value_error(reader, s, e, i);
          t->face[j] = v;
        }
        t->count = count;
      } else if (const Status s = reader.skip(p.type, count); s != Status::Ok) {
        return value_error(reader, s, e, i);
      }
    }

    const std::size_t corners = m.corner_vertex.size() - first;
    Index repeated = kInvalidIndex;
    const FaceProblem problem = check_face(m.corner_vertex.data() + first, corners,
                                           options_.allow_repeated_vertex, scratch, repeated);
    if (problem != FaceProblem::None)
      return fail("face " + std::to_string(i) + ": " + describe_face_problem(problem, corners, repeated, 0));
    for (TexcoordList& t : corner_texcoords_) {
      if (t.count != 0 && t.count != 2 * corners)
        return fail("face " + std::to_string(i) + ": " + t.name + " list has " + std::to_string(t.count) +
                    " values for " + std::to_string(corners) + " corners");
      if (t.count == 0 && t.values.empty()) continue;
      // Corners before the first face with texcoords have none: NaN marks "no UV".
      t.values.resize(2 * first, std::numeric_limits<float>::quiet_NaN());
      if (t.count) t.values.insert(t.values.end(), t.face.begin(), t.face.begin() + t.count);
      else t.values.resize(2 * (first + corners), std::numeric_limits<float>::quiet_NaN());
    }
    m.face_offsets.push_back(static_cast<Index>(m.corner_vertex.size()));
  }
  return true;
}

template <class Reader>
bool PlyParser::read_body(Reader& reader) {
  for (const PlyElement& e : elements_) {
    bool ok;
    if (e.name == "vertex") ok = read_vertices(reader, e);
    else if (e.name == "face") ok = read_faces(reader, e);
    else ok = skip_element(reader, e);
    if (!ok) return false;
  }
  return true;
}

bool PlyParser::finish() {
  PolyMesh& m = mesh_;
  if (m.num_faces() == 0) return fail("no faces");
  const Index nv = m.num_vertices();
  for (Index f = 0; f < m.num_faces(); ++f)
    for (Index c = m.face_begin(f); c < m.face_end(f); ++c)
      if (m.corner_vertex[c] >= nv)
        return fail("face " + std::to_string(f) + ": vertex index " + std::to_string(m.corner_vertex[c]) +
                    " out of range (" + std::to_string(nv) + " vertices)");

  // Per-corner lists win over per-vertex UVs for set 0. One pool entry per corner that has a
  // UV: the PLY list carries no sharing to preserve.
  for (TexcoordList& t : corner_texcoords_) {
    if (t.values.empty()) {
      if (m.uv_sets.empty() && !vertex_uvs_.empty()) m.uv_sets.push_back({"", std::move(vertex_uvs_), m.corner_vertex});
      continue;
    }
    t.values.resize(2 * std::size_t{m.num_corners()}, std::numeric_limits<float>::quiet_NaN());
    UvSet& set = m.uv_sets.emplace_back();
    set.name = t.name == "texcoord" ? "" : t.name;
    set.values.reserve(m.num_corners());
    set.corner.assign(m.num_corners(), kInvalidIndex);
    for (Index c = 0; c < m.num_corners(); ++c) {
      const double u = t.values[2 * c], v = t.values[2 * c + 1];
      if (!std::isfinite(u) || !std::isfinite(v)) continue;
      set.corner[c] = static_cast<Index>(set.values.size());
      set.values.emplace_back(u, v);
    }
  }
  if (m.uv_sets.empty() && !vertex_uvs_.empty()) m.uv_sets.push_back({"", std::move(vertex_uvs_), m.corner_vertex});
  if (!vertex_normals_.empty()) {
    m.normals = std::move(vertex_normals_);
    m.corner_normal = m.corner_vertex;
  }
  return true;
}

bool PlyParser::run() {
  if (!parse_header()) return false;
  const char* body = data_.data() + body_offset_;
  const char* end = data_.data() + data_.size();
  bool ok;
  if (encoding_ == PlyEncoding::Ascii) {
    AsciiReader reader(body, end);
    ok = read_body(reader);
  } else {
    const bool little = encoding_ == PlyEncoding::BinaryLittleEndian;
    BinaryReader reader(body, end, little != (std::endian::native == std::endian::little));
    ok = read_body(reader);
  }
  return ok && finish();
}

// --- writer -------------------------------------------------------------------------------

class PlyWriter {
 public:
  PlyWriter(std::string& out, PlyEncoding encoding)
      : out_(out), ascii_(encoding == PlyEncoding::Ascii),
        swap_((encoding == PlyEncoding::BinaryLittleEndian) != (std::endian::native == std::endian::little)) {}

  void f32(float v) {
    if (ascii_) {
      separate();
      append_float(out_, v);
    } else {
      put(v);
    }
  }
  void f64(double v) {
    if (ascii_) {
      separate();
      append_double(out_, v, 17);
    } else {
      put(v);
    }
  }
  /// A value of a property written as double when `wide`, else as float.
  void real(double v, bool wide) {
    if (wide) f64(v);
    else f32(static_cast<float>(v));
  }
  void u8(std::uint8_t v) {
    if (ascii_) {
      separate();
      append_uint(out_, v);
    } else {
      put(v);
    }
  }
  void i32(std::uint32_t v) {  // written as int or uint, same bytes for values < 2^31
    if (ascii_) {
      separate();
      append_uint(out_, v);
    } else {
      put(v);
    }
  }
  void end_record() {
    if (ascii_) out_ += '\n';
    first_ = true;
  }

 private:
  void separate() {
    if (!first_) out_ += ' ';
    first_ = false;
  }
  template <class T>
  void put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof v);
    if (swap_) std::reverse(b, b + sizeof b);
    out_.append(b, sizeof b);
  }
  std::string& out_;
  bool ascii_, swap_;
  bool first_ = true;
};

}  // namespace

namespace io_detail {

ReadResult parse_ply(std::string_view data, const std::string& name, const ReadOptions& options) {
  const Stopwatch clock;
  ReadResult result;
  PlyParser parser(data, name, options, result);
  if (!parser.run()) result.mesh = PolyMesh{};
  result.seconds = clock.seconds();
  return result;
}

bool format_ply(const PolyMesh& mesh, const WriteOptions& options, std::string& out,
                std::string& error) {
  if (std::string e = mesh.check_layout(); !e.empty()) {
    error = "invalid mesh: " + e;
    return false;
  }
  // Normals go out per vertex only when that loses nothing: every corner has one and all
  // corners of a vertex agree.
  std::vector<Vec3> vertex_normals;
  if (mesh.has_normals()) {
    vertex_normals.assign(mesh.num_vertices(), Vec3::Constant(std::numeric_limits<double>::quiet_NaN()));
    for (Index c = 0; c < mesh.num_corners() && !vertex_normals.empty(); ++c) {
      const Index n = mesh.corner_normal[c];
      Vec3& slot = vertex_normals[mesh.corner_vertex[c]];
      if (n == kInvalidIndex || (!std::isnan(slot.x()) && slot != mesh.normals[n])) vertex_normals.clear();
      else slot = mesh.normals[n];
    }
    for (Vec3& n : vertex_normals)
      if (std::isnan(n.x())) n = Vec3::Zero();  // unused vertex
  }
  const bool normals = !vertex_normals.empty();
  const bool colors = !mesh.vertex_colors.empty();
  const bool uvs = mesh.has_uvs();
  Index max_degree = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) max_degree = std::max(max_degree, mesh.face_size(f));
  const bool wide_count = max_degree > 255;
  const bool wide_texcoord_count = 2 * std::uint64_t{max_degree} > 255;
  const bool uint_index = mesh.num_vertices() > static_cast<Index>(std::numeric_limits<std::int32_t>::max());
  // Values beyond float's range go out as double: as float they would be infinite, a file this
  // reader refuses (issue 23, a fuzz finding), and the conversion itself is undefined.
  const auto beyond_float = [](double v) { return std::abs(v) > double(std::numeric_limits<float>::max()); };
  const auto any_beyond = [&](const auto& values) {
    return std::any_of(values.begin(), values.end(), [&](const auto& x) {
      return std::any_of(x.data(), x.data() + x.size(), beyond_float);
    });
  };
  const bool wide_positions = any_beyond(mesh.positions);
  const bool wide_normals = normals && any_beyond(vertex_normals);
  std::vector<std::uint8_t> wide_uvs(mesh.uv_sets.size());
  for (std::size_t k = 0; k < mesh.uv_sets.size(); ++k) wide_uvs[k] = any_beyond(mesh.uv_sets[k].values);

  out.clear();
  out += "ply\nformat ";
  out += options.ply_encoding == PlyEncoding::Ascii              ? "ascii"
         : options.ply_encoding == PlyEncoding::BinaryBigEndian ? "binary_big_endian"
                                                                 : "binary_little_endian";
  out += " 1.0\ncomment written by quadlod\nelement vertex ";
  append_uint(out, mesh.num_vertices());
  out += wide_positions ? "\nproperty double x\nproperty double y\nproperty double z\n"
                        : "\nproperty float x\nproperty float y\nproperty float z\n";
  if (normals)
    out += wide_normals ? "property double nx\nproperty double ny\nproperty double nz\n"
                        : "property float nx\nproperty float ny\nproperty float nz\n";
  if (colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "element face ";
  append_uint(out, mesh.num_faces());
  out += wide_count ? "\nproperty list int " : "\nproperty list uchar ";
  out += uint_index ? "uint vertex_indices\n" : "int vertex_indices\n";
  for (std::size_t k = 0; k < mesh.uv_sets.size(); ++k) {
    out += wide_texcoord_count ? "property list int " : "property list uchar ";
    out += wide_uvs[k] ? "double texcoord" : "float texcoord";
    if (k > 0) append_uint(out, k);
    out += '\n';
  }
  out += "end_header\n";

  const bool ascii = options.ply_encoding == PlyEncoding::Ascii;
  out.reserve(out.size() + mesh.positions.size() * (ascii ? 40 : 12) * (1 + normals + colors) +
              mesh.corner_vertex.size() * (ascii ? 8 : 4) * (uvs ? 3 : 1) + mesh.face_offsets.size() * 8);
  PlyWriter w(out, options.ply_encoding);
  const auto colour = [](double c) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(std::isfinite(c) ? c : 0.0, 0.0, 1.0) * 255.0));
  };
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) w.real(mesh.positions[v][k], wide_positions);
    if (normals)
      for (int k = 0; k < 3; ++k) w.real(vertex_normals[v][k], wide_normals);
    if (colors)
      for (int k = 0; k < 3; ++k) w.u8(colour(mesh.vertex_colors[v][k]));
    w.end_record();
  }
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Index n = mesh.face_size(f);
    if (wide_count) w.i32(n);
    else w.u8(static_cast<std::uint8_t>(n));
    for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) w.i32(mesh.corner_vertex[c]);
    for (std::size_t k = 0; k < mesh.uv_sets.size(); ++k) {
      const UvSet& set = mesh.uv_sets[k];
      Index with_uv = 0;
      for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) with_uv += set.corner[c] != kInvalidIndex;
      const Index count = with_uv == 0 ? 0 : 2 * n;
      if (wide_texcoord_count) w.i32(count);
      else w.u8(static_cast<std::uint8_t>(count));
      if (count)
        for (Index c = mesh.face_begin(f); c < mesh.face_end(f); ++c) {
          const Index t = set.corner[c];
          w.real(t == kInvalidIndex ? kNaN : set.values[t].x(), wide_uvs[k]);
          w.real(t == kInvalidIndex ? kNaN : set.values[t].y(), wide_uvs[k]);
        }
    }
    w.end_record();
  }
  return true;
}

}  // namespace io_detail

ReadResult read_ply(const std::filesystem::path& path, const ReadOptions& options) {
  return read_and_parse(path, options, parse_ply);
}

WriteResult write_ply(const PolyMesh& mesh, const std::filesystem::path& path,
                      const WriteOptions& options) {
  WriteResult r = format_and_write(mesh, path, options, format_ply);
  if (r.ok()) warn_dropped_tags(mesh, path, "PLY", r.warnings);
  return r;
}

}  // namespace quadlod
