// quadlod_meshopt_peer — the meshoptimizer peer of bench/run (issue 6).
//
// Reads a polygon OBJ (positions only: `v` and `f` records; `vt`/`vn` indices, negative indices
// and every other record are accepted and ignored), fan-triangulates every face (a k-gon
// v0 v1 ... v(k-1) becomes the triangles (v0, vi, vi+1), i = 1..k-2 — the same count of
// triangles as quadlod's triangle-equivalents), runs meshopt_simplify (meshoptimizer 0.18,
// Debian libmeshoptimizer-dev) towards a target triangle count and writes the result as a
// triangle OBJ with only the vertices it uses.
//
// meshopt_simplify preserves topology and may stop short of the target when no legal collapse
// is left; that is its result and the driver reports it as achieved, it does not retry.
//
//   quadlod_meshopt_peer INPUT.obj OUTPUT.obj --target-tris N [--target-error E] [--lock-border]
//
// Prints one JSON object on stdout: input and output counts, the result error meshopt reports
// (relative to the mesh extents) and the seconds of read, simplify and write.
// Exit codes as the quadlod CLI: 0 ok, 1 bad command line, 2 unreadable input or unwritable
// output (one line on stderr naming the file; no output file is left behind).
// The output appears atomically: written to a temporary file next to it, then renamed.

#include <meshoptimizer.h>

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <unistd.h>
#include <vector>

namespace {

struct Failure {
  int code;
  std::string message;
};

struct TriMesh {
  std::vector<float> positions;  // xyz per vertex
  std::vector<unsigned> indices; // 3 per triangle
  std::size_t polygons = 0;
};

double now_seconds() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(clock::now().time_since_epoch()).count();
}

std::string_view next_token(std::string_view& s) {
  std::size_t b = 0;
  while (b < s.size() && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  std::size_t e = b;
  while (e < s.size() && s[e] != ' ' && s[e] != '\t' && s[e] != '\r') ++e;
  std::string_view tok = s.substr(b, e - b);
  s.remove_prefix(e);
  return tok;
}

TriMesh read_obj(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Failure{2, path + ": cannot open: " + std::strerror(errno)};
  TriMesh mesh;
  std::string line;
  std::size_t line_no = 0;
  std::vector<unsigned> poly;
  auto fail = [&](const std::string& what) {
    throw Failure{2, path + ":" + std::to_string(line_no) + ": " + what};
  };
  while (std::getline(in, line)) {
    ++line_no;
    std::string_view rest(line);
    std::string_view key = next_token(rest);
    if (key == "v") {
      for (int k = 0; k < 3; ++k) {
        std::string_view t = next_token(rest);
        float value = 0;
        auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
        if (t.empty() || ec != std::errc() || p != t.data() + t.size()) fail("bad vertex coordinate");
        if (!(value == value) || value > std::numeric_limits<float>::max() ||
            value < -std::numeric_limits<float>::max())
          fail("non-finite vertex coordinate");
        mesh.positions.push_back(value);
      }
    } else if (key == "f") {
      poly.clear();
      const long long nv = static_cast<long long>(mesh.positions.size() / 3);
      for (std::string_view t = next_token(rest); !t.empty(); t = next_token(rest)) {
        std::string_view vtok = t.substr(0, t.find('/'));
        long long idx = 0;
        auto [p, ec] = std::from_chars(vtok.data(), vtok.data() + vtok.size(), idx);
        if (vtok.empty() || ec != std::errc() || p != vtok.data() + vtok.size()) fail("bad face index");
        if (idx < 0) idx = nv + 1 + idx;
        if (idx < 1 || idx > nv) fail("face index out of range");
        poly.push_back(static_cast<unsigned>(idx - 1));
      }
      if (poly.size() < 3) fail("face with fewer than 3 corners");
      ++mesh.polygons;
      for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
        mesh.indices.push_back(poly[0]);
        mesh.indices.push_back(poly[k]);
        mesh.indices.push_back(poly[k + 1]);
      }
    }
  }
  if (in.bad()) throw Failure{2, path + ": read error"};
  if (mesh.indices.empty()) throw Failure{2, path + ": no faces"};
  return mesh;
}

