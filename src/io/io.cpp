// quadlod — format dispatch by extension, whole-file loading, and the atomic file writer that
// every mesh writer and report writer goes through.
#include "io/io_common.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <system_error>
#include <utility>

namespace quadlod {

namespace fs = std::filesystem;

namespace {

std::string errno_message(int e) { return std::system_category().message(e); }

// Closes on scope exit so that every early return releases the descriptor.
struct Fd {
  int fd = -1;
  Fd() = default;
  explicit Fd(int f) : fd(f) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
  int release() { return std::exchange(fd, -1); }
};

}  // namespace

namespace io_detail {

bool read_whole_file(const fs::path& path, FileBuffer& out, std::string& error) {
  out = FileBuffer{};
  Fd f{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
  const auto fail = [&](const std::string& why) {
    error = "cannot read " + path.string() + ": " + why;
    out = FileBuffer{};
    return false;
  };
  if (f.fd < 0) return fail(errno_message(errno));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) return fail(errno_message(errno));
  if (S_ISDIR(st.st_mode)) return fail("is a directory");
  // Regular files are read in one go into a buffer of their size (+1 so that EOF is seen
  // without growing); pipes and the like report size 0 and grow the buffer as data arrives.
  std::size_t capacity = (S_ISREG(st.st_mode) ? static_cast<std::size_t>(st.st_size) : 0) + 1;
  if (capacity < 4096) capacity = 4096;
  out.data.reset(new char[capacity]);
  for (;;) {
    if (out.size == capacity) {
      std::unique_ptr<char[]> bigger(new char[capacity * 2]);
      std::memcpy(bigger.get(), out.data.get(), out.size);
      out.data = std::move(bigger);
      capacity *= 2;
    }
    const ssize_t n = ::read(f.fd, out.data.get() + out.size, capacity - out.size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(errno_message(errno));
    }
    if (n == 0) break;
    out.size += static_cast<std::size_t>(n);
  }
  return true;
}

FaceProblem check_face(const Index* corners, std::size_t count, bool allow_repeated_vertex,
                       std::vector<Index>& scratch, Index& repeated) {
  if (count < 3) return FaceProblem::TooFewCorners;
  if (allow_repeated_vertex) return FaceProblem::None;
  // Quads and small n-gons are the norm: the quadratic scan beats sorting for them.
  if (count <= 16) {
    for (std::size_t i = 1; i < count; ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (corners[i] == corners[j]) {
          repeated = corners[i];
          return FaceProblem::RepeatedVertex;
        }
    return FaceProblem::None;
  }
  scratch.assign(corners, corners + count);
  std::sort(scratch.begin(), scratch.end());
  const auto it = std::adjacent_find(scratch.begin(), scratch.end());
  if (it == scratch.end()) return FaceProblem::None;
  repeated = *it;
  return FaceProblem::RepeatedVertex;
}

std::string describe_face_problem(FaceProblem problem, std::size_t count, Index repeated,
                                  Index base) {
  switch (problem) {
    case FaceProblem::TooFewCorners:
      return "has " + std::to_string(count) + " corner" + (count == 1 ? "" : "s") +
             " (at least 3 needed)";
    case FaceProblem::RepeatedVertex:
      return "uses vertex " + std::to_string(std::uint64_t{repeated} + base) +
             " more than once";
    case FaceProblem::None: break;
  }
  return {};
}

}  // namespace io_detail

bool format_from_path(const fs::path& path, MeshFormat& format) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj") format = MeshFormat::Obj;
  else if (ext == ".ply") format = MeshFormat::Ply;
  else if (ext == ".off") format = MeshFormat::Off;
  else return false;
  return true;
}

namespace {

std::string unknown_format_error(const fs::path& path) {
  const std::string ext = path.extension().string();
  return path.string() + ": unknown mesh format " +
         (ext.empty() ? std::string("(no extension)") : "'" + ext + "'") +
         " (expected .obj, .ply or .off)";
}

}  // namespace

ReadResult read_mesh(const fs::path& path, const ReadOptions& options) {
  MeshFormat format{};
  if (!format_from_path(path, format)) {
    ReadResult r;
    r.error = unknown_format_error(path);
    return r;
  }
  switch (format) {
    case MeshFormat::Obj: return read_obj(path, options);
    case MeshFormat::Ply: return read_ply(path, options);
    case MeshFormat::Off: return read_off(path, options);
  }
  return {};
}

WriteResult write_mesh(const PolyMesh& mesh, const fs::path& path, const WriteOptions& options) {
  MeshFormat format{};
  if (!format_from_path(path, format)) return {"cannot write " + unknown_format_error(path), {}};
  WriteResult r;
  switch (format) {
    case MeshFormat::Obj: r = write_obj(mesh, path, options); break;
    case MeshFormat::Ply: r = write_ply(mesh, path, options); break;
    case MeshFormat::Off: r = write_off(mesh, path, options); break;
  }
  // Issue 34: none of the three holds blend shapes; say so instead of losing them silently.
  if (r.ok() && !mesh.morph_targets.empty())
    r.warnings.push_back(path.string() + ": " + std::to_string(mesh.morph_targets.size()) +
                         " blend shape(s) dropped: OBJ, PLY and OFF hold none (write .glb or .fbx to keep them)");
  return r;
}

WriteResult write_file_atomically(const fs::path& path, std::string_view contents) {
  const std::string shown = path.string();
  const auto fail = [&](const std::string& why) { return WriteResult{"cannot write " + shown + ": " + why, {}}; };
  if (!path.has_filename()) return fail("not a file name");

  const fs::path dir = path.parent_path();
  const fs::path dir_or_cwd = dir.empty() ? fs::path(".") : dir;
  std::error_code ec;
  const fs::file_status dir_status = fs::status(dir_or_cwd, ec);
  if (!fs::exists(dir_status)) return fail("directory does not exist");
  if (!fs::is_directory(dir_status)) return fail(dir.string() + " is not a directory");
  if (fs::is_directory(fs::status(path, ec))) return fail("is a directory");

  // The temp name starts with a dot so that directory listings and globs (*.obj) in the target
  // directory never pick up a half-written file; pid + random keep concurrent writers apart.
  // Seeded from the clock rather than std::random_device, which may throw.
  static std::atomic<std::uint64_t> counter{
      static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count())};
  Fd f;
  fs::path tmp;
  // The temp file's slot in the interrupt-cleanup registry, released on every way out (after
  // the rename or the unlink: until then a signal must still remove the file).
  int registered = -1;
  struct Unregister {
    int& slot;
    ~Unregister() { io_detail::unregister_temporary(slot); }
  } unregister{registered};
  for (int attempt = 0; attempt < 16 && f.fd < 0; ++attempt) {
    char suffix[64];
    const auto r = std::to_chars(suffix, suffix + sizeof suffix,
                                 counter.fetch_add(0x9e3779b97f4a7c15ull) >> 16, 16);
    std::string tmp_name(1, '.');
    tmp_name += path.filename().string();
    tmp_name += ".tmp-";
    tmp_name += std::to_string(::getpid());
    tmp_name += '-';
    tmp_name.append(suffix, r.ptr);
    tmp = dir_or_cwd / tmp_name;
    // Registered before it exists so that no signal can leave it behind (issue 23).
    const int slot = io_detail::register_temporary(tmp.c_str());
    f.fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (f.fd >= 0) registered = slot;
    else io_detail::unregister_temporary(slot);
    if (f.fd < 0 && errno != EEXIST) return fail(errno_message(errno));
  }
  if (f.fd < 0) return fail("cannot create a temporary file");

  const auto abandon = [&](int e) {
    ::close(f.release());
    ::unlink(tmp.c_str());
    return fail(errno_message(e));
  };

  // Replacing a file keeps its permission bits; a new file gets 0666 & ~umask from open().
  struct stat target {};
  if (::stat(path.c_str(), &target) == 0 && S_ISREG(target.st_mode))
    (void)::fchmod(f.fd, target.st_mode & 07777);

  const char* p = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(f.fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return abandon(errno);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  // Without the fsync a crash right after the rename can leave an empty target on some
  // filesystems (ext4 delayed allocation), which is exactly what the temp file avoids.
  if (::fsync(f.fd) != 0) return abandon(errno);
  if (::close(f.release()) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    return fail(errno_message(e));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    return fail(errno_message(e));
  }
  // Persist the directory entry as well; failure here does not undo a completed write.
  if (const int d = ::open(dir_or_cwd.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); d >= 0) {
    (void)::fsync(d);
    ::close(d);
  }
  return {};
}

}  // namespace quadlod
