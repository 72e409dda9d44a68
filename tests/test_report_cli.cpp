// `quadlod report` and `simplify --report-html` (issue 22): the page's data against known
// answers (a grid's counts, edges and poly-chord segments; zero distance of a mesh to itself;
// the heat map bounded by eval's Hausdorff distance), the metrics table's columns, the page being
// self-contained and script-safe, and the CLI's refusals. Rendering is tested in headless
// Chromium (tests/report/check_report_page.py).
#ifdef QUADLOD_HTML_REPORT

#include "cli_runner.h"

#include "quadlod/io.h"

#include <nlohmann/json.hpp>

#include <cstring>
#include <regex>

namespace quadlod::testing {
namespace {

std::vector<unsigned char> base64_decode(const std::string& text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::vector<unsigned char> out;
  unsigned buffer = 0;
  int bits = 0;
  for (char c : text) {
    const int v = value(c);
    if (v < 0) break;  // '=' padding
    buffer = (buffer << 6) | unsigned(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((buffer >> bits) & 0xff));
    }
  }
  return out;
}

template <class T>
std::vector<T> decode_array(const nlohmann::json& j) {
  const std::vector<unsigned char> bytes = base64_decode(j.get<std::string>());
  EXPECT_EQ(bytes.size() % sizeof(T), 0u);
  std::vector<T> values(bytes.size() / sizeof(T));
  std::memcpy(values.data(), bytes.data(), values.size() * sizeof(T));
  return values;
}

nlohmann::json page_data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"quadlod-data\">";
  const auto begin = html.find(open);
  EXPECT_NE(begin, std::string::npos);
  const auto end = html.find("</script>", begin);
  return nlohmann::json::parse(html.substr(begin + open.size(), end - begin - open.size()));
}

int metric_columns(const std::string& html) {
  std::smatch m;
  const std::regex head("<table id=\"metrics\"><thead><tr>(.*?)</tr>");
  if (!std::regex_search(html, m, head)) return -1;
  const std::string row = m[1];
  int n = 0;
  for (auto p = row.find("<th>"); p != std::string::npos; p = row.find("<th>", p + 1)) ++n;
  return n - 1;  // the first head is "metric"
}

class ReportCli : public ScratchDirTest {};

