// The visual report of `quadlod report` and `quadlod simplify --report-html` (issue 22): one
// self-contained HTML file — no network at view time — with synchronised side-by-side 3D views
// of the input and every output (three.js, inlined; the viewer is apps/quadlod/report/viewer.js),
// flat shading + wireframe with quads / triangles / n-gons coloured, the poly-chords' medial
// curves as an optional overlay (§3.1, src/topology/polychords.h), a heat map of each output
// vertex's distance to the input surface, and the `quadlod eval` metrics of every output in a
// table, one column per output (an LOD chain reads left to right).
#pragma once

#include "quadlod/mesh.h"
#include "quadlod/metrics.h"

#include <string>
#include <vector>

namespace quadlod::cli {

struct HtmlReportColumn {
  std::string label;               ///< shown above the view and as the table's column head
  const PolyMesh* mesh = nullptr;  ///< not owned; must outlive build_html_report()
};

struct HtmlReportParams {
  std::string title = "quadlod report";
  /// The metrics are `quadlod eval`'s with these parameters (same defaults, same numbers).
  EvalParams eval;
  /// The heat map's colour scale ends at this quantile of all outputs' vertex distances (one
  /// scale for every column, so columns compare); the largest distance is printed beside it.
  double heat_quantile = 0.99;
  bool progress = false;  ///< one line per column on stderr
};

struct HtmlReportResult {
  std::string html;
  std::string error;  ///< non-empty: an output could not be evaluated against the input (why)
  bool ok() const { return error.empty(); }
};

/// Builds the page. Coordinates are mapped as the metrics map them (input bbox centre at the
/// origin, longest input side 1), so every view shares one camera.
HtmlReportResult build_html_report(const HtmlReportColumn& input, const std::vector<HtmlReportColumn>& outputs,
                                   const HtmlReportParams& params);

/// The file name of a path, as a column label.
std::string file_label(const std::string& path);

/// Builds the page and writes it atomically to `path`; prints the error and returns kExitBadInput
/// on failure (the CLI's convention), kExitOk otherwise. Shared by `report` and `simplify --report-html`.
int write_html_report(const std::string& path, const HtmlReportColumn& input,
                      const std::vector<HtmlReportColumn>& outputs, const HtmlReportParams& params);

}  // namespace quadlod::cli
