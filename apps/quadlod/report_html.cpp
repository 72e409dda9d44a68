// The HTML report (see report_html.h). The page is: a header with the overlay switches, one view
// per mesh (drawn by viewer.js into one canvas, one camera), a legend, and the metrics table.
// Mesh data travel as base64 typed arrays in a JSON block; three.js travels as text in a
// `text/plain` script block that viewer.js imports through a blob URL, so nothing is fetched.
#ifdef QUADLOD_HTML_REPORT

#include "report_html.h"

#include "geometry/bvh.h"
#include "mesh/connectivity.h"
#include "topology/polychords.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cctype>
#include <cstring>
#include <functional>

extern const unsigned char quadlod_asset_three_js[];
extern const std::size_t quadlod_asset_three_js_size;
extern const unsigned char quadlod_asset_viewer_js[];
extern const std::size_t quadlod_asset_viewer_js_size;
extern const unsigned char quadlod_asset_viewer_css[];
extern const std::size_t quadlod_asset_viewer_css_size;

namespace quadlod::cli {

namespace {

std::string_view asset(const unsigned char* bytes, std::size_t size) {
  return {reinterpret_cast<const char*>(bytes), size};
}

std::string base64(const void* data, std::size_t bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes; i += 3) {
    const unsigned v = (unsigned(p[i]) << 16) | (i + 1 < bytes ? unsigned(p[i + 1]) << 8 : 0u) |
                       (i + 2 < bytes ? unsigned(p[i + 2]) : 0u);
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes ? table[v & 63] : '=';
  }
  return out;
}

template <class T>
std::string base64(const std::vector<T>& values) {
  return base64(values.data(), values.size() * sizeof(T));
}

/// JavaScript placed inside <script> must neither close it nor open an HTML comment: "</script" →
/// "<\/script", "<!--" → "<\!--" (the same text to JS string and regex literals, where these occur).
std::string script_safe(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] != '<' || i + 1 >= text.size()) continue;
    if (text[i + 1] == '!' && text.substr(i + 1, 3) == "!--") out += '\\';
    if (text[i + 1] == '/' && text.size() >= i + 8) {
      std::string word(text.substr(i + 2, 6));
      for (char& c : word) c = char(std::tolower(static_cast<unsigned char>(c)));
      if (word == "script") out += '\\';
    }
  }
  return out;
}

/// JSON placed inside <script>: every '<' (they occur only inside strings) as \u003c, which
/// closes nothing, opens no comment and is the same string to JSON.parse.
std::string json_script_safe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (char c : json) {
    if (c == '<') out += "\\u003c";
    else out += c;
  }
  return out;
}

std::string html_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// The maps p ↦ s·(p − c) of the metrics (include/quadlod/metrics.h).
struct Normalisation {
  Vec3 centre = Vec3::Zero();
  double scale = 1.0;
  Vec3 operator()(const Vec3& p) const { return scale * (p - centre); }
};

std::vector<std::array<Vec3, 3>> fan_triangles(const PolyMesh& mesh, const Normalisation& norm) {
  std::vector<std::array<Vec3, 3>> tris;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const auto v = mesh.face_vertices(f);
    for (Index k = 1; k + 1 < v.size(); ++k)
      tris.push_back({norm(mesh.positions[v[0]]), norm(mesh.positions[v[k]]), norm(mesh.positions[v[k + 1]])});
  }
  return tris;
}

/// One mesh's drawing data: positions, fan triangles with their face's kind, polygon edges,
/// poly-chord medial curves as segments.
nlohmann::json mesh_data(const PolyMesh& mesh, const Normalisation& norm, const std::string& label) {
  std::vector<float> positions;
  positions.reserve(3 * mesh.num_vertices());
  for (const Vec3& p : mesh.positions) {
    const Vec3 q = norm(p);
    positions.insert(positions.end(), {float(q.x()), float(q.y()), float(q.z())});
  }
  std::vector<std::uint32_t> triangles;
  std::vector<std::uint8_t> triangle_kind;  // 0 triangle, 1 quad, 2 n-gon (the face it comes from)
  std::uint64_t quads = 0, tris = 0, ngons = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const auto v = mesh.face_vertices(f);
    const std::uint8_t kind = v.size() == 3 ? 0 : v.size() == 4 ? 1 : 2;
    (kind == 0 ? tris : kind == 1 ? quads : ngons) += 1;
    for (Index k = 1; k + 1 < v.size(); ++k) {
      triangles.insert(triangles.end(), {v[0], v[k], v[k + 1]});
      triangle_kind.push_back(kind);
    }
  }
  const Connectivity conn = build_connectivity(mesh);
  std::vector<std::uint32_t> edges;
  edges.reserve(2 * conn.num_edges);
  for (const auto& e : conn.edge_vertices) edges.insert(edges.end(), {e[0], e[1]});
  const PolyChordResult chords = extract_polychords(mesh, conn);
  std::vector<float> chord_segments;
  std::vector<std::uint32_t> chord_of_segment;
  for (Index c = 0; c < chords.chords.size(); ++c) {
    std::vector<Vec3> curve = medial_curve(mesh, conn, chords.chords[c]);
    if (chords.chords[c].closed && !curve.empty()) curve.push_back(curve.front());
    for (std::size_t i = 0; i + 1 < curve.size(); ++i) {
      const Vec3 a = norm(curve[i]), b = norm(curve[i + 1]);
      chord_segments.insert(chord_segments.end(),
                            {float(a.x()), float(a.y()), float(a.z()), float(b.x()), float(b.y()), float(b.z())});
      chord_of_segment.push_back(c);
    }
  }
  return {
      {"label", label},
      {"vertices", mesh.num_vertices()},
      {"faces", mesh.num_faces()},
      {"quads", quads},
      {"triangles", tris},
      {"ngons", ngons},
      {"tri_equivalent", tri_equivalent_count(mesh)},
      {"chords", chords.chords.size()},
      {"positions", base64(positions)},
      {"triangle_vertices", base64(triangles)},
      {"triangle_kind", base64(triangle_kind)},
      {"edges", base64(edges)},
      {"chord_segments", base64(chord_segments)},
      {"chord_of_segment", base64(chord_of_segment)},
  };
}

