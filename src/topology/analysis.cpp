// The analysis stage (paper §3.1–§3.2.4) and its inspection export. See analysis.h.
#include "topology/analysis.h"

#include "quadlod/io.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <system_error>

namespace quadlod {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// --- export -----------------------------------------------------------------------------------

using Rgb = std::array<unsigned, 3>;

// Distinct, deterministic colours: the id is hashed (so ids 7 and 8 differ a lot), the hash
// picks a hue; saturation and value stay high enough to read against a grey mesh.
Rgb palette(Index id) {
  std::uint64_t h = id + 0x9e3779b97f4a7c15ull;
  h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
  h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
  h ^= h >> 31;
  const double hue = double(h & 0xffff) / 65536.0 * 6.0;
  const double sat = 0.65 + 0.35 * double((h >> 16) & 0xff) / 255.0;
  const double val = 0.75 + 0.25 * double((h >> 24) & 0xff) / 255.0;
  const int sector = static_cast<int>(hue) % 6;
  const double f = hue - std::floor(hue);
  const double p = val * (1 - sat), q = val * (1 - sat * f), t = val * (1 - sat * (1 - f));
  double r = 0, g = 0, b = 0;
  switch (sector) {
    case 0: r = val; g = t; b = p; break;
    case 1: r = q; g = val; b = p; break;
    case 2: r = p; g = val; b = t; break;
    case 3: r = p; g = q; b = val; break;
    case 4: r = t; g = p; b = val; break;
    default: r = val; g = p; b = q; break;
  }
  auto byte = [](double x) { return static_cast<unsigned>(std::lround(std::clamp(x, 0.0, 1.0) * 255.0)); };
  return {byte(r), byte(g), byte(b)};
}

struct EdgeLayer {
  std::string name;   // file stem
  std::string group;  // OBJ group prefix
  // (group id, edge) in output order
  std::vector<std::pair<Index, Index>> items;
};

void append_number(std::string& s, double x) {
  char buf[32];
  const int n = std::snprintf(buf, sizeof buf, "%.9g", x);
  s.append(buf, static_cast<std::size_t>(n));
}

// "x y z\n"
void append_point(std::string& s, const Vec3& p) {
  append_number(s, p.x());
  s += ' ';
  append_number(s, p.y());
  s += ' ';
  append_number(s, p.z());
  s += '\n';
}

std::string format_edge_ply(const PolyMesh& mesh, const Connectivity& conn, const EdgeLayer& layer) {
  std::string s;
  s.reserve(64 * (mesh.positions.size() + layer.items.size()) + 256);
  s += "ply\nformat ascii 1.0\ncomment quadlod analysis export: " + layer.name + "\n";
  s += "element vertex " + std::to_string(mesh.positions.size()) + "\n";
  s += "property float x\nproperty float y\nproperty float z\n";
  s += "element edge " + std::to_string(layer.items.size()) + "\n";
  s += "property int vertex1\nproperty int vertex2\n";
  s += "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  for (const Vec3& p : mesh.positions) {
    append_point(s, p);
  }
  for (const auto& [id, e] : layer.items) {
    const Rgb c = palette(id);
    s += std::to_string(conn.edge_vertices[e][0]) + ' ' + std::to_string(conn.edge_vertices[e][1]) + ' ' +
         std::to_string(c[0]) + ' ' + std::to_string(c[1]) + ' ' + std::to_string(c[2]) + '\n';
  }
  return s;
}

std::string format_edge_obj(const PolyMesh& mesh, const Connectivity& conn, const EdgeLayer& layer) {
  std::string s;
  s.reserve(40 * (mesh.positions.size() + layer.items.size()) + 256);
  s += "# quadlod analysis export: " + layer.name + " (polylines grouped by " + layer.group + "_N)\n";
  for (const Vec3& p : mesh.positions) {
    s += "v ";
    append_point(s, p);
  }
  Index current = kInvalidIndex;
  for (const auto& [id, e] : layer.items) {
    if (id != current) {
      s += "g " + layer.group + "_" + std::to_string(id) + "\n";
      current = id;
    }
    s += "l " + std::to_string(conn.edge_vertices[e][0] + 1) + ' ' +
         std::to_string(conn.edge_vertices[e][1] + 1) + '\n';
  }
  return s;
}

}  // namespace

AnalysisResult analyze(const PolyMesh& mesh, const Connectivity& conn, const AnalysisParams& params) {
  AnalysisResult r;
  const auto t0 = Clock::now();
  auto t = t0;
  r.polychords = extract_polychords(mesh, conn, params.polychords);
  r.timings.polychords_ms = ms_since(t);
  t = Clock::now();
  r.segmentation = segment_polychords(mesh, conn, r.polychords, params.segmentation);
  r.timings.segmentation_ms = ms_since(t);
  t = Clock::now();
  if (params.clusters) r.medial = cluster_medial_curves(mesh, conn, r.polychords, params.medial);
  r.timings.medial_ms = ms_since(t);
  t = Clock::now();
  if (params.clusters) r.triangles = cluster_triangle_regions(mesh, conn, params.triangles);
  r.timings.triangles_ms = ms_since(t);
  r.timings.total_ms = ms_since(t0);
  return r;
}

std::string analysis_summary(const PolyMesh& mesh, const AnalysisResult& r) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "analysis: %u faces, %zu chords, %zu segments, %zu quad clusters, %zu tri clusters in "
                "%.1f ms (chords %.1f, segments %.1f, medial %.1f, triangles %.1f)",
                mesh.num_faces(), r.polychords.chords.size(), r.segmentation.segments.size(),
                r.medial.clusters.size(), r.triangles.clusters.size(), r.timings.total_ms,
                r.timings.polychords_ms, r.timings.segmentation_ms, r.timings.medial_ms,
                r.timings.triangles_ms);
  return buf;
}

std::string write_analysis_export(const PolyMesh& mesh, const Connectivity& conn,
                                  const AnalysisResult& result, const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return "cannot create " + dir.string() + ": " + ec.message();

  std::vector<EdgeLayer> layers(4);
  layers[0] = {"chords", "chord", {}};
  for (Index c = 0; c < result.polychords.chords.size(); ++c)
    for (Index e : result.polychords.chords[c].opposing_edges) layers[0].items.emplace_back(c, e);
  layers[1] = {"segments", "segment", {}};
  for (Index s = 0; s < result.segmentation.segments.size(); ++s)
    for (Index e : result.segmentation.segments[s].opposing_edges) layers[1].items.emplace_back(s, e);
  layers[2] = {"quad_clusters", "cluster", {}};
  for (Index k = 0; k < result.medial.clusters.size(); ++k)
    for (Index e : result.medial.clusters[k].edges) layers[2].items.emplace_back(k, e);
  layers[3] = {"triangle_clusters", "tricluster", {}};
  for (Index k = 0; k < result.triangles.clusters.size(); ++k)
    for (Index e : result.triangles.clusters[k].edges) layers[3].items.emplace_back(k, e);

  for (const EdgeLayer& layer : layers) {
    WriteResult w = write_file_atomically(dir / (layer.name + ".ply"), format_edge_ply(mesh, conn, layer));
    if (!w.ok()) return w.error;
    w = write_file_atomically(dir / (layer.name + ".obj"), format_edge_obj(mesh, conn, layer));
    if (!w.ok()) return w.error;
  }
  WriteOptions options;
  options.ply_encoding = PlyEncoding::Ascii;
  for (const char* name : {"mesh.ply", "mesh.obj"}) {
    const WriteResult w = write_mesh(mesh, dir / name, options);
    if (!w.ok()) return w.error;
  }
  return {};
}

}  // namespace quadlod
