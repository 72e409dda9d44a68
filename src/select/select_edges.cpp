// The edge selection of paper §3.2 (selection.h), orchestrated: the decision groups and their
// constraints, the greedy selection, reach_band where the greedy misses Eq. 2's band, the
// annealing runs, the descent, the recombination and a second descent, then the MIP (whole model
// or large-neighbourhood search, src/ilp/) from that start, the open model of phase 2 where no
// selection in the band was found, and the report; also the test entry point detail::local_search.
#include "select/selection.h"

#include "select/formulation.h"
#include "ilp/solver.h"
#include "select/anneal.h"
#include "select/greedy.h"
#include "select/groups.h"
#include "select/moves.h"
#include "select/recombine.h"
#include "util/progress.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

namespace quadlod {

using namespace select_detail;

SelectionResult select_edges(const PolyMesh& mesh, const Connectivity& conn,
                             const AnalysisResult& analysis, std::uint64_t target,
                             const SelectionParams& params) {
  SelectionResult result;
  Stopwatch clock;
  result.input_tri_equivalent = tri_equivalent_count(mesh);
  result.target = target;
  result.edge_kept.assign(conn.num_edges, 1);
  result.predicted = result.greedy_predicted = result.input_tri_equivalent;
  if (target >= result.input_tri_equivalent) {
    result.note = "target " + std::to_string(target) + " is at or above the input size " +
                  std::to_string(result.input_tri_equivalent) + ": nothing to do";
    result.stop_reason = "nothing to do";
    return result;
  }

  Stopwatch prepare_clock;
  const std::vector<double> importance = selection_importance(mesh, conn, params);
  const Groups groups = make_groups(conn, analysis, importance, params);
  for (double q : importance) result.baseline_objective -= params.lambda_edge * q;
  const GroupConstraints gc = make_group_constraints(mesh, conn, groups, analysis, params);
  const FaceGroups fg = make_face_groups(mesh, conn, groups);
  std::vector<Index> adj_offsets, adjacent;  // groups that share a face
  group_adjacency(groups, fg, adj_offsets, adjacent);
  result.seconds_prepare = prepare_clock.seconds();

  Stopwatch greedy_clock;
  const GreedyResult greedy = greedy_select(groups, gc, fg, target, params);
  result.seconds_greedy = greedy_clock.seconds();
  result.greedy_predicted = greedy.count;
  const double lo = (1.0 - params.epsilon_n) * double(target);
  const double hi = (1.0 + params.epsilon_n) * double(target);
  auto in_band = [&](std::uint64_t c) { return double(c) >= lo && double(c) <= hi; };
  bool reachable = in_band(greedy.count);
  result.seconds_build = 0.0;
  const double time_limit = params.solve.time_limit_seconds;
  const int threads = ilp::backend::resolve_threads(params.solve);

  // The greedy stopped outside the band (fast formulation): an annealing that may leave the
  // greedy's choices looks for the band first (reach_band). Its state nearest the band is the
  // start of everything below, in the band or not.
  std::vector<std::uint8_t> closest = greedy.y;
  if (!reachable && time_limit > 0.0 && params.formulation == Formulation::Fast && params.reach_time_fraction > 0.0) {
    Stopwatch reach_clock;
    AnnealStats rs;
    closest = reach_band(groups, gc, fg, greedy.y, target, params,
                         params.reach_time_fraction * time_limit - clock.seconds(), adj_offsets, adjacent, threads, rs);
    result.reach_ran = true;
    result.reach_moves = rs.moves;
    result.reach_predicted = selection_count(fg, closest);
    result.seconds_reach = reach_clock.seconds();
    reachable = in_band(result.reach_predicted);
  }

  // Phase 1: Eq. 2 as a hard band. The greedy (or reached) selection is the start when it lies
  // in the band; otherwise the solver has to find a feasible point itself, with half of what is
  // left of the budget. Phase 2 (only if phase 1 ends without a solution): no band, the
  // selection nearest the band as start, so the result is the closest count found (reported in
  // `note`). A solve is solve_model() (src/select/formulation.h); neighbourhood_search() there is
  // the large-neighbourhood search of SelectionParams::Strategy.

  // The whole model is built before the local search, so that the annealing's and the descent's
  // shares of the budget (fractions of the time since select_edges() began) account for it: built
  // after them, it overran 0.625 s budgets by 0.1-0.2 s on cg57.
  Stopwatch build_clock;
  ModelBuilder banded(mesh, conn, analysis, groups, gc, fg, importance, params);
  banded.build(target, true);
  result.model = banded.stats;
  result.model.size = banded.model.size();
  result.seconds_build = build_clock.seconds();

  // The greedy selection (or reach_band's), annealed and polished by the descent, is the start
  // of every solve (skipped for a greedy-only run and when neither lies in the band).
  std::vector<std::uint8_t> start_y = closest;
  std::vector<std::vector<std::uint8_t>> alternatives;  // other annealing runs, for the recombination
  if (reachable && time_limit > 0.0) {
    // Fast formulation: simulated annealing from the greedy selection until anneal_time_fraction
    // of the budget has passed, then the deterministic local search as a final descent.
    if (params.anneal_time_fraction > 0.0 && params.formulation == Formulation::Fast) {
      Stopwatch anneal_clock;
      AnnealStats as;
      start_y = anneal_runs(groups, gc, fg, std::move(start_y), target, params,
                            params.anneal_time_fraction * time_limit - clock.seconds(), adj_offsets, adjacent,
                            threads, as, &alternatives);
      result.anneal_moves = as.moves;
      result.anneal_accepted = as.accepted;
      result.anneal_compounds = as.compounds;
      result.anneal_converged = as.schedule_done;
      result.anneal_runs = as.runs;
      result.anneal_priced_runs = as.priced_runs;
      result.priced_component_runs = as.component_runs;
      result.seconds_anneal = anneal_clock.seconds();
    }
    // The recombination (after annealing only) takes its share from the end of the descent's.
    const double recombination_fraction =
        params.formulation == Formulation::Fast && result.anneal_moves > 0 ? params.recombination_fraction : 0.0;
    Stopwatch flip_clock;
    FlipSearchStats fs;
    // After annealing the descent only gets what is left up to descent_end_fraction of the
    // budget (the neighbourhood MIPs get the rest).
    const double flip_budget =
        result.anneal_moves > 0
            ? std::min(params.flip_search_time_fraction * time_limit,
                       std::max(0.0, (params.descent_end_fraction - recombination_fraction) * time_limit - clock.seconds()))
            : params.flip_search_time_fraction * time_limit;
    start_y = flip_search(groups, gc, fg, std::move(start_y), target, params, flip_budget, adj_offsets, adjacent, fs);
    result.flip_passes = fs.passes;
    result.flips = fs.flips;
    result.swaps = fs.swaps;
    result.exchanges = fs.exchanges;
    result.chains = fs.chains;
    result.compounds = fs.compounds;
    result.flip_search_converged = fs.converged;
    result.seconds_flip_search = flip_clock.seconds();
    // Recombination of independent parts after the descent (fast formulation, after
    // annealing), then a second descent if it changed anything.
    if (recombination_fraction > 0.0) {
      Stopwatch recombine_clock;
      RecombineStats rs;
      const double before = group_objective(groups, gc, fg, start_y, target, params);
      const std::vector<std::uint8_t> unrecombined = start_y;
      start_y = recombine_components(groups, gc, fg, std::move(start_y), target, params,
                                     params.descent_end_fraction * time_limit - clock.seconds(), adj_offsets,
                                     adjacent, rs, alternatives);
      result.recombination_rounds = rs.rounds;
      result.recombination_improved = rs.improved;
      result.recombination_moved = rs.moved;
      result.components = rs.components;
      result.largest_component = rs.largest;
      result.seconds_recombination = recombine_clock.seconds();
      result.recombination_gain = before - group_objective(groups, gc, fg, start_y, target, params);
      if (result.recombination_gain < -1e-6 * std::max(1.0, std::abs(before))) {  // never: the programme is exact
        assert(false);
        start_y = unrecombined;
        result.recombination_gain = 0.0;
        rs.improved = 0;
      }
      if (rs.improved > 0) {
        FlipSearchStats fs2;
        start_y = flip_search(groups, gc, fg, std::move(start_y), target, params,
                              std::max(0.0, params.descent_end_fraction * time_limit - clock.seconds()), adj_offsets,
                              adjacent, fs2);
      }
    }
  }

  const std::vector<double> banded_start = banded.complete(start_y, target);
  if (reachable) banded.model.set_initial_solution(banded_start);

  std::vector<double> solution;
  bool proven_out_of_reach = false;  // phase 1 proved the band infeasible
  const ModelBuilder* used = &banded;
  const auto free_groups = static_cast<Index>(std::count(groups.fixed.begin(), groups.fixed.end(), 0));
  const bool neighbourhoods =
      params.formulation == Formulation::Fast &&
      (params.strategy == SelectionParams::Strategy::Neighbourhoods ||
       (params.strategy == SelectionParams::Strategy::Auto && free_groups > params.whole_model_groups));
  result.strategy = time_limit > 0.0 ? (neighbourhoods ? "neighbourhoods" : "whole") : "greedy";
  // Too large for a whole-model MIP to find the band when the greedy misses it (phases below).
  const bool large = free_groups > params.whole_model_groups;
  if (reachable) {
    result.greedy_objective = banded.model.evaluate(banded.complete(greedy.y, target));
    result.flip_search_objective = banded.model.evaluate(banded_start);
    // The budget covers the whole selection: what building the model and the greedy took is
    // subtracted (at least 10 % of it is left to the solver).
    // (After annealing, which already ran to its share of the budget, nothing is guaranteed.)
    const double budget = std::max(result.anneal_moves > 0 ? 0.0 : 0.1 * time_limit, time_limit - clock.seconds());
    if (time_limit > 0.0 && neighbourhoods) {
      solution = banded.complete(neighbourhood_search(mesh, conn, analysis, groups, gc, fg, importance, adj_offsets,
                                                       adjacent, target, params, start_y, budget, result),
                                  target);
    } else {
      solution = time_limit > 0.0 ? solve_model(banded.model, params, budget, result) : banded_start;
    }
    if (solution.empty()) solution = banded_start;
    result.band_enforced = true;
  } else if (time_limit > 0.0 && !(neighbourhoods && large)) {
    // Phase 1 only where the whole model is small enough to be searched (at most
    // whole_model_groups free groups): on the large models of the neighbourhood strategy a
    // whole-model MIP never found a point in the band in its half of the budget (cg57 at 0.4,
    // rounds after pins: 0 of 18), but each call cost 1–3 s beyond its limit (loading 300k rows,
    // the child process).
    solution =
        solve_model(banded.model, params, 0.5 * std::max(0.1 * time_limit, time_limit - clock.seconds()), result);
    result.band_enforced = !solution.empty();
    proven_out_of_reach = solution.empty() && result.solve.status == ilp::SolveStatus::Infeasible;
  }
  std::optional<ModelBuilder> open;
  if (solution.empty() && time_limit > 0.0 && ((neighbourhoods && large) || result.reach_ran)) {
    // The selection nearest the band stays (the greedy's on a large model, or reach_band's):
    // Eq. 9 without the band would trade count for λ_geo (a search of the open model raised N'
    // by ~3 % on cg57's later rounds, away from the target; on a cube with N' ∈ {12, 4, 0} for
    // N = 3 it kept all 12). The banded model evaluates it like the open one would (same
    // objective; only p's or q's bound is off).
    result.greedy_objective = banded.model.evaluate(banded.complete(greedy.y, target));
    solution = banded.complete(closest, target);
  } else if (solution.empty()) {
    // Phase 2: the band widened to the distance of the selection nearest it (so the result is
    // never farther from N than the closest selection found; Eq. 9 without any band traded
    // count for λ_geo: tpsdemo_red_robot at 0.4, N = 5 152, went to N' = 9 398 where the greedy
    // had 6 183).
    Stopwatch rebuild_clock;
    open.emplace(mesh, conn, analysis, groups, gc, fg, importance, params);
    open->build(target, false, std::abs(double(selection_count(fg, closest)) - double(target)));
    result.greedy_objective = open->model.evaluate(open->complete(greedy.y, target));
    const std::vector<double> start = open->complete(closest, target);
    open->model.set_initial_solution(start);
    result.seconds_build += rebuild_clock.seconds();
    solution = time_limit > 0.0
                   ? solve_model(open->model, params, std::max(0.1 * time_limit, time_limit - clock.seconds()), result)
                   : start;
    if (solution.empty()) solution = start;
    used = &*open;
  }
  if (!result.band_enforced && result.reach_ran) {
    result.stop_reason = "band not reached";
  } else if (time_limit <= 0.0 || (!result.band_enforced && neighbourhoods && large)) {
    result.stop_reason = "greedy";
  } else if (result.strategy == "neighbourhoods") {
    result.stop_reason = result.neighbourhoods_converged ? "converged" : "time";
  } else {
    result.stop_reason = result.solve.status == ilp::SolveStatus::Optimal ? "optimal"
                         : result.solve.stalled                            ? "stalled"
                                                                           : "time";
  }
  result.objective = used->model.evaluate(solution);
  result.edge_kept = used->edge_bits(solution);
  result.predicted = predicted_tri_equivalent(mesh, conn, result.edge_kept);
  std::vector<std::uint8_t> y(groups.count, 1);
  for (Index e = 0; e < conn.num_edges; ++e)
    if (!result.edge_kept[e]) y[groups.edge_group[e]] = 0;
  result.collapsed_groups = static_cast<Index>(std::count(y.begin(), y.end(), 0));
  result.collapsed_clusters = count_collapsed_clusters(gc, y);
  // The open search of phase 2 may still land in the band: then the target was not out of reach.
  if (!result.band_enforced && std::abs(double(result.predicted) - double(target)) <= params.epsilon_n * double(target))
    result.band_enforced = true;
  // Out of reach only where the solver proved it; otherwise what was searched, and the nearest.
  if (!result.band_enforced && result.note.empty()) {
    char text[320];
    if (proven_out_of_reach)
      std::snprintf(text, sizeof text,
                    "target %llu is out of reach of the hard constraints (the solver proved that no selection "
                    "lies within %g %% of it): the closest selection found has %llu triangle-equivalents",
                    static_cast<unsigned long long>(target), 100.0 * params.epsilon_n,
                    static_cast<unsigned long long>(result.predicted));
    else
      std::snprintf(text, sizeof text,
                    "no selection within %g %% of the target %llu was found under the hard constraints (%s): the "
                    "closest selection found has %llu triangle-equivalents",
                    100.0 * params.epsilon_n, static_cast<unsigned long long>(target),
                    result.reach_ran && result.solver_ran ? "searched by annealing and the MIP solver"
                    : result.reach_ran                    ? "searched by annealing"
                    : result.solver_ran                   ? "searched by the MIP solver"
                                                          : "greedy only, no search",
                    static_cast<unsigned long long>(result.predicted));
    result.note = text;
  }
  return result;
}

namespace detail {

std::vector<std::uint8_t> local_search(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                       std::uint64_t target, const SelectionParams& params,
                                       const std::vector<std::uint8_t>& edge_kept, double seconds) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  AnnealStats as;
  if (params.anneal_time_fraction > 0.0)
    p.y = anneal_runs(p.groups, p.gc, p.fg, std::move(p.y), target, params, seconds, p.adj_offsets, p.adjacent,
                      ilp::backend::resolve_threads(params.solve), as, nullptr);
  FlipSearchStats stats;
  return p.edge_bits(conn, flip_search(p.groups, p.gc, p.fg, p.y, target, params, seconds, p.adj_offsets,
                                       p.adjacent, stats));
}

}  // namespace detail

}  // namespace quadlod
