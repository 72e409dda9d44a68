// The pipeline of the paper's Fig. 2, stage by stage; each stage reads the previous stage's
// result and nothing reaches back. See include/quadlod/simplify.h.
#include "quadlod/simplify.h"

#include "ilp/formulation.h"
#include "mesh/connectivity.h"
#include "mesh/features.h"
#include "mesh/validation.h"
#include "post/cluster_collapse.h"
#include "post/dual_repair.h"
#include "topology/analysis.h"
#include "util/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

namespace quadlod {

double default_lambda_geo() { return SelectionParams{}.lambda_geo; }
double default_lambda_edge() { return SelectionParams{}.lambda_edge; }
double default_lambda_tri() { return SelectionParams{}.lambda_tri; }

namespace {

// Edges the selection must keep so that no cluster can join two strict feature lines or move a
// strict feature corner (issue 7, docs/attributes.md): a non-feature edge between two vertices on
// strict lines (collapsing it would merge two seams, or pinch one), and any edge between two
// feature corners of which one is strict. Chains through interior vertices (a ══ x ══ b with a, b on
// different seams) are left to the collapse's `feature` refusal: they need two collapsed edges
// that meet at a vertex, which chord collapses rarely produce.
std::vector<std::uint8_t> feature_pins(const Connectivity& conn, const FeatureEdges& feat, Index& count) {
  std::vector<std::uint8_t> pins(conn.num_edges, 0);
  count = 0;
  for (Index e = 0; e < conn.num_edges; ++e) {
    const auto [a, b] = conn.edge_vertices[e];
    if (a == b) continue;
    const bool across = !feat.is_strict(e) && feat.on_strict(a) && feat.on_strict(b);
    const bool corners = feat.vertex_corner[a] && feat.vertex_corner[b] && (feat.on_strict(a) || feat.on_strict(b));
    if (across || corners) {
      pins[e] = 1;
      ++count;
    }
  }
  return pins;
}

// One line per finished stage: "[3/5] select      1.84 s  (total 2.10 s)".
class StageLog {
 public:
  explicit StageLog(bool enabled) : enabled_(enabled) {}
  void done(int index, const char* stage, double seconds, const std::string& detail = {}) {
    if (!enabled_) return;
    std::fprintf(stderr, "[%d/5] %-9s %3d%%  %7.2f s  (elapsed %.2f s)%s%s\n", index, stage,
                 index * 100 / 5, seconds, total_.seconds(), detail.empty() ? "" : "  ",
                 detail.c_str());
  }

