// quadlod_meshopt_peer — the meshoptimizer peer of bench/run (issue 6).
//
// Reads a polygon OBJ (positions only: `v` and `f` records; `vt`/`vn` indices, negative indices
// and every other record are accepted and ignored; see --uv below), fan-triangulates every face (a k-gon
// v0 v1 ... v(k-1) becomes the triangles (v0, vi, vi+1), i = 1..k-2 — the same count of
// triangles as quadlod's triangle-equivalents), runs meshopt_simplify (meshoptimizer 0.18,
// Debian libmeshoptimizer-dev) towards a target triangle count and writes the result as a
// triangle OBJ with only the vertices it uses.
//
// meshopt_simplify preserves topology and may stop short of the target when no legal collapse
// is left; that is its result and the driver reports it as achieved, it does not retry.
//
// --uv (bench/run's `meshopt-uv`, issue 32): the seam-aware input instead. Texture coordinates
// (`vt`, the second index of an `f` corner) are read too, and every distinct (OBJ vertex, UV
// value) pair becomes one meshoptimizer vertex, so a vertex on a UV seam is split into one copy
// per side, all at the same position. meshopt_simplify treats vertices at equal positions as one
// point with split attributes (a seam) and keeps the seam: it moves such copies together and
// collapses along the seam only. A face with a corner lacking a UV uses no UV at any corner (its
// corners are (vertex, no UV) pairs). The output is written with `v` (one per OBJ vertex used),
// `vt` (one per UV value used) and `f v/vt` corners, so the seams reach `quadlod eval` as seams
// and not as cracks. meshopt_simplify can leave a triangle with two copies of one OBJ vertex
// (distinct meshoptimizer vertices, one point: zero area in 3D; e.g. 4 of 774 triangles of
// flightgear_hitachi395_train_car at 0.1); OBJ readers refuse a face naming a vertex twice, so
// such triangles are dropped (`dropped_triangles` in the JSON; `achieved_triangles` counts the
// triangles written). Materials, groups and normals are not kept in either mode.
//
//   quadlod_meshopt_peer INPUT.obj OUTPUT.obj --target-tris N [--target-error E] [--lock-border] [--uv]
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
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <unistd.h>
#include <vector>

