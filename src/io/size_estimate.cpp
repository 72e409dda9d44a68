// quadlod — how big a mesh file is before it is read (issue 23, `--max-memory`): element counts
// from the PLY / OFF header, or from one streaming pass over an OBJ file in fixed-size chunks.
// Nothing here allocates in proportion to the file.
#include "io/io_common.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <system_error>

namespace quadlod {

namespace {

constexpr std::size_t kChunkBytes = 1 << 20;
constexpr std::size_t kHeaderBytes = 1 << 16;  ///< a PLY / OFF header longer than this is not one

struct ReadFd {
  int fd = -1;
  ~ReadFd() {
    if (fd >= 0) ::close(fd);
  }
};

std::uint64_t parse_count(std::string_view token) {
  std::uint64_t v = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  return ec == std::errc() ? v : 0;
}

std::vector<std::string_view> tokens_of(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && io_detail::is_space(line[i])) ++i;
    const std::size_t b = i;
    while (i < line.size() && !io_detail::is_space(line[i])) ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

void from_ply_header(std::string_view head, InputSizeEstimate& e) {
  std::size_t at = 0;
  while (at < head.size()) {
    std::size_t eol = head.find('\n', at);
    if (eol == std::string_view::npos) eol = head.size();
    const auto tok = tokens_of(head.substr(at, eol - at));
    at = eol + 1;
    if (tok.size() == 3 && tok[0] == "element" && tok[1] == "vertex") e.vertices = parse_count(tok[2]);
    if (tok.size() == 3 && tok[0] == "element" && tok[1] == "face") e.faces = parse_count(tok[2]);
    if (!tok.empty() && tok[0] == "end_header") break;
  }
  e.corners = 4 * e.faces;  // the header has no corner count: quad-dominant input
}

void from_off_header(std::string_view head, InputSizeEstimate& e) {
  std::vector<std::string_view> numbers;
  std::size_t at = 0;
  bool keyword = true;
  while (at < head.size() && numbers.size() < 2) {
    std::size_t eol = head.find('\n', at);
    if (eol == std::string_view::npos) eol = head.size();
    std::string_view line = head.substr(at, eol - at);
    at = eol + 1;
    line = line.substr(0, line.find('#'));
    for (std::string_view t : tokens_of(line)) {
      if (keyword) {
        keyword = false;
        continue;
      }
      numbers.push_back(t);
    }
  }
  if (numbers.size() >= 2) {  // vertices faces [edges]
    e.vertices = parse_count(numbers[0]);
    e.faces = parse_count(numbers[1]);
  }
  e.corners = 4 * e.faces;
}

// One pass over an OBJ file: `v` and `f` records, and the corners of the `f` records (tokens
// after the keyword). A line continued with a backslash is counted as separate lines, which
// can only under-count corners of such rare faces.
struct ObjCounter {
  InputSizeEstimate& e;
  enum { LineStart, Keyword, FaceLine, Skip } state = LineStart;
  char keyword[3] = {0, 0, 0};
  int keyword_length = 0;
  bool in_token = false;
  void feed(const char* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      const char c = p[i];
      if (c == '\n') {
        end_keyword();
        state = LineStart;
        keyword_length = 0;
        in_token = false;
        continue;
      }
      switch (state) {
        case LineStart:
          if (io_detail::is_blank(c)) break;
          state = Keyword;
          [[fallthrough]];
        case Keyword:
          if (io_detail::is_blank(c)) end_keyword();
          else if (keyword_length < 3) keyword[keyword_length++] = c;
          else state = Skip;
          break;
        case FaceLine:
          if (io_detail::is_blank(c)) in_token = false;
          else if (!in_token) {
            in_token = true;
            ++e.corners;
          }
          break;
        case Skip: break;
      }
    }
  }
  void end_keyword() {
    if (state != Keyword) return;
    state = Skip;
    if (keyword_length == 1 && keyword[0] == 'v') ++e.vertices;
    if (keyword_length == 1 && keyword[0] == 'f') {
      ++e.faces;
      state = FaceLine;
      in_token = false;
    }
  }
};

}  // namespace

InputSizeEstimate estimate_input_size(const std::filesystem::path& path) {
  InputSizeEstimate e;
  MeshFormat format{};
  if (!format_from_path(path, format)) {
    e.error = path.string() + ": unknown mesh format (expected .obj, .ply or .off)";
    return e;
  }
  ReadFd f{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
  struct stat st {};
  if (f.fd < 0 || ::fstat(f.fd, &st) != 0) {
    e.error = "cannot read " + path.string() + ": " + std::system_category().message(errno);
    return e;
  }
  e.file_bytes = static_cast<std::uint64_t>(st.st_size);
  std::unique_ptr<char[]> chunk(new char[kChunkBytes]);
  const auto read_some = [&](std::size_t want) -> std::size_t {
    std::size_t got = 0;
    while (got < want) {
      const ssize_t n = ::read(f.fd, chunk.get() + got, want - got);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
    }
    return got;
  };
  if (format == MeshFormat::Obj) {
    ObjCounter counter{e};
    for (std::size_t n; (n = read_some(kChunkBytes)) > 0;) counter.feed(chunk.get(), n);
    counter.feed("\n", 1);
    return e;
  }
  const std::size_t n = read_some(kHeaderBytes);
  const std::string_view head(chunk.get(), n);
  if (format == MeshFormat::Ply) from_ply_header(head, e);
  else from_off_header(head, e);
  return e;
}

std::uint64_t estimate_simplify_peak_bytes(const InputSizeEstimate& input, const MemoryModel& model) {
  const std::uint64_t tri_equivalent = input.corners > 2 * input.faces ? input.corners - 2 * input.faces : input.faces;
  return model.base_bytes + input.file_bytes +
         static_cast<std::uint64_t>(model.bytes_per_tri_equivalent * double(tri_equivalent));
}

}  // namespace quadlod