TEST_F(ReportCli, GridDataMatchesItsKnownCounts) {
  const auto grid = dir / "grid.obj";
  ASSERT_EQ(run_cli("-q generate grid --n 6 --m 4 -o '" + grid.string() + "'", dir).exit_code, 0);
  const auto page = dir / "grid.html";
  // The grid against itself: every distance is zero.
  const CliRun run = run_cli("-q report '" + grid.string() + "' '" + grid.string() + "' -o '" + page.string() +
                                 "' --samples 2000",
                             dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string html = slurp(page);
  const nlohmann::json data = page_data(html);
  ASSERT_EQ(data["columns"].size(), 2u);
  for (const nlohmann::json& column : data["columns"]) {
    EXPECT_EQ(column["vertices"], 7 * 5);
    EXPECT_EQ(column["faces"], 24);
    EXPECT_EQ(column["quads"], 24);
    EXPECT_EQ(column["tri_equivalent"], 48);
    EXPECT_EQ(column["chords"], 6 + 4);
    EXPECT_EQ(decode_array<float>(column["positions"]).size(), 3u * 35);
    EXPECT_EQ(decode_array<std::uint32_t>(column["triangle_vertices"]).size(), 3u * 48);  // 2 fan triangles per quad
    EXPECT_EQ(decode_array<std::uint8_t>(column["triangle_kind"]), std::vector<std::uint8_t>(48, 1));
    EXPECT_EQ(decode_array<std::uint32_t>(column["edges"]).size(), 2u * (7 * 4 + 6 * 5));
    // Every quad lies on two chords and adds one medial-curve segment to each.
    EXPECT_EQ(decode_array<float>(column["chord_segments"]).size(), 6u * 2 * 24);
    EXPECT_EQ(decode_array<std::uint32_t>(column["chord_of_segment"]).size(), 2u * 24);
  }
  EXPECT_EQ(data["columns"][0]["role"], "input");
  EXPECT_FALSE(data["columns"][0].contains("heat"));
  for (float d : decode_array<float>(data["columns"][1]["heat"])) EXPECT_EQ(d, 0.0f);
  EXPECT_EQ(data["heat_top"], 0.0);
  EXPECT_EQ(metric_columns(html), 1);
  // Self-contained: nothing to fetch.
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
}

TEST_F(ReportCli, HeatMapIsBoundedByEvalHausdorffAndOneColumnPerOutput) {
  const auto torus = dir / "torus.obj", lod1 = dir / "lod1.obj", lod2 = dir / "lod2.obj";
  ASSERT_EQ(run_cli("-q generate torus --n 24 --m 12 -o '" + torus.string() + "'", dir).exit_code, 0);
  ASSERT_EQ(run_cli("-q simplify '" + torus.string() + "' -o '" + lod1.string() + "' --ratio 0.5", dir).exit_code, 0);
  ASSERT_EQ(run_cli("-q simplify '" + lod1.string() + "' -o '" + lod2.string() + "' --ratio 0.5", dir).exit_code, 0);
  const auto page = dir / "chain.html";
  const CliRun run = run_cli("-q report '" + torus.string() + "' '" + lod1.string() + "' '" + lod2.string() +
                                 "' -o '" + page.string() + "' --samples 5000",
                             dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string html = slurp(page);
  EXPECT_EQ(metric_columns(html), 2);
  const nlohmann::json data = page_data(html);
  ASSERT_EQ(data["columns"].size(), 3u);
  for (int k = 1; k <= 2; ++k) {
    const nlohmann::json& column = data["columns"][k];
    const std::vector<float> heat = decode_array<float>(column["heat"]);
    EXPECT_EQ(heat.size(), column["vertices"].get<std::size_t>());
    // Hausdorff (out → in) includes every output vertex, so it bounds each vertex's distance.
    const double hausdorff = column["hausdorff"];
    float top = 0;
    for (float d : heat) top = std::max(top, d);
    EXPECT_GT(top, 0.0f);
    EXPECT_LE(top, hausdorff * (1 + 1e-6));
  }
  const double heat_top = data["heat_top"], heat_max = data["heat_max"];
  EXPECT_GT(heat_top, 0.0);
  EXPECT_LE(heat_max, heat_top);
}

TEST_F(ReportCli, SimplifyWritesTheSamePageForOneRun) {
  const auto grid = dir / "grid.obj", out = dir / "out.obj", page = dir / "run.html";
  ASSERT_EQ(run_cli("-q generate torus --n 16 --m 8 -o '" + grid.string() + "'", dir).exit_code, 0);
  const CliRun run = run_cli("-q simplify '" + grid.string() + "' -o '" + out.string() + "' --ratio 0.5 --report-html '" +
                                 page.string() + "'",
                             dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string html = slurp(page);
  EXPECT_EQ(metric_columns(html), 1);
  const nlohmann::json data = page_data(html);
  ASSERT_EQ(data["columns"].size(), 2u);
  const ReadResult written = read_mesh(out);
  ASSERT_TRUE(written.ok()) << written.error;
  EXPECT_EQ(data["columns"][1]["faces"], written.mesh.num_faces());
  EXPECT_EQ(data["columns"][1]["tri_equivalent"], tri_equivalent_count(written.mesh));
}

TEST_F(ReportCli, TitleCannotCloseTheScripts) {
  const auto grid = dir / "grid.obj", page = dir / "t.html";
  ASSERT_EQ(run_cli("-q generate grid --n 2 --m 2 -o '" + grid.string() + "'", dir).exit_code, 0);
  const CliRun run = run_cli("-q report '" + grid.string() + "' '" + grid.string() + "' -o '" + page.string() +
                                 "' --samples 1000 --title '</script><!-- x'",
                             dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string html = slurp(page);
  std::size_t closes = 0;
  for (auto p = html.find("</script>"); p != std::string::npos; p = html.find("</script>", p + 1)) ++closes;
  EXPECT_EQ(closes, 3u);  // the data block, three.js, the viewer
  EXPECT_EQ(page_data(html)["title"], "</script><!-- x");
  EXPECT_NE(html.find("<h1>&lt;/script&gt;&lt;!-- x</h1>"), std::string::npos);
}

TEST_F(ReportCli, Refusals) {
  const auto grid = dir / "grid.obj";
  ASSERT_EQ(run_cli("-q generate grid --n 2 --m 2 -o '" + grid.string() + "'", dir).exit_code, 0);
  const std::string copy = (dir / "copy.obj").string();
  std::filesystem::copy_file(grid, copy);
  // The HTML path names an input: refused, the input unchanged.
  const std::string before = slurp(copy);
  CliRun run = run_cli("-q report '" + grid.string() + "' '" + copy + "' -o '" + copy + "'", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("refusing to overwrite an input"), std::string::npos) << run.err;
  EXPECT_EQ(slurp(copy), before);
  // No output mesh: a usage error.
  EXPECT_EQ(run_cli("-q report '" + grid.string() + "' -o '" + (dir / "x.html").string() + "'", dir).exit_code, 1);
  // An unreadable output: exit 2 naming the file, no page left behind.
  const auto bad = dir / "bad.obj";
  std::ofstream(bad) << "v 0 0 0\nf 1 2 3\n";
  run = run_cli("-q report '" + grid.string() + "' '" + bad.string() + "' -o '" + (dir / "y.html").string() + "'", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("bad.obj"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "y.html"));
  // simplify: the HTML report may not be the output mesh.
  run = run_cli("-q simplify '" + grid.string() + "' -o '" + (dir / "o.obj").string() + "' --ratio 0.5 --report-html '" +
                    (dir / "o.obj").string() + "'",
                dir);
  EXPECT_EQ(run.exit_code, 2);
}

}  // namespace
}  // namespace quadlod::testing

#endif  // QUADLOD_HTML_REPORT