 private:
  bool enabled_;
  Stopwatch total_;
};

nlohmann::json solve_json(const SelectionResult& s) {
  nlohmann::json j = {
      {"formulation_rows", s.model.size.rows},
      {"formulation_cols", s.model.size.cols},
      {"formulation_nonzeros", s.model.size.nonzeros},
      {"integer_cols", s.model.size.integer_cols},
      {"edge_groups", s.model.edge_groups},
      {"fixed_kept_groups", s.model.fixed_kept_groups},
      {"owner_aggregates", s.model.owner_aggregates},
      {"general_faces", s.model.general_faces},
      {"triangle_faces", s.model.triangle_faces},
      {"linear_faces", s.model.linear_faces},
      {"geo_clusters", s.model.geo_clusters},
      {"tri_clusters", s.model.tri_clusters},
      {"tri_neighbour_rows", s.model.tri_neighbour_rows},
      {"split_pairs", s.model.split_pairs},
      {"target", s.target},
      {"predicted", s.predicted},
      {"greedy_predicted", s.greedy_predicted},
      {"objective", s.objective},
      {"greedy_objective", s.greedy_objective},
      {"baseline_objective", s.baseline_objective},
      {"collapsed_groups", s.collapsed_groups},
      {"collapsed_clusters", s.collapsed_clusters},
      {"band_enforced", s.band_enforced},
      {"note", s.note},
      {"solver_ran", s.solver_ran},
      {"strategy", s.strategy},
      {"neighbourhoods", s.neighbourhoods},
      {"neighbourhoods_improved", s.neighbourhoods_improved},
      {"neighbourhood_sweeps", s.neighbourhood_sweeps},
      {"neighbourhoods_converged", s.neighbourhoods_converged},
      {"seconds_neighbourhood_build", s.seconds_neighbourhood_build},
      {"flip_search_objective", s.flip_search_objective},
      {"flip_passes", s.flip_passes},
      {"flips", s.flips},
      {"swaps", s.swaps},
      {"seconds_flip_search", s.seconds_flip_search},
      {"seconds_build", s.seconds_build},
      {"seconds_greedy", s.seconds_greedy},
      {"seconds_solve", s.seconds_solve},
  };
  if (s.solver_ran) {
    const ilp::SolveResult& r = s.solve;
    auto finite = [](double v) -> nlohmann::json { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
    j["solver"] = {
        {"backend", r.backend},
        {"call", std::string(ilp::to_string(r.call))},
        {"status", std::string(ilp::to_string(r.status))},
        {"message", r.message},
        {"objective", finite(r.objective)},
        {"best_bound", finite(r.best_bound)},
        {"gap", finite(r.gap)},
        {"seconds", r.seconds},
        {"nodes", r.nodes},
        {"iterations", r.iterations},
        {"start", std::string(ilp::to_string(r.start))},
        {"solution_is_start", r.solution_is_start},
        {"presolved_rows", r.presolved.rows},
        {"presolved_cols", r.presolved.cols},
        {"presolved_nonzeros", r.presolved.nonzeros},
    };
  }
  return j;
}

}  // namespace

SimplifyResult simplify(const PolyMesh& input, const SimplifyOptions& options) {
  SimplifyResult result;
  Stopwatch total;
  if (std::string problem = check_pipeline_input(input); !problem.empty()) {
    result.error = problem;
    return result;
  }
  if (!(options.ratio > 0.0 && options.ratio <= 1.0) && options.target_tri_equivalent == 0) {
    result.error = "the target ratio must be in (0, 1]";
    return result;
  }
  StageLog log(options.progress);
  nlohmann::json& report = result.report;

  // 1. Connectivity and analysis (§3.1, §3.2.2–§3.2.4).
  Stopwatch clock;
  const Connectivity conn = build_connectivity(input);
  AnalysisParams ap;
  ap.segmentation.enable = options.segmentation;
  ap.segmentation.epsilon_theta = options.epsilon_theta_deg * std::numbers::pi / 180.0;
  const AnalysisResult analysis = analyze(input, conn, ap);
  const double analysis_seconds = clock.seconds();
  report["analysis"] = {
      {"seconds", analysis_seconds},
      {"polychords", analysis.polychords.chords.size()},
      {"polychords_closed", analysis.polychords.num_closed},
      {"polychords_self_crossing", analysis.polychords.num_self_crossing},
      {"segments", analysis.segmentation.segments.size()},
      {"breakpoints", analysis.segmentation.stats.num_breakpoints},
      {"quad_clusters", analysis.medial.clusters.size()},
      {"triangle_clusters", analysis.triangles.clusters.size()},
  };
  log.done(1, "analysis", analysis_seconds, analysis_summary(input, analysis));

  // 2. Target (§3.2, Eq. 2: triangle-equivalents).
  result.input_tri_equivalent = tri_equivalent_count(input);
  result.target = options.target_tri_equivalent > 0
                      ? options.target_tri_equivalent
                      : static_cast<std::uint64_t>(std::llround(options.ratio * double(result.input_tri_equivalent)));
  SelectionParams sp;
  sp.epsilon_n = options.epsilon_n;
  if (options.lambda_geo >= 0.0) sp.lambda_geo = options.lambda_geo;
  if (options.lambda_edge >= 0.0) sp.lambda_edge = options.lambda_edge;
  if (options.lambda_tri >= 0.0) sp.lambda_tri = options.lambda_tri;
  sp.formulation = options.exact_formulation ? Formulation::Exact : Formulation::Fast;
  sp.neighbourhood_groups = std::max<Index>(1, options.neighbourhood_groups);
  if (options.strategy == "whole") sp.strategy = SelectionParams::Strategy::Whole;
  else if (options.strategy == "neighbourhoods") sp.strategy = SelectionParams::Strategy::Neighbourhoods;
  else if (options.strategy != "auto") {
    result.error = "unknown solver strategy '" + options.strategy + "' (auto, whole, neighbourhoods)";
    return result;
  }
  sp.consistency = options.consistency;
  sp.geometry = options.geometry;
  sp.solver = options.solver;
  sp.solve.threads = options.threads;
  sp.solve.seed = options.seed;
  sp.quiet = !options.progress;
  DualRepairParams dp;
  dp.enable = options.dual_repair;
  ClusterCollapseParams cp;
  cp.max_hausdorff = options.max_hausdorff;
  cp.respect_features = options.features;
  cp.project_attributes = options.features;
  cp.features.hard_angle_deg = options.hard_angle_deg;

  // Stages 2–4 — selection (§3.2), dual repair (§3.3.1), cluster collapse (§3.3.2) — run in
  // rounds (beyond the paper). The collapse refuses clusters that would break a guarantee, and
  // every refusal keeps faces the selection meant to remove, so the output can land well above
  // N. A further round pins the refused edges as kept (their chords are not collapsible here),
  // aims the selection below N by the drift the last round showed, and runs the three stages
  // again, until the result is within `round_tolerance` of N or `max_rounds` ran out. The round
  // closest to N is the result. docs/formulation.md ("Rounds") has the measurements.
  const bool reducing = result.target < result.input_tri_equivalent;
  const int max_rounds = reducing ? std::max(1, options.max_rounds) : 1;
  std::vector<std::uint8_t> pinned;
  if (options.features) {
    clock = Stopwatch();
    const FeatureEdges feat = find_feature_edges(input, conn, cp.features);
    Index pins = 0;
    pinned = feature_pins(conn, feat, pins);
    report["features"] = {
        {"feature_edges", feat.feature_edges},
        {"boundary_edges", feat.edges_with_bit[0]},
        {"nonmanifold_edges", feat.edges_with_bit[1]},
        {"uv_seam_edges", feat.edges_with_bit[2]},
        {"normal_seam_edges", feat.edges_with_bit[3]},
        {"material_border_edges", feat.edges_with_bit[4]},
        {"hard_edges", feat.edges_with_bit[5]},
        {"lines", feat.num_lines},
        {"corners", feat.corners},
        {"pinned_edges", pins},
        {"seconds", clock.seconds()},
    };
  }
  std::int64_t selection_target = static_cast<std::int64_t>(result.target);
  std::int64_t previous_target = 0, previous_achieved = 0;
  std::optional<ClusterCollapseResult> best;
  double best_distance = INFINITY;
  Index best_refusals = 0;
  double select_total = 0.0, dual_total = 0.0, collapse_total = 0.0;
  nlohmann::json rounds = nlohmann::json::array();
  for (int round = 1; round <= max_rounds; ++round) {
    const std::string tag = round == 1 ? std::string() : " (round " + std::to_string(round) + ")";
    sp.solve.time_limit_seconds =
        round == 1 ? options.time_limit_seconds : options.time_limit_seconds * options.later_round_time_fraction;
    sp.keep_edges = pinned;
    clock = Stopwatch();
    const SelectionResult selection =
        select_edges(input, conn, analysis, static_cast<std::uint64_t>(selection_target), sp);
    const double select_seconds = clock.seconds();
    select_total += select_seconds;
    log.done(2, "select", select_seconds,
             "N' " + std::to_string(selection.predicted) + " of " + std::to_string(selection_target) +
                 (selection.solver_ran ? ", solver " + std::string(ilp::to_string(selection.solve.status)) : "") +
                 tag);

    clock = Stopwatch();
    const DualRepairResult repaired =
        repair_dual_graph(input, conn, analysis.polychords, selection.edge_kept, dp);
    dual_total += clock.seconds();
    log.done(3, "dual", clock.seconds(),
             std::to_string(repaired.stats.super_faces_found) + " super-faces, " +
                 std::to_string(repaired.stats.splits) + " splits" + tag);

    clock = Stopwatch();
    ClusterCollapseResult collapsed = collapse_clusters(input, conn, repaired.edge_kept, cp);
    if (collapsed.status != ClusterCollapseStatus::Ok) {
      result.error = collapsed.error;
      return result;
    }
    collapse_total += clock.seconds();
    const std::int64_t achieved = static_cast<std::int64_t>(collapsed.stats.tri_equivalent_out);
    const std::int64_t drift = achieved - static_cast<std::int64_t>(result.target);
    log.done(4, "collapse", clock.seconds(),
             std::to_string(collapsed.stats.total_refusals()) + " clusters refused, " +
                 std::to_string(achieved) + " of " + std::to_string(result.target) + tag);

    // Edges the selection (after repair) collapsed and the collapse kept: refused.
    Index newly_pinned = 0;
    if (pinned.empty()) pinned.assign(conn.num_edges, 0);
    for (Index e = 0; e < conn.num_edges; ++e)
      if (!repaired.edge_kept[e] && !collapsed.edge_collapsed_final[e] && !pinned[e]) {
        pinned[e] = 1;
        ++newly_pinned;
      }

    nlohmann::json round_json = {
        {"round", round},
        {"selection_target", selection_target},
        {"predicted", selection.predicted},
        {"achieved", achieved},
        {"refusals", collapsed.stats.total_refusals()},
        {"refused_tri_equivalents",
         std::int64_t(collapsed.stats.tri_equivalent_out) - std::int64_t(collapsed.stats.tri_equivalent_wanted)},
        {"newly_pinned_edges", newly_pinned},
        {"seconds_select", select_seconds},
        {"time_limit_seconds", sp.solve.time_limit_seconds},
    };
    const double distance = std::abs(double(drift));
    const bool better = distance < best_distance;
    round_json["chosen"] = better;
    if (better) {
      for (auto& r : rounds) r["chosen"] = false;
      best_distance = distance;
      report["selection"] = solve_json(selection);
      report["selection"]["seconds"] = select_seconds;
      report["selection"]["quads_to_triangles"] = predicted_new_triangles(input, conn, selection.edge_kept);
      report["dual_repair"] = {
          {"seconds", repaired.seconds},
          {"super_faces_found", repaired.stats.super_faces_found},
          {"super_faces_left", repaired.stats.super_faces_left},
          {"splits", repaired.stats.splits},
          {"eroded_edges", repaired.stats.eroded_edges},
          {"restored_edges", repaired.stats.restored_edges},
          {"unsplittable", repaired.stats.unsplittable},
          {"max_valence_before", repaired.stats.max_valence_before},
          {"max_valence_after", repaired.stats.max_valence_after},
          {"quads_to_triangles", predicted_new_triangles(input, conn, repaired.edge_kept)},
      };
      report["collapse"] = to_json(collapsed.stats);
      report["collapse"]["seconds"] = collapsed.seconds;
      result.note = selection.note;
      result.rounds_used = round;
      best_refusals = collapsed.stats.total_refusals();
      best = std::move(collapsed);
    }
    rounds.push_back(std::move(round_json));
    if (!reducing || distance <= options.round_tolerance * double(result.target)) break;
    // Re-aim: a secant step on achieved(selection target) through the last two rounds, its
    // slope kept in [0.5, 1] (refusals make the output move less than the selection, and pins
    // change the function between rounds), the target kept within [N/2, 3N/2].
    double slope = 1.0;
    if (round > 1 && selection_target != previous_target)
      slope = std::clamp(double(achieved - previous_achieved) / double(selection_target - previous_target), 0.5, 1.0);
    previous_target = selection_target;
    previous_achieved = achieved;
    const double aimed = double(selection_target) - double(drift) / slope;
    const std::int64_t next = static_cast<std::int64_t>(std::llround(
        std::clamp(aimed, 0.5 * double(result.target), 1.5 * double(result.target))));
    if (next < 1 || (newly_pinned == 0 && next == selection_target)) break;
    selection_target = next;
  }
  const int rounds_run = static_cast<int>(rounds.size());
  report["rounds"] = std::move(rounds);
  report["stage_seconds"] = {{"analysis", analysis_seconds},
                             {"select", select_total},
                             {"dual", dual_total},
                             {"collapse", collapse_total}};

  // 5. Summary.
  result.mesh = std::move(best->mesh);
  result.achieved = tri_equivalent_count(result.mesh);
  for (Index f = 0; f < result.mesh.num_faces(); ++f) {
    const Index k = result.mesh.face_size(f);
    if (k == 3) ++result.triangles;
    else if (k == 4) ++result.quads;
    else ++result.ngons;
  }
  const double deviation = result.target ? (double(result.achieved) - double(result.target)) / double(result.target) : 0.0;
  if (result.note.empty() && std::abs(deviation) > options.epsilon_n && result.target < result.input_tri_equivalent) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "achieved %llu is %+.1f %% off the target %llu after %d rounds: the collapse refused "
                  "%u clusters (report: collapse.refused) whose collapse would break a guarantee",
                  static_cast<unsigned long long>(result.achieved), 100.0 * deviation,
                  static_cast<unsigned long long>(result.target), rounds_run,
                  static_cast<unsigned>(best_refusals));
    result.note = text;
  }
  report["input_tri_equivalent"] = result.input_tri_equivalent;
  report["target"] = result.target;
  report["achieved"] = result.achieved;
  report["deviation"] = deviation;
  report["quads"] = result.quads;
  report["triangles"] = result.triangles;
  report["ngons"] = result.ngons;
  report["note"] = result.note;
  report["seconds"] = total.seconds();
  report["options"] = {
      {"ratio", options.ratio},
      {"target_tri_equivalent", options.target_tri_equivalent},
      {"epsilon_n", sp.epsilon_n},
      {"epsilon_theta_deg", options.epsilon_theta_deg},
      {"lambda_geo", sp.lambda_geo},
      {"lambda_edge", sp.lambda_edge},
      {"lambda_tri", sp.lambda_tri},
      {"time_limit_seconds", options.time_limit_seconds},
      {"threads", options.threads},
      {"seed", options.seed},
      {"formulation", options.exact_formulation ? "exact" : "fast"},
      {"strategy", options.strategy},
      {"neighbourhood_groups", sp.neighbourhood_groups},
      {"consistency", options.consistency},
      {"segmentation", options.segmentation},
      {"geometry", options.geometry},
      {"dual_repair", options.dual_repair},
      {"max_hausdorff", options.max_hausdorff},
      {"features", options.features},
      {"hard_angle_deg", options.hard_angle_deg},
      {"max_rounds", options.max_rounds},
      {"round_tolerance", options.round_tolerance},
      {"later_round_time_fraction", options.later_round_time_fraction},
  };
  log.done(5, "done", total.seconds(),
           "target " + std::to_string(result.target) + ", achieved " + std::to_string(result.achieved));
  return result;
}

}  // namespace quadlod
