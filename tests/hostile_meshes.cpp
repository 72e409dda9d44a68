// The catalogue of hostile meshes (see hostile_meshes.h). Geometry is written as text (OBJ /
// OFF / ASCII PLY) or little-endian binary PLY straight to an ofstream.
#include "hostile_meshes.h"

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>

namespace quadlod::hostile {

namespace {

namespace fs = std::filesystem;
using Vertex = std::array<double, 3>;
using Face = std::vector<std::int64_t>;  // 0-based

// An OBJ of the given vertices and faces (written 1-based).
void write_obj(const fs::path& path, const std::vector<Vertex>& vertices, const std::vector<Face>& faces) {
  std::ofstream out(path, std::ios::binary);
  out.precision(17);
  for (const Vertex& v : vertices) out << "v " << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
  for (const Face& f : faces) {
    out << 'f';
    for (std::int64_t i : f) out << ' ' << i + 1;
    out << '\n';
  }
}

// An n × m quad grid in the unit square, vertex (i, j) = j * (n + 1) + i.
void grid(int n, int m, std::vector<Vertex>& vertices, std::vector<Face>& faces) {
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= n; ++i) vertices.push_back({double(i) / n, double(j) / m, 0.0});
  const auto id = [n](int i, int j) { return std::int64_t{j} * (n + 1) + i; };
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
}

// A closed n × m quad surface that wraps in u (period n) and in v (period m); `flip_u` /
// `flip_v` glue the wrap of that direction with a reflection (Möbius / Klein). Only the
// connectivity matters; positions follow `place(u, v)` with u in [0, n), v in [0, m].
void wrapped(int n, int m, bool wrap_v, bool flip_v, std::function<Vertex(int, int)> place,
             std::vector<Vertex>& vertices, std::vector<Face>& faces) {
  const int rows = wrap_v ? m : m + 1;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < n; ++i) vertices.push_back(place(i, j));
  // The u-wrap: column n is column 0 with the rows reversed when the strip is twisted.
  const auto id = [&](int i, int j) -> std::int64_t {
    if (i == n) {
      i = 0;
      if (flip_v) j = (wrap_v ? (m - j) % m : m - j);
    }
    if (wrap_v) j %= m;
    return std::int64_t{j} * n + i;
  };
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
}

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

template <class T>
void put_le(std::ofstream& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.write(bytes, sizeof(T));
}

// Binary PLY: a triangle 0 1 2 and one face whose last index is `index` (int32).
void write_ply_index(const fs::path& path, std::int32_t index) {
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (float c : xyz) put_le(out, c);
  put_le<std::uint8_t>(out, 3);
  for (std::int32_t i : {0, 1, 2}) put_le(out, i);
  put_le<std::uint8_t>(out, 3);
  for (std::int32_t i : {0, 1, index}) put_le(out, i);
}

// A closed poly-chord that crosses itself `crossings` times. Quads X_0 … X_{k-1} form a row
// (pass 1 runs through their left and right edges); pass 2 comes back through their top and
// bottom edges, from X_{k-1} down to X_0, and between X_i and X_{i-1} a ribbon of quads loops
// under the row from X_i's bottom edge to X_{i-1}'s top edge. Two closing ribbons join the
// passes (X_{k-1}'s right edge to its top edge, X_0's bottom edge to its left edge), so the
// chord of the row is one closed loop through every X_i twice, crossing itself there.
void chord_crossings(int crossings, std::vector<Vertex>& vertices, std::vector<Face>& faces) {
  const int k = crossings;
  const auto B = [](int i) { return std::int64_t{2} * i; };
  const auto T = [](int i) { return std::int64_t{2} * i + 1; };
  for (int i = 0; i <= k; ++i) {
    vertices.push_back({double(i), 0.0, 0.0});
    vertices.push_back({double(i), 1.0, 0.0});
  }
  for (int i = 0; i < k; ++i) faces.push_back({B(i), B(i + 1), T(i + 1), T(i)});
  constexpr int kSteps = 4;  // quads per ribbon
  // A ribbon from edge (a0, a1) to edge (b0, b1): side a0 → b0 and side a1 → b1, kSteps - 1
  // intermediate vertex pairs on an arc through `bulge`.
  const auto ribbon = [&](std::int64_t a0, std::int64_t a1, std::int64_t b0, std::int64_t b1, Vertex bulge) {
    std::int64_t p0 = a0, p1 = a1;
    for (int s = 1; s <= kSteps; ++s) {
      std::int64_t q0 = b0, q1 = b1;
      if (s < kSteps) {
        const double t = double(s) / kSteps, lift = std::sin(std::numbers::pi * t);
        for (auto [from, to] : {std::pair{a0, b0}, std::pair{a1, b1}}) {
          Vertex v;
          for (int c = 0; c < 3; ++c)
            v[c] = (1 - t) * vertices[from][c] + t * vertices[to][c] + lift * bulge[c];
          vertices.push_back(v);
        }
        q0 = std::int64_t(vertices.size()) - 2;
        q1 = std::int64_t(vertices.size()) - 1;
      }
      faces.push_back({p0, p1, q1, q0});
      p0 = q0;
      p1 = q1;
    }
  };
  for (int i = k - 1; i >= 1; --i) ribbon(B(i), B(i + 1), T(i - 1), T(i), {0.0, 0.5, -0.8});
  ribbon(B(k), T(k), T(k), T(k - 1), {0.6, 0.3, 0.5});  // right edge of X_{k-1} → its top
  ribbon(B(1), B(0), B(0), T(0), {-0.6, -0.3, 0.5});    // bottom edge of X_0 → its left
}

}  // namespace