// Writes only the vertices the triangles use, in first-use order.
void write_obj_atomic(const std::string& path, const std::vector<float>& positions,
                      const std::vector<unsigned>& indices) {
  std::vector<unsigned> remap(positions.size() / 3, ~0u);
  std::vector<unsigned> used;
  for (unsigned v : indices)
    if (remap[v] == ~0u) {
      remap[v] = static_cast<unsigned>(used.size());
      used.push_back(v);
    }
  std::string dir = ".";
  std::string base = path;
  if (auto slash = path.rfind('/'); slash != std::string::npos) {
    dir = path.substr(0, slash + 1);
    base = path.substr(slash + 1);
  }
  std::string tmpl = dir + "/." + base + ".tmpXXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  int fd = mkstemp(name.data());
  if (fd < 0) throw Failure{2, path + ": cannot create temporary file: " + std::strerror(errno)};
  FILE* f = fdopen(fd, "w");
  if (!f) {
    close(fd);
    unlink(name.data());
    throw Failure{2, path + ": cannot open temporary file"};
  }
  std::fprintf(f, "# quadlod_meshopt_peer: meshopt_simplify (meshoptimizer %d.%d)\n",
               MESHOPTIMIZER_VERSION / 1000, MESHOPTIMIZER_VERSION % 1000 / 10);
  for (unsigned v : used)
    std::fprintf(f, "v %.9g %.9g %.9g\n", positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3)
    std::fprintf(f, "f %u %u %u\n", remap[indices[t]] + 1, remap[indices[t + 1]] + 1, remap[indices[t + 2]] + 1);
  bool ok = std::fflush(f) == 0 && !std::ferror(f);
  ok = (std::fclose(f) == 0) && ok;
  if (!ok || std::rename(name.data(), path.c_str()) != 0) {
    std::string why = std::strerror(errno);
    unlink(name.data());
    throw Failure{2, path + ": cannot write: " + why};
  }
}

int usage(const char* why) {
  std::fprintf(stderr,
               "quadlod_meshopt_peer: %s\n"
               "usage: quadlod_meshopt_peer INPUT.obj OUTPUT.obj --target-tris N "
               "[--target-error E] [--lock-border]\n",
               why);
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> positional;
  long long target_tris = -1;
  // No error bound by default: stop only at the target or when no legal collapse remains.
  float target_error = std::numeric_limits<float>::max();
  unsigned options = 0;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&](const char* name) -> std::string {
      if (i + 1 >= argc) throw Failure{1, std::string(name) + " needs a value"};
      return argv[++i];
    };
    try {
      if (a == "--target-tris") {
        std::string v = value("--target-tris");
        std::size_t used = 0;
        target_tris = std::stoll(v, &used);
        if (used != v.size() || target_tris < 1) return usage("--target-tris must be a positive integer");
      } else if (a == "--target-error") {
        std::string v = value("--target-error");
        std::size_t used = 0;
        target_error = std::stof(v, &used);
        if (used != v.size() || !(target_error >= 0)) return usage("--target-error must be >= 0");
      } else if (a == "--lock-border") {
        options |= meshopt_SimplifyLockBorder;
      } else if (a == "-h" || a == "--help") {
        usage("help");
        return 0;
      } else if (!a.empty() && a[0] == '-') {
        return usage(("unknown option " + a).c_str());
      } else {
        positional.push_back(a);
      }
    } catch (const Failure& f) {
      return usage(f.message.c_str());
    } catch (const std::exception&) {
      return usage(("bad value for " + a).c_str());
    }
  }
  if (positional.size() != 2) return usage("expected INPUT and OUTPUT");
  if (target_tris < 1) return usage("--target-tris is required");
  if (positional[0] == positional[1]) return usage("OUTPUT names INPUT");

  try {
    double t0 = now_seconds();
    TriMesh mesh = read_obj(positional[0]);
    double t1 = now_seconds();
    const std::size_t vertex_count = mesh.positions.size() / 3;
    std::vector<unsigned> out(mesh.indices.size());
    float result_error = 0;
    std::size_t target_index_count = static_cast<std::size_t>(target_tris) * 3;
    std::size_t n = meshopt_simplify(out.data(), mesh.indices.data(), mesh.indices.size(),
                                     mesh.positions.data(), vertex_count, sizeof(float) * 3,
                                     target_index_count, target_error, options, &result_error);
    out.resize(n);
    double t2 = now_seconds();
    if (n == 0) throw Failure{2, positional[0] + ": meshopt_simplify removed every triangle"};
    write_obj_atomic(positional[1], mesh.positions, out);
    double t3 = now_seconds();
    std::ostringstream js;
    js.precision(9);
    js << "{\"peer\": \"meshoptimizer\", \"version\": \"" << MESHOPTIMIZER_VERSION / 1000 << "."
       << MESHOPTIMIZER_VERSION % 1000 / 10 << "\", \"input_vertices\": " << vertex_count
       << ", \"input_polygons\": " << mesh.polygons
       << ", \"input_triangles\": " << mesh.indices.size() / 3 << ", \"target_triangles\": " << target_tris
       << ", \"achieved_triangles\": " << n / 3 << ", \"result_error\": " << result_error
       << ", \"lock_border\": " << ((options & meshopt_SimplifyLockBorder) ? "true" : "false")
       << ", \"seconds_read\": " << (t1 - t0) << ", \"seconds_simplify\": " << (t2 - t1)
       << ", \"seconds_write\": " << (t3 - t2) << "}\n";
    std::fputs(js.str().c_str(), stdout);
    return 0;
  } catch (const Failure& f) {
    std::fprintf(stderr, "quadlod_meshopt_peer: %s\n", f.message.c_str());
    return f.code;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "quadlod_meshopt_peer: out of memory\n");
    return 3;
  }
}
