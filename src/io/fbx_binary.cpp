// quadlod — binary FBX record tree (see fbx_binary.h for the layout and the checks).
#include "io/fbx_binary.h"

#include <zlib.h>

#include <bit>
#include <cstring>

namespace quadlod::fbx {

namespace {

constexpr std::string_view kMagic("Kaydara FBX Binary  \0\x1a\0", 23);
constexpr std::size_t kHeaderBytes = 27;  // magic + u32 version

std::string quoted_name(const std::string& name) {
  std::string out(1, '\'');  // (not "'" + …: GCC 12 warns falsely on that concatenation)
  out += printable(name);
  out += '\'';
  return out;
}

/// A cursor over the buffer; every read is bounds-checked, the first failure sets `error`.
class Reader {
 public:
  Reader(std::string_view bytes, const ParseParams& params) : bytes_(bytes), params_(params) {}

  bool parse(Document& doc) {
    if (!is_binary_fbx(bytes_)) return fail(0, "not a binary FBX (no \"Kaydara FBX Binary\" header)");
    pos_ = kHeaderBytes - 4;
    std::uint32_t version = 0;
    if (!u32(version)) return false;
    doc.version = version;
    wide_ = version >= 7500;
    // Top level: records until a NULL record or the end of the buffer (a file without a footer).
    while (pos_ < bytes_.size()) {
      Record record;
      bool null_record = false;
      if (!parse_record(record, bytes_.size(), 0, null_record)) return false;
      if (null_record) break;
      doc.records.push_back(std::move(record));
    }
    return true;
  }

  const std::string& error() const { return error_; }

 private:
  bool fail(std::size_t at, const std::string& what) {
    if (error_.empty()) error_ = "FBX byte " + std::to_string(at) + ": " + what;
    return false;
  }
  bool need(std::size_t n, const char* what) {
    if (n > bytes_.size() - pos_) return fail(pos_, std::string("truncated ") + what);
    return true;
  }
  template <class T>
  bool scalar(T& out, const char* what) {
    if (!need(sizeof(T), what)) return false;
    std::memcpy(&out, bytes_.data() + pos_, sizeof(T));  // little-endian host (x86-64, arm64)
    pos_ += sizeof(T);
    return true;
  }
  bool u32(std::uint32_t& out) { return scalar(out, "u32"); }
  bool offset_field(std::uint64_t& out) {
    if (wide_) return scalar(out, "record header");
    std::uint32_t narrow = 0;
    if (!scalar(narrow, "record header")) return false;
    out = narrow;
    return true;
  }

  /// One record ending at or before `limit`; `null_record` set for the zero record ending a list.
  bool parse_record(Record& record, std::size_t limit, int depth, bool& null_record) {
    const std::size_t start = pos_;
    std::uint64_t end = 0, property_count = 0, property_bytes = 0;
    if (!offset_field(end) || !offset_field(property_count) || !offset_field(property_bytes)) return false;
    std::uint8_t name_length = 0;
    if (!scalar(name_length, "record header")) return false;
    if (end == 0 && property_count == 0 && property_bytes == 0 && name_length == 0) {
      null_record = true;
      return true;
    }
    if (end <= start || end > limit) return fail(start, "record end offset " + std::to_string(end) + " is outside its enclosing record (" + std::to_string(start) + ".." + std::to_string(limit) + ")");
    if (!need(name_length, "record name")) return false;
    record.name.assign(bytes_.data() + pos_, name_length);
    pos_ += name_length;
    // (Before any subtraction from `end`: a header and name longer than the record would wrap.)
    if (pos_ > end) return fail(start, "record " + quoted_name(record.name) + ": header and name run past the record's end");
    const std::size_t properties_start = pos_;
    if (property_bytes > end - pos_) return fail(start, "record " + quoted_name(record.name) + ": property list runs past the record's end");
    const std::size_t properties_end = pos_ + static_cast<std::size_t>(property_bytes);
    // Each property is at least 2 bytes (code + a 1-byte scalar): the count is bounded before reserving.
    if (property_count > property_bytes / 2 + 1) return fail(start, "record " + quoted_name(record.name) + ": " + std::to_string(property_count) + " properties in " + std::to_string(property_bytes) + " bytes");
    record.properties.reserve(static_cast<std::size_t>(property_count));
    const std::string_view saved = bytes_;
    bytes_ = bytes_.substr(0, properties_end);  // a property may not read past the list
    for (std::uint64_t i = 0; i < property_count; ++i) {
      Property p;
      if (!parse_property(p, record.name)) return false;
      record.properties.push_back(std::move(p));
    }
    bytes_ = saved;
    if (pos_ != properties_end) return fail(properties_start, "record " + quoted_name(record.name) + ": properties end at byte " + std::to_string(pos_) + ", the list says " + std::to_string(properties_end));
    if (pos_ < end) {
      if (depth + 1 > params_.max_depth) return fail(start, "records nested deeper than " + std::to_string(params_.max_depth));
      bool closed = false;
      while (pos_ < end) {
        Record child;
        bool child_null = false;
        if (!parse_record(child, static_cast<std::size_t>(end), depth + 1, child_null)) return false;
        if (child_null) {
          closed = true;
          break;
        }
        record.children.push_back(std::move(child));
      }
      // Tolerated: a list that fills its record without the NULL record (assimp 5.2's own writer).
      (void)closed;
      if (pos_ != end) return fail(start, "record " + quoted_name(record.name) + ": nested records end at byte " + std::to_string(pos_) + ", the record at " + std::to_string(end));
    }
    return true;
  }