namespace {

struct Failure {
  int code;
  std::string message;
};

constexpr unsigned kNoUv = ~0u;

struct TriMesh {
  std::vector<float> positions;  // xyz per meshoptimizer vertex
  std::vector<unsigned> indices; // 3 per triangle
  std::size_t polygons = 0;
  // --uv only: per meshoptimizer vertex, its OBJ vertex (0-based `v`) and its UV (an index into
  // `uvs`, one entry per distinct value, or kNoUv); the OBJ's own vertex count and `vt` count.
  bool uv_mode = false;
  std::vector<unsigned> obj_vertex;
  std::vector<unsigned> uv_of;
  std::vector<float> uvs;  // u, v per distinct UV value
  std::size_t obj_vertices = 0;
  std::size_t obj_texcoords = 0;
  std::size_t polygons_without_uv = 0;
};

std::uint64_t pair_key(std::uint32_t a, std::uint32_t b) {
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

std::uint32_t float_bits(float f) {
  if (f == 0.0f) f = 0.0f;  // -0 and +0 are one UV value
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

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

bool parse_float(std::string_view t, float& value) {
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  return !t.empty() && ec == std::errc() && p == t.data() + t.size();
}

bool finite_float(float value) {
  return value == value && value <= std::numeric_limits<float>::max() &&
         value >= -std::numeric_limits<float>::max();
}

// One OBJ index (1-based or negative) -> 0-based, or -1 when out of range / malformed.
long long obj_index(std::string_view tok, long long count) {
  long long idx = 0;
  auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), idx);
  if (tok.empty() || ec != std::errc() || p != tok.data() + tok.size()) return -2;
  if (idx < 0) idx = count + 1 + idx;
  if (idx < 1 || idx > count) return -1;
  return idx - 1;
}

TriMesh read_obj(const std::string& path, bool uv_mode) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Failure{2, path + ": cannot open: " + std::strerror(errno)};
  TriMesh mesh;
  mesh.uv_mode = uv_mode;
  std::vector<float> obj_positions;  // xyz per OBJ `v`
  std::vector<unsigned> vt_value;    // per OBJ `vt`: its index into mesh.uvs (equal values share one)
  std::unordered_map<std::uint64_t, unsigned> uv_ids;      // UV value bits -> index into mesh.uvs
  std::unordered_map<std::uint64_t, unsigned> vertex_ids;  // (OBJ vertex, UV) -> meshopt vertex
  std::string line;
  std::size_t line_no = 0;
  std::vector<unsigned> poly, poly_uv;
  auto fail = [&](const std::string& what) {
    throw Failure{2, path + ":" + std::to_string(line_no) + ": " + what};
  };
  while (std::getline(in, line)) {
    ++line_no;
    std::string_view rest(line);
    std::string_view key = next_token(rest);
    if (key == "v") {
      for (int k = 0; k < 3; ++k) {
        float value = 0;
        if (!parse_float(next_token(rest), value)) fail("bad vertex coordinate");
        if (!finite_float(value)) fail("non-finite vertex coordinate");
        obj_positions.push_back(value);
      }
    } else if (key == "vt" && uv_mode) {
      float uv[2] = {0, 0};  // `vt u` alone has v = 0; a third (w) coordinate is ignored
      for (int k = 0; k < 2; ++k) {
        std::string_view t = next_token(rest);
        if (t.empty() && k == 1) break;
        if (!parse_float(t, uv[k])) fail("bad texture coordinate");
        if (!finite_float(uv[k])) fail("non-finite texture coordinate");
      }
      auto [it, inserted] = uv_ids.emplace(pair_key(float_bits(uv[0]), float_bits(uv[1])),
                                           static_cast<unsigned>(mesh.uvs.size() / 2));
      if (inserted) {
        mesh.uvs.push_back(uv[0]);
        mesh.uvs.push_back(uv[1]);
      }
      vt_value.push_back(it->second);
    } else if (key == "f") {
      poly.clear();
      poly_uv.clear();
      const long long nv = static_cast<long long>(obj_positions.size() / 3);
      const long long nt = static_cast<long long>(vt_value.size());
      bool all_uv = uv_mode;
      for (std::string_view t = next_token(rest); !t.empty(); t = next_token(rest)) {
        std::size_t slash = t.find('/');
        long long idx = obj_index(t.substr(0, slash), nv);
        if (idx == -2) fail("bad face index");
        if (idx < 0) fail("face index out of range");
        poly.push_back(static_cast<unsigned>(idx));
        if (!uv_mode) continue;
        std::string_view ttok;
        if (slash != std::string_view::npos) {
          ttok = t.substr(slash + 1);
          ttok = ttok.substr(0, ttok.find('/'));
        }
        if (ttok.empty()) {
          all_uv = false;
          poly_uv.push_back(kNoUv);
          continue;
        }
        long long tidx = obj_index(ttok, nt);
        if (tidx == -2) fail("bad texture coordinate index");
        if (tidx < 0) fail("texture coordinate index out of range");
        poly_uv.push_back(vt_value[static_cast<std::size_t>(tidx)]);
      }
      if (poly.size() < 3) fail("face with fewer than 3 corners");
      ++mesh.polygons;
      if (uv_mode) {
        if (!all_uv) ++mesh.polygons_without_uv;
        // Corner k -> the meshoptimizer vertex of (OBJ vertex, UV value); no UV at any corner of a
        // face where one lacks it, so every triangle is all-UV or all-plain.
        for (std::size_t k = 0; k < poly.size(); ++k) {
          unsigned uv = all_uv ? poly_uv[k] : kNoUv;
          auto [it, inserted] = vertex_ids.emplace(pair_key(poly[k], uv),
                                                   static_cast<unsigned>(mesh.obj_vertex.size()));
          if (inserted) {
            mesh.obj_vertex.push_back(poly[k]);
            mesh.uv_of.push_back(uv);
            for (int c = 0; c < 3; ++c) mesh.positions.push_back(obj_positions[3 * poly[k] + c]);
          }
          poly[k] = it->second;
        }
      }
      for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
        mesh.indices.push_back(poly[0]);
        mesh.indices.push_back(poly[k]);
        mesh.indices.push_back(poly[k + 1]);
      }
    }
  }
  if (in.bad()) throw Failure{2, path + ": read error"};
  if (mesh.indices.empty()) throw Failure{2, path + ": no faces"};
  mesh.obj_vertices = obj_positions.size() / 3;
  mesh.obj_texcoords = vt_value.size();
  if (!uv_mode) mesh.positions = std::move(obj_positions);
  return mesh;
}

