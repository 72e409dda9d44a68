// The large-neighbourhood search of the edge selection (SelectionParams::Strategy; beyond the
// paper, docs/formulation.md, "Speed"): sweeps of neighbourhood MIPs of the fast model (§3.2)
// around the incumbent, and the test entry point detail::neighbourhood_model (selection.h).
#include "select/formulation.h"

#include "ilp/solver.h"
#include "util/progress.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

namespace quadlod {

namespace select_detail {

namespace {

// Neighbourhoods of one sweep of the large-neighbourhood search: a partition of the free groups
// into regions of `size` groups (the last one smaller). A region grows breadth-first over groups
// that share a face from the first seed in `order` that no region took yet, only over untaken
// groups; when that runs out (a small part of the mesh, or enclosed by earlier regions) it goes
// on from the next untaken seed, so a region may hold several patches — the count row couples
// them anyway. Fixed groups are crossed but never freed. Each region lists its free groups.
std::vector<std::vector<Index>> neighbourhood_partition(const Groups& g, const std::vector<Index>& adj_offsets,
                                                        const std::vector<Index>& adjacent,
                                                        const std::vector<Index>& order, Index size) {
  std::vector<std::vector<Index>> regions;
  std::vector<std::uint8_t> seen(g.count, 0);  // queued by some region
  std::vector<Index> queue, region;
  for (Index seed : order) {
    if (g.fixed[seed] || seen[seed]) continue;
    queue.assign(1, seed);
    seen[seed] = 1;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const Index a = queue[head];
      if (!g.fixed[a]) {
        region.push_back(a);
        if (region.size() >= size) {  // full: groups still queued go back to the pool
          for (std::size_t k = head + 1; k < queue.size(); ++k) seen[queue[k]] = 0;
          break;
        }
      }
      for (Index k = adj_offsets[a]; k < adj_offsets[a + 1]; ++k)
        if (!seen[adjacent[k]]) {
          seen[adjacent[k]] = 1;
          queue.push_back(adjacent[k]);
        }
    }
    if (region.size() >= size) regions.push_back(std::move(region)), region.clear();
  }
  if (!region.empty()) regions.push_back(std::move(region));
  return regions;
}

}  // namespace

// Large-neighbourhood search (SelectionParams::Strategy): BFS over groups that share a face
// collects `neighbourhood_groups` free groups around a seed; the fast model restricted to them
// (everything else fixed at the incumbent, the greedy selection as cutoff) is solved and an
// improvement is kept. Seeds sweep the groups in index order; a sweep without improvement ends
// the search.
std::vector<std::uint8_t> neighbourhood_search(const PolyMesh& mesh, const Connectivity& conn,
                                               const AnalysisResult& analysis, const Groups& groups,
                                               const GroupConstraints& gc, const FaceGroups& fg,
                                               const std::vector<double>& importance,
                                               const std::vector<Index>& adj_offsets,
                                               const std::vector<Index>& adjacent, std::uint64_t target,
                                               const SelectionParams& params, std::vector<std::uint8_t> y,
                                               double seconds, SelectionResult& result) {
  Stopwatch lns_clock;
  double best = group_objective(groups, gc, fg, y, target, params);
  std::vector<std::uint8_t> free(groups.count, 0);
  Index improved_in_sweep = 0, idle_sweeps = 0;
  ilp::SolveResult summary;
  summary.backend = params.solver;
  summary.call = ilp::CallStatus::Ok;
  auto solver = ilp::make_solver(params.solver, &summary.message);
  if (!solver) return y;
  // Sweep k solves the regions of one partition of the groups (neighbourhood_partition): seeds
  // in index order for the first sweep, in a shuffled order (seeded by k) after that, so the
  // region borders of one sweep lie inside regions of the next. Two sweeps in a row without an
  // improvement end the search.
  std::vector<Index> order(groups.count);
  std::iota(order.begin(), order.end(), Index{0});
  std::vector<std::vector<Index>> regions;
  std::size_t next_region = 0;
  std::mt19937 rng(params.solve.seed);
  const ScopeIndex scope_index = make_scope_index(groups, gc, fg);
  auto count_of = [&](const std::vector<std::uint8_t>& bits) {
    std::uint64_t n = 0;
    for (Index f = 0; f + 1 < fg.offsets.size(); ++f) n += face_count(fg, f, bits);
    return n;
  };
  std::uint64_t count = count_of(y);
  std::vector<Index> free_list;
  while (lns_clock.seconds() < seconds) {
    if (next_region == regions.size()) {
      if (!regions.empty()) {
        ++result.neighbourhood_sweeps;
        idle_sweeps = improved_in_sweep == 0 ? idle_sweeps + 1 : 0;
        if (idle_sweeps >= 2 || (idle_sweeps == 1 && regions.size() == 1)) {
          result.neighbourhoods_converged = true;
          break;
        }
        improved_in_sweep = 0;
        std::shuffle(order.begin(), order.end(), rng);
      }
      regions = neighbourhood_partition(groups, adj_offsets, adjacent, order, params.neighbourhood_groups);
      next_region = 0;
      if (regions.empty()) break;
    }
    free_list = regions[next_region++];
    std::sort(free_list.begin(), free_list.end());
    for (Index a : free_list) free[a] = 1;
    Stopwatch build_clock;
    ModelBuilder sub(mesh, conn, analysis, groups, gc, fg, importance, params);
    sub.set_scope(free, y, scope_index, free_list, count);
    sub.build(target, true);
    sub.model.set_initial_solution(sub.complete(y, target));
    result.seconds_neighbourhood_build += build_clock.seconds();
    ilp::SolveParams sp = params.solve;
    sp.start_as_mip_start = params.greedy_as_mip_start;
    sp.time_limit_seconds =
        std::max(1e-3, std::min(params.neighbourhood_time_limit, seconds - lns_clock.seconds()));
    sp.isolate_process = params.isolate_neighbourhoods;
    sp.light = params.light_neighbourhoods;
    const ilp::ReducedModel reduced = ilp::without_fixed_columns(sub.model);
    const ilp::SolveResult r = solver->solve(reduced.model, sp);
    ++result.neighbourhoods;
    summary.nodes += r.nodes;
    summary.iterations += r.iterations;
    // The neighbourhood model holds every term of Eq. 9 that its free groups change, so the
    // change of its objective is the change of Eq. 9.
    const double change = r.objective - reduced.model.evaluate(reduced.model.initial_solution());
    if (r.has_solution() && !r.solution_is_start && reduced.violated_constant_rows == 0 &&
        change < -1e-9 * std::max(1.0, std::abs(best))) {
      {
        sub.read_free_groups(reduced.expand(sub.model, r.solution), y);
        best += change;
        count = count_of(y);
        assert(std::abs(best - group_objective(groups, gc, fg, y, target, params)) <=
               1e-6 * std::max(1.0, std::abs(best)));
        ++result.neighbourhoods_improved;
        ++improved_in_sweep;
        if (!params.quiet) {
          std::fprintf(stderr, "\rselect      neighbourhood %u  objective %.4f  %6.1f s",
                       result.neighbourhoods, best, lns_clock.seconds());
          std::fflush(stderr);
        }
      }
    }
    for (Index a : free_list) free[a] = 0;
  }
  if (!params.quiet && result.neighbourhoods_improved) std::fprintf(stderr, "\n");
  summary.status = ilp::SolveStatus::Feasible;  // no bound: a neighbourhood optimum is not a global one
  summary.objective = best;
  summary.seconds = lns_clock.seconds();
  summary.solution_is_start = result.neighbourhoods_improved == 0;
  summary.start = ilp::StartStatus::NotUsed;
  result.solve = std::move(summary);
  result.solver_ran = true;
  result.seconds_solve += lns_clock.seconds();
  return y;
}

}  // namespace select_detail