/// Distance of every vertex of `mesh` used by a face to the input surface (normalised units);
/// unused vertices get 0.
std::vector<float> vertex_distances(const PolyMesh& mesh, const Normalisation& norm, const TriangleBvh& input) {
  std::vector<std::uint8_t> used(mesh.num_vertices(), 0);
  for (Index v : mesh.corner_vertex) used[v] = 1;
  std::vector<float> d(mesh.num_vertices(), 0.0f);
  Index hint = kInvalidIndex;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (!used[v]) continue;
    const NearestHit hit = input.nearest(norm(mesh.positions[v]), hint);
    hint = hit.primitive;
    d[v] = float(std::sqrt(hit.distance_sq));
  }
  return d;
}

std::string number(double v, const char* format = "%.4g") {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

/// The metrics table: one row per metric of `quadlod eval`, one column per output.
std::string metrics_table(const std::vector<HtmlReportColumn>& outputs, const std::vector<EvalResult>& results,
                          const PolyMesh& input) {
  struct Row {
    std::string name, help;
    std::function<std::string(const EvalResult&)> cell;
  };
  auto u = [](std::uint64_t v) { return std::to_string(v); };
  const std::vector<Row> rows = {
      {"triangle-equivalents", "quad = 2, k-gon = k − 2 (input " + std::to_string(tri_equivalent_count(input)) + ")",
       [&](const EvalResult& r) { return u(r.counts_out.tri_equivalent); }},
      {"faces (quads / tris / n-gons)", "",
       [&](const EvalResult& r) {
         return u(r.counts_out.faces) + " (" + u(r.counts_out.quads) + " / " + u(r.counts_out.tris) + " / " +
                u(r.counts_out.ngons) + ")";
       }},
      {"quad fraction", "quads / faces", [&](const EvalResult& r) { return number(r.quad_fraction_out, "%.3f"); }},
      {"QPR", "quad preservation ratio (Knodt 2025)", [&](const EvalResult& r) { return number(r.qpr, "%.3f"); }},
      {"Chamfer", "mean surface distance, both ways (unit bbox)", [&](const EvalResult& r) { return number(r.chamfer, "%.3e"); }},
      {"Hausdorff", "largest surface distance (unit bbox)", [&](const EvalResult& r) { return number(r.hausdorff, "%.3e"); }},
      {"PCCD", "poly-chord Chamfer distance", [&](const EvalResult& r) { return r.pccd_defined ? number(r.pccd, "%.3e") : "undefined"; }},
      {"flow deviation", "mean / p90 angle to the input's quad edges (degrees)",
       [&](const EvalResult& r) { return number(r.flow_deviation_deg, "%.2f") + " / " + number(r.flow_deviation_p90_deg, "%.2f"); }},
      {"UV seams torn", "", [&](const EvalResult& r) { return u(r.seams_torn); }},
      {"UV islands", "input → output (merged)",
       [&](const EvalResult& r) { return u(r.uv_islands_in) + " → " + u(r.uv_islands_out) + " (" + u(r.uv_islands_merged) + ")"; }},
      {"UV error", "mean / max, of the island's UV diagonal",
       [&](const EvalResult& r) { return number(r.uv_error_mean, "%.2e") + " / " + number(r.uv_error_max, "%.2e"); }},
      {"material border error", "max (unit bbox)", [&](const EvalResult& r) { return number(r.material_border_error, "%.2e"); }},
      {"feature deviation", "max (unit bbox)", [&](const EvalResult& r) { return number(r.feature_deviation_max, "%.2e"); }},
      {"flipped faces", "", [&](const EvalResult& r) { return u(r.flipped_faces); }},
  };
  std::string html = "<table id=\"metrics\"><thead><tr><th>metric</th>";
  for (const HtmlReportColumn& c : outputs) html += "<th>" + html_escape(c.label) + "</th>";
  html += "</tr></thead><tbody>\n";
  for (const Row& row : rows) {
    html += "<tr><th title=\"" + html_escape(row.help) + "\">" + html_escape(row.name) + "</th>";
    for (const EvalResult& r : results) html += "<td>" + html_escape(row.cell(r)) + "</td>";
    html += "</tr>\n";
  }
  return html + "</tbody></table>\n";
}

}  // namespace