std::vector<HostileCase> catalogue(int components) {
  std::vector<HostileCase> cases;
  const auto add = [&](std::string name, std::string ext, std::string description, Expect expect,
                       std::string message_has, std::uint64_t faces, std::function<void(const fs::path&)> write,
                       std::uint64_t vertices = 0) {
    cases.push_back({std::move(name), std::move(ext), std::move(description), expect, std::move(message_has), faces,
                     vertices, std::move(write)});
  };
  const auto refuse = Expect::Refusal;
  const auto either = Expect::RefusalOrOutput;

  // --- headers and indices at the 32-bit limits -------------------------------------------------
  add("ply_header_2e31_vertices", ".ply", "PLY header claims 2^31 vertices, holds 3", refuse, "vertices", 1,
      [](const fs::path& p) {
        write_text(p, "ply\nformat ascii 1.0\nelement vertex 2147483648\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
      });
  add("ply_header_2e31_faces", ".ply", "binary PLY header claims 2^31 - 1 faces, holds 1", refuse, "2147483647", 1,
      [](const fs::path& p) {
        std::ofstream out(p, std::ios::binary);
        out << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
               "property float z\nelement face 2147483647\nproperty list uchar int vertex_indices\nend_header\n";
        for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put_le(out, c);
        put_le<std::uint8_t>(out, 3);
        for (std::int32_t i : {0, 1, 2}) put_le(out, i);
      });
  add("off_header_2e31", ".off", "OFF header claims 2^31 vertices and faces", refuse, "2147483648", 0,
      [](const fs::path& p) { write_text(p, "OFF\n2147483648 2147483648 0\n0 0 0\n"); });
  add("obj_index_2e31_minus_1", ".obj", "OBJ face index 2^31 - 1 (3 vertices defined)", refuse, "vertex", 1,
      [](const fs::path& p) { write_text(p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2147483647\n"); });
  add("obj_index_minus_2e31", ".obj", "OBJ face index -2^31 (relative, 3 vertices defined)", refuse, "vertex", 1,
      [](const fs::path& p) { write_text(p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -2147483648\n"); });
  add("ply_index_2e31_minus_1", ".ply", "binary PLY face index 2^31 - 1", refuse, "vertex", 2,
      [](const fs::path& p) { write_ply_index(p, 2147483647); });
  add("ply_index_minus_2e31", ".ply", "binary PLY face index -2^31", refuse, "", 2,
      [](const fs::path& p) { write_ply_index(p, std::numeric_limits<std::int32_t>::min()); });

  // --- shapes ---------------------------------------------------------------------------------
  add("ngon_100k", ".obj", "one face with 100 000 corners (a circle)", either, "", 1, [](const fs::path& p) {
    std::vector<Vertex> v;
    Face f;
    for (int i = 0; i < 100000; ++i) {
      const double a = 2 * std::numbers::pi * i / 100000;
      v.push_back({std::cos(a), std::sin(a), 0.0});
      f.push_back(i);
    }
    write_obj(p, v, {f});
  });
  add("one_point", ".obj", "32 × 32 quad grid with every vertex on one point", either, "", 1024, [](const fs::path& p) {
    std::vector<Vertex> v;
    std::vector<Face> f;
    grid(32, 32, v, f);
    for (Vertex& x : v) x = {1.0, 1.0, 1.0};
    write_obj(p, v, f);
  });
  add("zero_area_strip", ".obj", "strip of 1000 quads, all corners on one line", either, "", 1000, [](const fs::path& p) {
    std::vector<Vertex> v;
    std::vector<Face> f;
    grid(1000, 1, v, f);
    for (Vertex& x : v) x = {x[0] + 0.37 * x[1], 0.0, 0.0};
    write_obj(p, v, f);
  });
  add("collinear_quad", ".obj", "one quad whose four corners are collinear", either, "", 1, [](const fs::path& p) {
    write_text(p, "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3 4\n");
  });
  add("mobius", ".obj", "Möbius strip, 96 × 4 quads (non-orientable, one boundary)", either, "", 384, [](const fs::path& p) {
    std::vector<Vertex> v;
    std::vector<Face> f;
    const int n = 96, m = 4;
    wrapped(n, m, false, true, [&](int i, int j) -> Vertex {
      const double a = 2 * std::numbers::pi * i / n, w = (double(j) / m - 0.5) * 0.6;
      return {(1 + w * std::cos(a / 2)) * std::cos(a), (1 + w * std::cos(a / 2)) * std::sin(a), w * std::sin(a / 2)};
    }, v, f);
    write_obj(p, v, f);
  });
  add("klein_bottle", ".obj", "Klein bottle, 48 × 16 quads (closed, non-orientable)", either, "", 768, [](const fs::path& p) {
    std::vector<Vertex> v;
    std::vector<Face> f;
    const int n = 48, m = 16;
    // Figure-8 immersion: a tube whose cross-section turns half a revolution around the loop.
    wrapped(n, m, true, true, [&](int i, int j) -> Vertex {
      const double u = 2 * std::numbers::pi * i / n, t = 2 * std::numbers::pi * j / m, r = 2.0;
      const double a = r + std::cos(u / 2) * std::sin(t) - std::sin(u / 2) * std::sin(2 * t);
      return {a * std::cos(u), a * std::sin(u), std::sin(u / 2) * std::sin(t) + std::cos(u / 2) * std::sin(2 * t)};
    }, v, f);
    write_obj(p, v, f);
  });
  add("fins_everywhere", ".obj", "30 × 30 grid with a fin quad on every edge (3-5 faces per edge)", either, "", 900 + 1860,
      [](const fs::path& p) {
        std::vector<Vertex> v;
        std::vector<Face> f;
        const int n = 30;
        grid(n, n, v, f);
        const std::int64_t base = std::int64_t(v.size());
        for (std::int64_t i = 0; i < base; ++i) v.push_back({v[i][0], v[i][1], 0.1});
        const auto id = [](int i, int j) { return std::int64_t{j} * (n + 1) + i; };
        for (int j = 0; j <= n; ++j)
          for (int i = 0; i <= n; ++i) {
            if (i < n) f.push_back({id(i, j), id(i + 1, j), base + id(i + 1, j), base + id(i, j)});
            if (j < n) f.push_back({id(i, j), id(i, j + 1), base + id(i, j + 1), base + id(i, j)});
          }
        write_obj(p, v, f);
      });
  add("components_" + std::to_string(components / 1000) + "k", ".obj",
      std::to_string(components / 1000) + " 000 separate one-quad components", either, "", components,
      [components](const fs::path& p) {
    std::vector<Vertex> v;
    std::vector<Face> f;
    for (int k = 0; k < components; ++k) {
      const double x = (k % 400) * 2.0, y = (k / 400) * 2.0;
      const std::int64_t b = std::int64_t(v.size());
      for (auto [dx, dy] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) v.push_back({x + dx, y + dy, 0.0});
      f.push_back({b, b + 1, b + 2, b + 3});
    }
    write_obj(p, v, f);
  }, 4 * std::uint64_t(components));
  add("chord_crossing_1000", ".obj", "one closed poly-chord crossing itself 1000 times", either, "", 5000, [](const fs::path& p) {
    std::vector<Vertex> v;
    std::vector<Face> f;
    chord_crossings(1000, v, f);
    write_obj(p, v, f);
  });

  // --- numbers --------------------------------------------------------------------------------
  add("coords_1e38", ".obj", "32 × 32 grid scaled to 1e38 (squares overflow float)", either, "", 1024, [](const fs::path& p) {
    std::vector<Vertex> v;
    std::vector<Face> f;
    grid(32, 32, v, f);
    for (Vertex& x : v) x = {x[0] * 1e38, x[1] * 1e38, (x[0] * x[1]) * 1e38};
    write_obj(p, v, f);
  });
  add("coords_1e-38", ".obj", "32 × 32 grid scaled to 1e-38 (squares underflow)", either, "", 1024, [](const fs::path& p) {
    std::vector<Vertex> v;
    std::vector<Face> f;
    grid(32, 32, v, f);
    for (Vertex& x : v) x = {x[0] * 1e-38, x[1] * 1e-38, (x[0] * x[1]) * 1e-38};
    write_obj(p, v, f);
  });
  add("uv_missing_on_some_corners", ".obj", "16 × 16 grid, UVs on every corner but one per face", either, "", 256,
      [](const fs::path& p) {
        std::vector<Vertex> v;
        std::vector<Face> f;
        grid(16, 16, v, f);
        std::ofstream out(p, std::ios::binary);
        for (const Vertex& x : v) out << "v " << x[0] << ' ' << x[1] << ' ' << x[2] << '\n';
        for (const Vertex& x : v) out << "vt " << x[0] << ' ' << x[1] << '\n';
        for (const Face& face : f) {
          out << 'f';
          for (std::size_t c = 0; c < face.size(); ++c) {
            out << ' ' << face[c] + 1;
            if (c != 0) out << '/' << face[c] + 1;
          }
          out << '\n';
        }
      });
  add("line_2gb", ".obj", "a triangle, then one 2 GiB comment line (streamed, never in memory)", refuse, "memory", 1,
      [](const fs::path& p) {
        std::ofstream out(p, std::ios::binary);
        out << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n#";
        const std::string block(1 << 20, 'x');
        for (int i = 0; i < 2048; ++i) out.write(block.data(), std::streamsize(block.size()));
        out << '\n';
      });
  return cases;
}

}  // namespace quadlod::hostile