namespace detail {

using namespace select_detail;

ilp::Model neighbourhood_model(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                               std::uint64_t target, const SelectionParams& params,
                               const std::vector<std::uint8_t>& edge_kept, const std::vector<Index>& free_edges,
                               bool indexed) {
  const Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  std::vector<std::uint8_t> free(p.groups.count, 0);
  std::vector<Index> free_list;
  for (Index e : free_edges) {
    const Index grp = p.groups.edge_group[e];
    if (!p.groups.fixed[grp] && !free[grp]) {
      free[grp] = 1;
      free_list.push_back(grp);
    }
  }
  std::sort(free_list.begin(), free_list.end());
  const ScopeIndex index = make_scope_index(p.groups, p.gc, p.fg);
  std::uint64_t count = 0;
  for (Index f = 0; f + 1 < p.fg.offsets.size(); ++f) count += face_count(p.fg, f, p.y);
  ModelBuilder sub(mesh, conn, analysis, p.groups, p.gc, p.fg, p.importance, params);
  if (indexed) sub.set_scope(free, p.y, index, free_list, count);
  else sub.set_scope(free, p.y);
  sub.build(target, true);
  sub.model.set_initial_solution(sub.complete(p.y, target));
  return ilp::without_fixed_columns(sub.model).model;
}

}  // namespace detail

}  // namespace quadlod
