// Simulated annealing of the edge selection (beyond the paper; docs/formulation.md, "Speed" and
// "Targets the greedy misses"): annealing runs on several threads from the greedy start (plain,
// priced, and priced runs by independent component), and reach_band, the annealing that looks
// for Eq. 2's band where the greedy selection misses it. anneal.cpp has the moves and schedules.
#pragma once

#include "select/groups.h"

#include <cstdint>
#include <vector>

namespace quadlod::select_detail {

struct AnnealStats {
  std::int64_t moves = 0, accepted = 0, compounds = 0;  // compounds: compound moves accepted
  std::int64_t component_runs = 0;  // priced runs by component: annealings of one component
  bool schedule_done = false;  // ended by its move count, not by the time
  int runs = 0;                // annealing runs (anneal_runs)
  int priced_runs = 0;         // of which priced
};

// Annealing runs on `threads` threads (issue 4; docs/formulation.md, "Speed"). Each thread runs
// annealing chains one after the other from the same start: params.anneal_runs of them, each an
// equal share of what is left of its time, and more while at least half the last run's time is
// left (a schedule that ends by its move count leaves time: small meshes, long budgets), up to
// params.anneal_max_runs per thread. Run i
// (in the order thread 0's first, thread 1's first, …, thread 0's second, …) has seed
// solve.seed + i. The run with the lowest Eq. 9 is returned (ties: the lowest seed); the others,
// best first, go to `alternatives` (at most params.anneal_max_alternatives): the recombination
// takes each independent component from whichever run did best there. On c172p the runs end
// 5-10 % apart in Eq. 9, but not in the same components, so the combination lies below every
// run; one long run per thread, whose results only compete as a best-of-k, ends higher. Every
// other run is a priced one where runs are recombined (below; SelectionParams::anneal_prices).
std::vector<std::uint8_t> anneal_runs(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                      std::vector<std::uint8_t> y, std::uint64_t target,
                                      const SelectionParams& params, double seconds,
                                      const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                      int threads, AnnealStats& stats,
                                      std::vector<std::vector<std::uint8_t>>* alternatives);

// Reaching Eq. 2's band from a start the hard constraints stopped the greedy short of
// (SelectionParams::reach_time_fraction; docs/formulation.md, "Targets the greedy misses"): one
// Reach annealing run per thread (seed solve.seed + k) for `seconds`; the state nearest the band
// wins, then the lowest Eq. 9. The greedy collapses groups cheapest first and skips any whose
// collapse Eq. 8 forbids at that moment, so where triangle clusters interleave its early choices
// can block more triangle-equivalents than they remove; the annealing undoes such choices.
std::vector<std::uint8_t> reach_band(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                     const std::vector<std::uint8_t>& y, std::uint64_t target,
                                     const SelectionParams& params, double seconds,
                                     const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                     int threads, AnnealStats& stats);

}  // namespace quadlod::select_detail