  bool parse_property(Property& p, const std::string& record) {
    const std::size_t at = pos_;
    std::uint8_t code = 0;
    if (!scalar(code, "property type")) return false;
    p.type = static_cast<char>(code);
    switch (p.type) {
      case 'Y': { std::int16_t v; if (!scalar(v, "i16")) return false; p.integers.push_back(v); return true; }
      case 'C': { std::uint8_t v; if (!scalar(v, "bool")) return false; p.integers.push_back(v); return true; }
      case 'I': { std::int32_t v; if (!scalar(v, "i32")) return false; p.integers.push_back(v); return true; }
      case 'L': { std::int64_t v; if (!scalar(v, "i64")) return false; p.integers.push_back(v); return true; }
      case 'F': { float v; if (!scalar(v, "f32")) return false; p.reals.push_back(v); return true; }
      case 'D': { double v; if (!scalar(v, "f64")) return false; p.reals.push_back(v); return true; }
      case 'S':
      case 'R': {
        std::uint32_t n = 0;
        if (!u32(n) || !need(n, "string")) return false;
        p.bytes.assign(bytes_.data() + pos_, n);
        pos_ += n;
        return true;
      }
      case 'f': return parse_array<float>(p, at, record);
      case 'd': return parse_array<double>(p, at, record);
      case 'i': return parse_array<std::int32_t>(p, at, record);
      case 'l': return parse_array<std::int64_t>(p, at, record);
      case 'b': return parse_array<std::uint8_t>(p, at, record);
      default:
        return fail(at, "record " + quoted_name(record) + ": unknown property type 0x" + hex(code));
    }
  }

  template <class T>
  bool parse_array(Property& p, std::size_t at, const std::string& record) {
    std::uint32_t count = 0, encoding = 0, stored = 0;
    if (!u32(count) || !u32(encoding) || !u32(stored) || !need(stored, "array data")) return false;
    const std::uint64_t bytes = std::uint64_t{count} * sizeof(T);
    const std::string where = "record " + quoted_name(record) + ": array of " + std::to_string(count) + " '" + std::string(1, p.type) + "'";
    std::string inflated;
    const char* data = bytes_.data() + pos_;
    if (encoding == 0) {
      if (stored != bytes) return fail(at, where + " stores " + std::to_string(stored) + " bytes, not " + std::to_string(bytes));
    } else if (encoding == 1) {
      if (bytes > std::uint64_t{stored} * params_.max_inflate_ratio + 64)
        return fail(at, where + " cannot inflate from " + std::to_string(stored) + " zlib bytes");
      inflated.resize(static_cast<std::size_t>(bytes));
      uLongf length = static_cast<uLongf>(bytes);
      const int z = uncompress(reinterpret_cast<Bytef*>(inflated.data()), &length,
                               reinterpret_cast<const Bytef*>(data), stored);
      if (z != Z_OK || length != bytes)
        return fail(at, where + ": zlib data " + (z == Z_OK ? "inflates to " + std::to_string(length) + " bytes" : std::string("is corrupt (") + zError(z) + ")"));
      data = inflated.data();
    } else {
      return fail(at, where + ": unknown encoding " + std::to_string(encoding));
    }
    pos_ += stored;
    std::vector<T> values(count);
    if (bytes) std::memcpy(values.data(), data, static_cast<std::size_t>(bytes));
    if constexpr (std::is_floating_point_v<T>)
      p.reals.assign(values.begin(), values.end());
    else
      p.integers.assign(values.begin(), values.end());
    return true;
  }

  static std::string hex(std::uint8_t b) {
    const char* digits = "0123456789abcdef";
    return {digits[b >> 4], digits[b & 15]};
  }

  std::string_view bytes_;
  const ParseParams& params_;
  std::size_t pos_ = 0;
  bool wide_ = false;
  std::string error_;
};

}  // namespace

std::string printable(std::string_view text, std::size_t max_length) {
  std::string out;
  for (char ch : text.substr(0, max_length)) {
    const auto b = static_cast<unsigned char>(ch);
    if (b >= 0x20 && b < 0x7f) {
      out.push_back(ch);
    } else {
      const char* digits = "0123456789abcdef";
      out += "\\x";
      out.push_back(digits[b >> 4]);
      out.push_back(digits[b & 15]);
    }
  }
  if (text.size() > max_length) out += "...";
  return out;
}

const Record* Record::find(std::string_view child) const {
  for (const Record& r : children)
    if (r.name == child) return &r;
  return nullptr;
}

std::string Record::string_property(std::size_t i) const {
  if (i >= properties.size() || (properties[i].type != 'S' && properties[i].type != 'R')) return {};
  return properties[i].bytes;
}

const Record* Document::find(std::string_view name) const {
  for (const Record& r : records)
    if (r.name == name) return &r;
  return nullptr;
}

bool is_binary_fbx(std::string_view bytes) {
  return bytes.size() >= kHeaderBytes && bytes.substr(0, kMagic.size()) == kMagic;
}

ParseResult parse_binary_fbx(std::string_view bytes, const ParseParams& params) {
  static_assert(std::endian::native == std::endian::little, "the FBX reader copies little-endian fields as they are");
  ParseResult result;
  Reader reader(bytes, params);
  if (!reader.parse(result.document)) {
    result.error = reader.error();
    result.document = {};
  }
  return result;
}

}  // namespace quadlod::fbx