// Writes only the vertices (and, with --uv, the UV values) the triangles use, in first-use order.
// With --uv, the meshoptimizer vertices of one OBJ vertex are written as one `v` again (a seam
// stays a seam, not a crack) and each corner names its UV: `f v/vt`, or `f v` on a face without.
void write_obj_atomic(const std::string& path, const TriMesh& mesh, const std::vector<unsigned>& indices) {
  const std::size_t n = mesh.positions.size() / 3;
  // Output `v` of each meshoptimizer vertex: its own (positions mode) or its OBJ vertex's (--uv).
  std::vector<unsigned> remap(n, ~0u);
  std::vector<unsigned> used;  // a meshoptimizer vertex holding each output `v`'s position
  std::vector<unsigned> obj_remap(mesh.uv_mode ? mesh.obj_vertices : 0, ~0u);
  std::vector<unsigned> uv_remap(mesh.uvs.size() / 2, ~0u);
  std::vector<unsigned> uv_used;
  for (unsigned v : indices) {
    if (remap[v] != ~0u) continue;
    if (!mesh.uv_mode) {
      remap[v] = static_cast<unsigned>(used.size());
      used.push_back(v);
      continue;
    }
    unsigned& o = obj_remap[mesh.obj_vertex[v]];
    if (o == ~0u) {
      o = static_cast<unsigned>(used.size());
      used.push_back(v);
    }
    remap[v] = o;
    unsigned uv = mesh.uv_of[v];
    if (uv != kNoUv && uv_remap[uv] == ~0u) {
      uv_remap[uv] = static_cast<unsigned>(uv_used.size());
      uv_used.push_back(uv);
    }
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
  std::fprintf(f, "# quadlod_meshopt_peer: meshopt_simplify (meshoptimizer %d.%d)%s\n",
               MESHOPTIMIZER_VERSION / 1000, MESHOPTIMIZER_VERSION % 1000 / 10,
               mesh.uv_mode ? ", vertices split by (position, UV)" : "");
  const std::vector<float>& p = mesh.positions;
  for (unsigned v : used) std::fprintf(f, "v %.9g %.9g %.9g\n", p[3 * v], p[3 * v + 1], p[3 * v + 2]);
  for (unsigned uv : uv_used) std::fprintf(f, "vt %.9g %.9g\n", mesh.uvs[2 * uv], mesh.uvs[2 * uv + 1]);
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const unsigned* c = &indices[t];
    bool with_uv = mesh.uv_mode && mesh.uv_of[c[0]] != kNoUv && mesh.uv_of[c[1]] != kNoUv &&
                   mesh.uv_of[c[2]] != kNoUv;
    if (with_uv)
      std::fprintf(f, "f %u/%u %u/%u %u/%u\n", remap[c[0]] + 1, uv_remap[mesh.uv_of[c[0]]] + 1,
                   remap[c[1]] + 1, uv_remap[mesh.uv_of[c[1]]] + 1, remap[c[2]] + 1,
                   uv_remap[mesh.uv_of[c[2]]] + 1);
    else
      std::fprintf(f, "f %u %u %u\n", remap[c[0]] + 1, remap[c[1]] + 1, remap[c[2]] + 1);
  }
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
               "[--target-error E] [--lock-border] [--uv]\n",
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
  bool uv_mode = false;
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
      } else if (a == "--uv") {
        uv_mode = true;
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
    TriMesh mesh = read_obj(positional[0], uv_mode);
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
    std::size_t dropped = 0;
    if (mesh.uv_mode) {
      // Drop triangles with two corners on one OBJ vertex (seam copies: zero area in 3D).
      std::size_t kept = 0;
      for (std::size_t t = 0; t + 2 < out.size(); t += 3) {
        unsigned a = mesh.obj_vertex[out[t]], b = mesh.obj_vertex[out[t + 1]], c = mesh.obj_vertex[out[t + 2]];
        if (a == b || b == c || a == c) {
          ++dropped;
          continue;
        }
        for (int k = 0; k < 3; ++k) out[kept + k] = out[t + k];
        kept += 3;
      }
      out.resize(kept);
      n = kept;
    }
    if (n == 0) throw Failure{2, positional[0] + ": meshopt_simplify removed every triangle"};
    write_obj_atomic(positional[1], mesh, out);
    double t3 = now_seconds();
    std::ostringstream js;
    js.precision(9);
    js << "{\"peer\": \"meshoptimizer\", \"version\": \"" << MESHOPTIMIZER_VERSION / 1000 << "."
       << MESHOPTIMIZER_VERSION % 1000 / 10 << "\", \"input_vertices\": " << vertex_count
       << ", \"input_polygons\": " << mesh.polygons
       << ", \"input_triangles\": " << mesh.indices.size() / 3 << ", \"target_triangles\": " << target_tris
       << ", \"achieved_triangles\": " << n / 3 << ", \"result_error\": " << result_error
       << ", \"lock_border\": " << ((options & meshopt_SimplifyLockBorder) ? "true" : "false")
       << ", \"uv\": " << (mesh.uv_mode ? "true" : "false") << ", \"dropped_triangles\": " << dropped;
    if (mesh.uv_mode)
      js << ", \"input_obj_vertices\": " << mesh.obj_vertices << ", \"input_texcoords\": " << mesh.obj_texcoords
         << ", \"input_uv_values\": " << mesh.uvs.size() / 2
         << ", \"input_polygons_without_uv\": " << mesh.polygons_without_uv;
    js << ", \"seconds_read\": " << (t1 - t0) << ", \"seconds_simplify\": " << (t2 - t1)
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
