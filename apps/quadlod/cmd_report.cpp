// `quadlod report INPUT OUTPUT... -o report.html`: the visual report (report_html.h) of one or
// more outputs — typically an LOD chain, one column per level — against their input.
#ifdef QUADLOD_HTML_REPORT

#include "commands.h"
#include "report_html.h"

#include "quadlod/io.h"

#include <cstdio>
#include <memory>

namespace quadlod::cli {

namespace {

struct ReportOptions {
  std::string input, html;
  std::vector<std::string> outputs;
  std::string title;
  std::uint64_t samples = EvalParams{}.samples;
  std::uint64_t seed = EvalParams{}.seed;
  unsigned threads = 0;
};

}  // namespace

std::string file_label(const std::string& path) { return std::filesystem::path(path).filename().string(); }

int write_html_report(const std::string& path, const HtmlReportColumn& input,
                      const std::vector<HtmlReportColumn>& outputs, const HtmlReportParams& params) {
  const HtmlReportResult report = build_html_report(input, outputs, params);
  if (!report.ok()) return fail(report.error);
  const WriteResult written = write_file_atomically(path, report.html);
  if (!written.ok()) return fail(written.error);
  if (params.progress) std::fprintf(stderr, "report: wrote %s (%zu bytes)\n", path.c_str(), report.html.size());
  return kExitOk;
}

Command add_report(CLI::App& app, const GlobalOptions& global) {
  auto opt = std::make_shared<ReportOptions>();
  CLI::App* sub = app.add_subcommand(
      "report", "One self-contained HTML page: side-by-side 3D views, poly-chords, distance heat map, eval metrics");
  sub->add_option("INPUT", opt->input, "The original mesh")->required();
  sub->add_option("OUTPUT", opt->outputs, "Reduced meshes, one column each (an LOD chain: in order)")
      ->required()->expected(1, 64);
  sub->add_option("-o,--output", opt->html, "The HTML file to write")->required();
  sub->add_option("--title", opt->title, "Page title (default: quadlod report: INPUT)");
  sub->add_option("--samples", opt->samples, "Surface samples per direction of the metrics (as quadlod eval)")
      ->check(CLI::Range(std::uint64_t{1000}, std::uint64_t{100000000}))->capture_default_str();
  sub->add_option("--seed", opt->seed, "Sampling seed of the metrics")->capture_default_str();
  sub->add_option("--threads", opt->threads, "Worker threads of the metrics (0 = all cores)")->capture_default_str();
  return {sub, [opt, &global]() -> int {
            std::vector<std::string> meshes = opt->outputs;
            meshes.push_back(opt->input);
            for (const std::string& mesh : meshes)
              if (same_file(mesh, opt->html)) return fail(opt->html + ": refusing to overwrite an input");
            const ReadResult in = read_mesh(opt->input);
            if (!in.ok()) return fail(in.error);
            std::vector<ReadResult> reads;
            reads.reserve(opt->outputs.size());
            for (const std::string& path : opt->outputs) {
              reads.push_back(read_mesh(path));
              if (!reads.back().ok()) return fail(reads.back().error);
            }
            std::vector<HtmlReportColumn> outputs;
            for (std::size_t i = 0; i < reads.size(); ++i) outputs.push_back({file_label(opt->outputs[i]), &reads[i].mesh});
            HtmlReportParams params;
            params.title = opt->title.empty() ? "quadlod report: " + file_label(opt->input) : opt->title;
            params.eval.samples = opt->samples;
            params.eval.seed = opt->seed;
            params.eval.threads = opt->threads;
            params.progress = !global.quiet;
            return write_html_report(opt->html, {file_label(opt->input), &in.mesh}, outputs, params);
          }};
}

}  // namespace quadlod::cli

#endif  // QUADLOD_HTML_REPORT