HtmlReportResult build_html_report(const HtmlReportColumn& input, const std::vector<HtmlReportColumn>& outputs,
                                   const HtmlReportParams& params) {
  HtmlReportResult out;
  const BoundingBox box = bounding_box(*input.mesh);
  if (box.empty() || !(box.longest_side() > 0)) {
    out.error = input.label + ": the input's bounding box has zero size";
    return out;
  }
  Normalisation norm;
  norm.centre = 0.5 * (box.min + box.max);
  norm.scale = 1.0 / box.longest_side();

  std::vector<EvalResult> results;
  for (const HtmlReportColumn& c : outputs) {
    EvalResult r = evaluate(*input.mesh, *c.mesh, params.eval);
    if (!r.ok()) {
      out.error = c.label + ": " + r.error;
      return out;
    }
    if (params.progress)
      std::fprintf(stderr, "report: %s: chamfer %.3e, hausdorff %.3e (%.2f s)\n", c.label.c_str(), r.chamfer,
                   r.hausdorff, r.seconds);
    results.push_back(std::move(r));
  }

  const std::vector<std::array<Vec3, 3>> input_triangles = fan_triangles(*input.mesh, norm);
  const TriangleBvh input_surface(input_triangles);
  nlohmann::json columns = nlohmann::json::array();
  columns.push_back(mesh_data(*input.mesh, norm, input.label));
  columns.back()["role"] = "input";
  std::vector<float> all_distances;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    nlohmann::json column = mesh_data(*outputs[i].mesh, norm, outputs[i].label);
    const std::vector<float> d = vertex_distances(*outputs[i].mesh, norm, input_surface);
    all_distances.insert(all_distances.end(), d.begin(), d.end());
    column["role"] = "output";
    column["heat"] = base64(d);
    column["chamfer"] = results[i].chamfer;
    column["hausdorff"] = results[i].hausdorff;
    columns.push_back(std::move(column));
  }
  double heat_max = 0.0, heat_top = 0.0;
  if (!all_distances.empty()) {
    std::sort(all_distances.begin(), all_distances.end());
    const std::size_t q = std::min(all_distances.size() - 1,
                                   std::size_t(params.heat_quantile * double(all_distances.size() - 1)));
    heat_max = all_distances[q];
    heat_top = all_distances.back();
  }
  if (!(heat_max > 0)) heat_max = std::max(heat_top, 1e-6);
  const nlohmann::json data = {
      {"title", params.title},
      {"columns", columns},
      {"heat_max", heat_max},
      {"heat_top", heat_top},
  };

  std::string& html = out.html;
  html += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" + html_escape(params.title) +
          "</title>\n<meta name=\"generator\" content=\"quadlod 0.1.0\">\n<style>\n";
  html += asset(quadlod_asset_viewer_css, quadlod_asset_viewer_css_size);
  html += "</style></head>\n<body>\n<header><h1>" + html_escape(params.title) + "</h1>\n"
          "<label><input type=\"checkbox\" id=\"show-wire\" checked> wireframe</label>\n"
          "<label><input type=\"checkbox\" id=\"show-chords\"> poly-chords</label>\n"
          "<label><input type=\"checkbox\" id=\"show-heat\"> distance to the input</label>\n"
          "<label><input type=\"checkbox\" id=\"z-up\"> Z up</label>\n"
          "<button id=\"reset-view\">reset view</button>\n"
          "<span class=\"hint\">drag: rotate · shift/right-drag: pan · wheel: zoom — all views move together</span>\n"
          "</header>\n<div id=\"views\"><canvas id=\"canvas\"></canvas><div id=\"labels\"></div></div>\n"
          "<div id=\"legend\"></div>\n<h2>Metrics of each output against " + html_escape(input.label) +
          " (as <code>quadlod eval</code>)</h2>\n";
  html += metrics_table(outputs, results, *input.mesh);
  html += "<p class=\"note\">Distances in units of the input's longest bounding-box side; " +
          std::to_string(params.eval.samples) + " surface samples per direction, seed " +
          std::to_string(params.eval.seed) + " (docs/metrics.md). Heat map: each output vertex's distance to the "
          "input surface, scale 0 to " + number(heat_max, "%.3e") + " (" +
          number(100 * params.heat_quantile, "%.0f") + "th percentile; largest " + number(heat_top, "%.3e") + ").</p>\n";
  html += "<script type=\"application/json\" id=\"quadlod-data\">" + json_script_safe(data.dump()) + "</script>\n";
  html += "<script type=\"text/plain\" id=\"three-src\">";
  html += script_safe(asset(quadlod_asset_three_js, quadlod_asset_three_js_size));
  html += "</script>\n<script type=\"module\">\n";
  html += script_safe(asset(quadlod_asset_viewer_js, quadlod_asset_viewer_js_size));
  html += "</script>\n</body></html>\n";
  return out;
}

}  // namespace quadlod::cli

#endif  // QUADLOD_HTML_REPORT
