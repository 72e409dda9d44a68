// Simulated annealing of the edge selection (anneal.h): the annealing moves (flips, swaps and
// chains, journaled for undo), one annealing run on Eq. 9 in Eq. 2's band, priced (cost + μ N') or
// reaching for the band; the plain schedule beside the penalty continuation on short schedules;
// priced runs by independent component; the runs on several threads; reach_band; and the test
// entry points detail::priced_anneal, priced_component_anneal and reach_band (selection.h).
#include "select/anneal.h"

#include "ilp/solver.h"
#include "select/moves.h"
#include "util/progress.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <random>
#include <thread>

namespace quadlod {

namespace select_detail {

namespace {

// The two-group and chain moves of the annealing (anneal() and anneal_component()). Their flips
// are journaled in `flipped`, so that a rejected move is undone; `rest` collects their change of
// Eq. 9 without the count term (the caller prices the count from st.count).
struct MoveScratch {
  std::vector<std::pair<Index, std::int64_t>> flipped;
  std::vector<Index> queue;
  std::vector<std::uint32_t> stamp;
  std::uint32_t round = 0;
};

// Flips grp unless collapsing it would break Eq. 8 (then nothing is done: false).
bool flip_journaled(SelectionState& st, Index grp, const SelectionParams& params, double& rest, MoveScratch& ms) {
  if (st.y[grp] && !st.may_collapse(grp)) return false;
  const std::int64_t dc = st.delta_count(grp);
  rest += st.delta_rest(grp, params);
  st.flip(grp, dc);
  ms.flipped.emplace_back(grp, dc);
  return true;
}

void undo_journaled(SelectionState& st, MoveScratch& ms) {
  while (!ms.flipped.empty()) {
    st.flip(ms.flipped.back().first, -ms.flipped.back().second);
    ms.flipped.pop_back();
  }
}

// Swaps a with a random group of the other value that shares a face with it (a must have one).
// The kept one first: keeping never breaks Eq. 8. false = nothing flipped.
bool swap_move(SelectionState& st, const Groups& g, Index a, const std::vector<Index>& adj_offsets,
               const std::vector<Index>& adjacent, std::mt19937_64& rng, const SelectionParams& params,
               double& rest, MoveScratch& ms) {
  const Index b = adjacent[adj_offsets[a] + rng() % (adj_offsets[a + 1] - adj_offsets[a])];
  if (g.fixed[b] || st.y[b] == st.y[a]) return false;
  const Index keep = st.y[a] ? b : a, drop = st.y[a] ? a : b;
  flip_journaled(st, keep, params, rest, ms);
  if (!flip_journaled(st, drop, params, rest, ms)) {
    undo_journaled(st, ms);
    return false;
  }
  return true;
}

// Flips 2 – 16 groups of a's value, breadth-first along split partners from a (λ_tri pairs).
// false = nothing flipped.
bool chain_move(SelectionState& st, const Groups& g, const GroupConstraints& gc, Index a, std::mt19937_64& rng,
                const SelectionParams& params, double& rest, MoveScratch& ms) {
  if (ms.stamp.size() != g.count) ms.stamp.assign(g.count, 0);
  const std::uint8_t v = st.y[a];
  const std::size_t length = 2 + rng() % 15;
  ms.queue.assign(1, a);
  ms.stamp[a] = ++ms.round;
  for (std::size_t head = 0; head < ms.queue.size() && ms.flipped.size() < length; ++head) {
    const Index x = ms.queue[head];
    if (st.y[x] != v || !flip_journaled(st, x, params, rest, ms)) continue;
    for (Index b : gc.group_split[x])
      if (!g.fixed[b] && ms.stamp[b] != ms.round && st.y[b] == v) {
        ms.stamp[b] = ms.round;
        ms.queue.push_back(b);
      }
  }
  return !ms.flipped.empty();
}

// Simulated annealing over the local-search moves (beyond the paper; docs/formulation.md,
// "Speed"): random single flips, swaps with an adjacent group of the other value, and chains of
// random length along λ_tri split partners (see chain_moves), each evaluated exactly through the
// incremental state, never leaving Eq. 2's band or breaking Eq. 8; a worsening move of Δ is
// taken with probability exp(−Δ/T), T falling geometrically from t0 to t1 over the budget (time,
// or anneal_moves_per_group moves per free group, whichever ends first). The
// best selection seen is returned. Microseconds per move, so millions of moves fit where the
// neighbourhood MIPs manage a few hundred; the MIPs then polish its result.
//
// What an annealing run minimises (AnnealGoal::Kind):
// * Band: Eq. 9 in Eq. 2's band, with the penalty continuation below.
// * Priced: cost + μ N' instead, the count term of Eq. 9 replaced by a price μ per
//   triangle-equivalent, with no band and no continuation, which makes every independent
//   component a problem of its own (the Lagrangian relaxation the recombination uses). Its end
//   state lies anywhere in N' and is only an alternative for the recombination.
// * Reach: from a start outside the band (a greedy selection the hard constraints stopped short
//   of it), Eq. 9 plus ρ per triangle-equivalent outside the band, moving freely; the best state
//   is the one nearest the band, then the lowest Eq. 9 (SelectionParams::reach_time_fraction).
struct AnnealGoal {
  enum class Kind { Band, Priced, Reach };
  Kind kind = Kind::Band;
  double weight = 0.0;  // Priced: μ; Reach: ρ
  static AnnealGoal priced(double mu) { return {Kind::Priced, mu}; }
  static AnnealGoal reach(double rho) { return {Kind::Reach, rho}; }
};

std::vector<std::uint8_t> anneal(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                 std::vector<std::uint8_t> y, std::uint64_t target, const SelectionParams& params,
                                 double seconds, const std::vector<Index>& adj_offsets,
                                 const std::vector<Index>& adjacent, AnnealStats& stats,
                                 AnnealGoal goal = {}) {
  Stopwatch clock;
  SelectionState st(g, gc, fg, std::move(y));
  const double n = double(target), band = params.epsilon_n * n;
  const bool priced = goal.kind == AnnealGoal::Kind::Priced, reach = goal.kind == AnnealGoal::Kind::Reach;
  const bool banded = goal.kind == AnnealGoal::Kind::Band;
  auto beyond = [&](std::int64_t c) { return std::max(0.0, std::abs(double(c) - n) - band); };
  auto count_term = [&](std::int64_t c) {
    return priced ? goal.weight * double(c) : std::abs(double(c) - n) + (reach ? goal.weight * beyond(c) : 0.0);
  };
  auto in_band = [&](std::int64_t c) { return !banded || std::abs(double(c) - n) <= band; };
  std::vector<Index> movable;
  for (Index grp = 0; grp < g.count; ++grp)
    if (!g.fixed[grp]) movable.push_back(grp);
  std::vector<std::uint8_t> best_y = st.y;
  if (movable.empty() || seconds <= 0.0) return best_y;
  std::mt19937_64 rng(params.solve.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double current = 0.0, best = 0.0;  // relative to the start
  MoveScratch moves;
  auto& flipped = moves.flipped;
  const double t0 = params.anneal_t0, t1 = params.anneal_t1;
  double temperature = t0;
  // Penalty continuation (SelectionParams::anneal_count_weight): until the ramp starts the count
  // term weighs w0 and N' may leave Eq. 2's band by band_relax × the band; over the ramp both go
  // linearly to the true objective and the hard band, the excess beyond the band penalised by
  // band_penalty × ramp per triangle-equivalent.
  const double w0 = banded ? params.anneal_count_weight : 1.0, band_relax = params.anneal_band_relax;
  const double rho_max = params.anneal_band_penalty;
  const double count_ramp_start = params.anneal_ramp_start, count_ramp_end = params.anneal_ramp_end;
  double count_weight = w0;
  double ramp = 0.0;  // 0 before the ramp, 1 after it
  auto outside = [&](std::int64_t c) { return banded ? beyond(c) : 0.0; };
  auto annealed = [&](double delta, std::int64_t c0, std::int64_t c1) {
    return delta - (1.0 - count_weight) * (count_term(c1) - count_term(c0)) +
           rho_max * ramp * (outside(c1) - outside(c0));
  };
  // Whether the annealing may go from count c0 to c1.
  auto allowed = [&](std::int64_t c0, std::int64_t c1) {
    if (!banded || in_band(c1)) return true;
    if (ramp >= 1.0) return outside(c1) <= outside(c0);
    return std::abs(double(c1) - n) <= band * (1.0 + band_relax);
  };
  // The best selection is kept as best_y plus a journal of the groups flipped since: a new best
  // copies only those (a full copy per improvement cost O(groups) each time). A journal longer
  // than the groups falls back to one full copy.
  std::vector<Index> journal;
  bool journal_full = false;
  auto record = [&](Index grp) {
    if (journal_full) return;
    journal.push_back(grp);
    if (journal.size() > movable.size()) {
      journal_full = true;
      journal.clear();
    }
  };
  // Reach: the best state is the nearest to the band, then the lowest (penalised) Eq. 9.
  double best_beyond = reach ? beyond(st.count) : 0.0;
  auto accept = [&](double delta) {
    ++stats.accepted;
    current += delta;
    const bool better = reach ? beyond(st.count) < best_beyond - 1e-9 ||
                                    (beyond(st.count) <= best_beyond + 1e-9 && current < best - 1e-9)
                              : current < best - 1e-9 && in_band(st.count);
    if (better) {
      best = current;
      best_beyond = reach ? beyond(st.count) : 0.0;
      if (journal_full) best_y = st.y;
      else
        for (Index grp : journal) best_y[grp] = st.y[grp];
      journal.clear();
      journal_full = false;
    }
  };
  CompoundScratch compound;
  // (compound moves judge Eq. 9's count term and band themselves: only in banded runs)
  const double compound_share = params.compound_moves && banded ? params.anneal_compound_share : 0.0;
  // The schedule runs on time or on moves, whichever ends first (small meshes: moves).
  const double max_moves = params.anneal_moves_per_group * double(movable.size());
  for (;; ++stats.moves) {
    if ((stats.moves & 1023) == 0) {
      const double by_time = clock.seconds() / seconds, by_moves = double(stats.moves) / max_moves;
      if (by_time >= 1.0 || by_moves >= 1.0) {
        stats.schedule_done = by_moves >= 1.0;
        break;
      }
      const double progress = std::max(by_time, by_moves);
      temperature = t0 * std::pow(t1 / t0, progress);
      ramp = progress >= count_ramp_end     ? 1.0
             : progress <= count_ramp_start ? 0.0
                                            : (progress - count_ramp_start) / (count_ramp_end - count_ramp_start);
      count_weight = w0 + (1.0 - w0) * ramp;
    }
    const Index a = movable[rng() % movable.size()];
    const std::int64_t c0 = st.count;
    double rest = 0.0;
    flipped.clear();
    if (compound_share > 0.0 && unit(rng) < compound_share) {
      const double delta = compound_move(st, a, g, adj_offsets, adjacent, target, params, compound, flipped);
      if (!(delta < INFINITY)) continue;  // nothing in the band; the state is unchanged
      const double da = annealed(delta, c0, st.count);
      if (da > 0.0 && unit(rng) >= std::exp(-da / temperature)) {
        undo_journaled(st, moves);
        continue;
      }
      ++stats.compounds;
      for (const auto& fl : flipped) record(fl.first);
      accept(delta);
      continue;
    }
    const std::uint64_t kind = rng() % 3;
    if (kind == 0 || (kind == 1 && adj_offsets[a] == adj_offsets[a + 1])) {
      // A single flip is judged before it is made: most moves are rejected, and flipping and
      // undoing them costs as much as the evaluation. Eq. 8 is checked last, only for a move
      // that would be taken (most are not).
      const std::int64_t dc = st.delta_count(a);
      if (!allowed(c0, c0 + dc)) continue;
      const double delta = count_term(c0 + dc) - count_term(c0) + st.delta_rest(a, params);
      const double da = annealed(delta, c0, c0 + dc);
      if (da > 0.0 && unit(rng) >= std::exp(-da / temperature)) continue;
      if (st.y[a] && !st.may_collapse(a)) continue;
      st.flip(a, dc);
      record(a);
      accept(delta);
      continue;
    } else if (kind == 1) {
      if (!swap_move(st, g, a, adj_offsets, adjacent, rng, params, rest, moves)) continue;
    } else if (!chain_move(st, g, gc, a, rng, params, rest, moves)) {
      continue;
    }
    const double delta = count_term(st.count) - count_term(c0) + rest;
    const double da = annealed(delta, c0, st.count);
    if (!allowed(c0, st.count) || (da > 0.0 && unit(rng) >= std::exp(-da / temperature))) {
      undo_journaled(st, moves);
      continue;
    }
    for (const auto& fl : flipped) record(fl.first);
    accept(delta);
  }
  return best_y;
}

// One annealing chain. Where the schedule ends by its move count (small meshes: ram's whole
// schedule takes 0.3 s), the penalty continuation spends 60 % of a short schedule on the relaxed
// problem and can end above an annealing on Eq. 9 throughout (round-1 selection at 0.4, 5 s:
// opensubdiv_car_cage 1 362.2 → 1 583.9, hitachi395 650.5 → 698.5, frankie 876.8 → 909.4 when the
// continuation came in). So there the plain schedule (SelectionParams::anneal_plain_when_short)
// runs too, from the same start, and the lower Eq. 9 wins (1 362.2, 646.5, 882.2); on large
// meshes the schedule ends by time and only the continuation runs.
std::vector<std::uint8_t> anneal_chain(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                       std::vector<std::uint8_t> y, std::uint64_t target,
                                       const SelectionParams& params, double seconds,
                                       const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                       AnnealStats& stats, AnnealGoal goal = {}) {
  Stopwatch clock;
  const bool continuation = goal.kind == AnnealGoal::Kind::Band && params.anneal_plain_when_short &&
                            (params.anneal_count_weight != 1.0 || params.anneal_band_relax != 0.0);
  std::vector<std::uint8_t> start = continuation ? y : std::vector<std::uint8_t>{};
  std::vector<std::uint8_t> best =
      anneal(g, gc, fg, std::move(y), target, params, seconds, adj_offsets, adjacent, stats, goal);
  if (!continuation || !stats.schedule_done || clock.seconds() >= 0.5 * seconds) return best;
  SelectionParams plain = params;
  plain.anneal_count_weight = 1.0;
  plain.anneal_band_relax = 0.0;
  AnnealStats plain_stats;
  std::vector<std::uint8_t> other =
      anneal(g, gc, fg, std::move(start), target, plain, seconds - clock.seconds(), adj_offsets, adjacent, plain_stats);
  stats.moves += plain_stats.moves;
  stats.accepted += plain_stats.accepted;
  stats.compounds += plain_stats.compounds;
  if (group_objective(g, gc, fg, other, target, params) < group_objective(g, gc, fg, best, target, params)) {
    stats.schedule_done = plain_stats.schedule_done;
    return other;
  }
  return best;
}

// Scratch of anneal_component, kept across calls.
struct ComponentScratch {
  MoveScratch moves;
  std::vector<std::uint8_t> best;
};

// One priced annealing (cost + μ N', no band) of the groups of one free component, in a state
// shared with the other components: no term of Eq. 9 but the count couples components, and the
// price makes the count separable, so the component's moves see only its own groups. The moves
// are those of anneal() (flip, swap with a neighbour, chain along split partners); the schedule
// runs t0 → t1 over `moves` moves, or ends early at the clock's `deadline`. The state ends at the
// best selection of the component the run met; returns its value minus the start's.
double anneal_component(SelectionState& st, const Groups& g, const GroupConstraints& gc,
                        const Index* movable, std::size_t m, double mu, std::int64_t moves,
                        const SelectionParams& params, const std::vector<Index>& adj_offsets,
                        const std::vector<Index>& adjacent, std::mt19937_64& rng, ComponentScratch& sc,
                        const Stopwatch& clock, double deadline, std::int64_t& moves_done) {
  if (m == 0) return 0.0;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  sc.best.resize(m);
  for (std::size_t i = 0; i < m; ++i) sc.best[i] = st.y[movable[i]];
  double current = 0.0, best = 0.0;
  const double t0 = params.anneal_t0, t1 = params.anneal_t1;
  double temperature = t0;
  auto take = [&](double delta) {
    current += delta;
    if (current < best - 1e-9) {
      best = current;
      for (std::size_t i = 0; i < m; ++i) sc.best[i] = st.y[movable[i]];
    }
  };
  auto rejected = [&](double delta) { return delta > 0.0 && unit(rng) >= std::exp(-delta / temperature); };
  std::int64_t k = 0;
  for (; k < moves; ++k) {
    if ((k & 255) == 0) {
      if ((k & 16383) == 0 && k > 0 && clock.seconds() >= deadline) break;
      temperature = t0 * std::pow(t1 / t0, double(k) / double(moves));
    }
    const Index a = movable[rng() % m];
    const std::uint64_t kind = rng() % 3;
    sc.moves.flipped.clear();
    const std::int64_t c0 = st.count;
    if (kind == 0 || (kind == 1 && adj_offsets[a] == adj_offsets[a + 1])) {
      // judged before it is made, as in anneal()
      const std::int64_t dc = st.delta_count(a);
      const double delta = mu * double(dc) + st.delta_rest(a, params);
      if (rejected(delta) || (st.y[a] && !st.may_collapse(a))) continue;
      st.flip(a, dc);
      take(delta);
      continue;
    }
    double rest = 0.0;
    if (kind == 1 ? !swap_move(st, g, a, adj_offsets, adjacent, rng, params, rest, sc.moves)
                  : !chain_move(st, g, gc, a, rng, params, rest, sc.moves))
      continue;
    const double delta = rest + mu * double(st.count - c0);
    if (rejected(delta)) {
      undo_journaled(st, sc.moves);
      continue;
    }
    take(delta);
  }
  moves_done += k;
  // Back to the best state: flip() does not check Eq. 8, and the end state (the best) kept it.
  for (std::size_t i = 0; i < m; ++i)
    if (st.y[movable[i]] != sc.best[i]) st.flip(movable[i], st.delta_count(movable[i]));
  return best;
}

// A priced run by component (SelectionParams::priced_by_component): from `y`, in rounds of
// growing effort. Round r gives every component still open two annealings of
// priced_moves_per_group × factor^r moves per group, each from the component's state in `y`; a
// component whose two annealings end at the same value, equal to its best so far, is closed.
// Rounds go on up to priced_moves_per_group_max while `seconds` last. Every component ends at
// the best state it met (its state in `y` if that is lower). Why: the annealing of the whole mesh
// spends the same moves on every group, but most components of a many-part mesh settle in the
// first round (c172p at 0.4, 5 s: about 2.2 annealings per component and run), and a few reach
// states 8 – 18 lower only now and then at 1 600 moves per group (μ = 0.3, eight seeds;
// docs/formulation.md).
std::vector<std::uint8_t> anneal_priced_components(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                                   const FreeComponents& fc, std::vector<std::uint8_t> y,
                                                   double mu, const SelectionParams& params, double seconds,
                                                   const std::vector<Index>& adj_offsets,
                                                   const std::vector<Index>& adjacent, AnnealStats& stats) {
  Stopwatch clock;
  SelectionState st(g, gc, fg, std::move(y));
  const std::vector<std::uint8_t> start = st.y;
  std::vector<std::uint8_t> best_y = st.y;
  std::vector<double> best(fc.count, 0.0);  // relative to the start
  std::vector<Index> open(fc.count);
  std::iota(open.begin(), open.end(), Index{0});
  std::mt19937_64 rng(params.solve.seed);
  ComponentScratch sc;
  const double factor = std::max(params.priced_moves_factor, 1.0 + 1e-9);
  // At most the moves of a whole-mesh schedule (anneal_moves_per_group per free group): where
  // schedules end by their move count (small meshes), more runs in the same time do better.
  const double budget = params.anneal_moves_per_group * double(fc.offsets.back());
  const std::int64_t moves_before = stats.moves;
  auto spent = [&] { return clock.seconds() >= seconds || double(stats.moves - moves_before) >= budget; };
  for (double per_group = params.priced_moves_per_group;
       !open.empty() && per_group <= params.priced_moves_per_group_max * (1.0 + 1e-9); per_group *= factor) {
    std::size_t kept_open = 0;
    for (std::size_t i = 0; i < open.size(); ++i) {
      const Index c = open[i];
      const Index* movable = &fc.groups[fc.offsets[c]];
      const std::size_t m = fc.offsets[c + 1] - fc.offsets[c];
      const auto moves = static_cast<std::int64_t>(std::ceil(per_group * double(m)));
      double value[2] = {INFINITY, INFINITY};
      for (double& v : value) {
        if (spent()) break;
        for (std::size_t j = 0; j < m; ++j)  // from the start: restarts, not continuations
          if (st.y[movable[j]] != start[movable[j]]) st.flip(movable[j], st.delta_count(movable[j]));
        v = anneal_component(st, g, gc, movable, m, mu, moves, params, adj_offsets, adjacent, rng, sc, clock,
                             seconds, stats.moves);
        ++stats.component_runs;
        if (v < best[c] - 1e-9) {
          best[c] = v;
          for (std::size_t j = 0; j < m; ++j) best_y[movable[j]] = st.y[movable[j]];
        }
      }
      if (spent()) {
        kept_open = 0;
        open.clear();
        break;
      }
      const bool settled = std::abs(value[0] - value[1]) <= 1e-9 && std::abs(value[0] - best[c]) <= 1e-9;
      if (!settled) open[kept_open++] = c;
    }
    open.resize(kept_open);
  }
  return best_y;
}

}  // namespace

// Annealing runs: see anneal.h.
std::vector<std::uint8_t> anneal_runs(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                      std::vector<std::uint8_t> y, std::uint64_t target,
                                      const SelectionParams& params, double seconds,
                                      const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                      int threads, AnnealStats& stats,
                                      std::vector<std::vector<std::uint8_t>>* alternatives) {
  threads = std::max(threads, 1);
  // Runs split a thread's time only where the recombination can combine them: with one component
  // holding most free groups they only compete as a best-of-n, and one longer run per thread is
  // better (oakeshott_sword_quaddominant, 0.4, 5 s, 2 threads: Eq. 9 -1 849.3 with two runs per
  // thread, -1 870.2, -1 898.4, -1 881.5 with one). The extra runs after schedules that end by
  // their move count stay everywhere: on small meshes their best-of-n beats the neighbourhood
  // MIPs that would get the time instead (5 s, 2 threads, with / without them: collada_duck
  // 142.7 / 167.8, opensubdiv_bishop_cage 97.0 / 103.1, blender_suzanne 641.8 / 646.6;
  // assimp_suzanne_subdiv is the exception, -10 263.7 / -10 288.2).
  int planned = std::max(params.anneal_runs, 1);
  FreeComponents components;
  if (planned > 1) {
    components = free_components(g, gc, fg);
    Index largest = 0;
    for (Index c = 0; c < components.count; ++c)
      largest = std::max(largest, components.offsets[c + 1] - components.offsets[c]);
    if (double(largest) > params.anneal_runs_max_share * double(components.offsets.back())) planned = 1;
  }
  Stopwatch clock;
  struct Run {
    std::uint32_t index;  // seed offset
    bool priced = false;
    double value;         // Eq. 9; INFINITY for a priced run (never the incumbent)
    std::vector<std::uint8_t> y;
    AnnealStats stats;
  };
  std::vector<std::vector<Run>> runs(static_cast<std::size_t>(threads));
  // Where the runs are recombined, every other run of a thread (its second, fourth, …) is a
  // priced one, at a price of the count term's slope at the thread's first run (0 inside the
  // band's middle, ±1 near its edges, as in the recombination) plus the next offset of
  // anneal_prices (mirrored below the band), so that each component also offers states at the
  // exchange rates of triangle-equivalents against Eq. 9's other terms. With priced_by_component
  // it anneals the components one by one from the thread's first run (anneal_priced_components).
  const bool priced_runs = planned > 1 && !params.anneal_prices.empty();
  const auto band = static_cast<std::int64_t>(std::floor(params.epsilon_n * double(target)));
  auto work = [&](int k) {
    double last = 0.0;
    double slope = 0.0;
    for (int r = 0;; ++r) {
      const double left = seconds - clock.seconds();
      if (left <= 0.0 || r >= params.anneal_max_runs || (r >= planned && left < 0.5 * last)) break;
      Run run;
      run.index = static_cast<std::uint32_t>(r * threads + k);
      SelectionParams p = params;
      p.solve.seed = params.solve.seed + run.index;
      std::optional<double> price;
      if (priced_runs && r % 2 == 1) {
        // priced runs in the order thread 0's first, thread 1's first, …
        const auto i = std::size_t(r / 2) * std::size_t(threads) + std::size_t(k);
        const double offset = params.anneal_prices[i % params.anneal_prices.size()];
        price = slope + (slope < 0.0 ? -offset : offset);
      }
      Stopwatch run_clock;
      const double share = left / double(std::max(1, planned - r));
      if (price && params.priced_by_component)  // from the thread's first (plain) run
        run.y = anneal_priced_components(g, gc, fg, components, runs[std::size_t(k)].front().y, *price, p, share,
                                         adj_offsets, adjacent, run.stats);
      else
        run.y = anneal_chain(g, gc, fg, y, target, p, share, adj_offsets, adjacent, run.stats,
                             price ? AnnealGoal::priced(*price) : AnnealGoal{});
      last = run_clock.seconds();
      run.priced = price.has_value();
      run.value = run.priced ? INFINITY : group_objective(g, gc, fg, run.y, target, params);
      if (r == 0) {
        const auto d = static_cast<std::int64_t>(selection_count(fg, run.y)) - static_cast<std::int64_t>(target);
        slope = count_slope(d, band);
      }
      runs[std::size_t(k)].push_back(std::move(run));
    }
  };
  if (threads == 1) {
    work(0);
  } else {
    std::vector<std::thread> workers;
    for (int k = 0; k < threads; ++k) workers.emplace_back(work, k);
    for (std::thread& w : workers) w.join();
  }
  std::vector<Run> all;
  for (auto& thread_runs : runs)
    for (Run& run : thread_runs) all.push_back(std::move(run));
  stats = {};
  if (all.empty()) return y;
  std::sort(all.begin(), all.end(),
            [](const Run& a, const Run& b) { return a.value < b.value || (a.value == b.value && a.index < b.index); });
  for (const Run& run : all) {
    stats.priced_runs += run.priced;
    stats.moves += run.stats.moves;
    stats.accepted += run.stats.accepted;
    stats.compounds += run.stats.compounds;
    stats.component_runs += run.stats.component_runs;
  }
  stats.runs = static_cast<int>(all.size());
  stats.schedule_done = all.front().stats.schedule_done;
  if (alternatives)
    for (std::size_t i = 1; i < all.size() && alternatives->size() < params.anneal_max_alternatives; ++i)
      alternatives->push_back(std::move(all[i].y));
  return std::move(all.front().y);
}

// Reaching Eq. 2's band: see anneal.h.
std::vector<std::uint8_t> reach_band(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                     const std::vector<std::uint8_t>& y, std::uint64_t target,
                                     const SelectionParams& params, double seconds,
                                     const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                     int threads, AnnealStats& stats) {
  threads = std::max(threads, 1);
  std::vector<std::vector<std::uint8_t>> ends(static_cast<std::size_t>(threads));
  std::vector<AnnealStats> run_stats(static_cast<std::size_t>(threads));
  auto work = [&](int k) {
    SelectionParams p = params;
    p.solve.seed = params.solve.seed + static_cast<std::uint32_t>(k);
    p.anneal_t0 = params.reach_t0;
    ends[std::size_t(k)] = anneal(g, gc, fg, y, target, p, seconds, adj_offsets, adjacent, run_stats[std::size_t(k)],
                                  AnnealGoal::reach(params.reach_band_penalty));
  };
  if (threads == 1) {
    work(0);
  } else {
    std::vector<std::thread> workers;
    for (int k = 0; k < threads; ++k) workers.emplace_back(work, k);
    for (std::thread& w : workers) w.join();
  }
  const double n = double(target), band = params.epsilon_n * n;
  auto key = [&](const std::vector<std::uint8_t>& s) {
    const double beyond = std::max(0.0, std::abs(double(selection_count(fg, s)) - n) - band);
    return std::pair(beyond, group_objective(g, gc, fg, s, target, params));
  };
  std::size_t best = 0;
  for (std::size_t k = 1; k < ends.size(); ++k)
    if (key(ends[k]) < key(ends[best])) best = k;
  stats = {};
  for (const AnnealStats& rs : run_stats) {
    stats.moves += rs.moves;
    stats.accepted += rs.accepted;
  }
  stats.runs = threads;
  return std::move(ends[best]);
}

}  // namespace select_detail

namespace detail {

using namespace select_detail;

std::vector<std::uint8_t> priced_anneal(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                        std::uint64_t target, const SelectionParams& params,
                                        const std::vector<std::uint8_t>& edge_kept, double price, double seconds) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  AnnealStats as;
  return p.edge_bits(conn, anneal_chain(p.groups, p.gc, p.fg, p.y, target, params, seconds, p.adj_offsets,
                                        p.adjacent, as, AnnealGoal::priced(price)));
}

std::vector<std::uint8_t> priced_component_anneal(const PolyMesh& mesh, const Connectivity& conn,
                                                  const AnalysisResult& analysis, const SelectionParams& params,
                                                  const std::vector<std::uint8_t>& edge_kept, double price,
                                                  double seconds) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  AnnealStats as;
  const FreeComponents fc = free_components(p.groups, p.gc, p.fg);
  return p.edge_bits(conn, anneal_priced_components(p.groups, p.gc, p.fg, fc, p.y, price, params, seconds,
                                                    p.adj_offsets, p.adjacent, as));
}

std::vector<std::uint8_t> reach_band(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                     std::uint64_t target, const SelectionParams& params,
                                     const std::vector<std::uint8_t>& edge_kept, double seconds) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  AnnealStats as;
  return p.edge_bits(conn, select_detail::reach_band(p.groups, p.gc, p.fg, p.y, target, params, seconds,
                                                     p.adj_offsets, p.adjacent,
                                                     ilp::backend::resolve_threads(params.solve), as));
}

}  // namespace detail

}  // namespace quadlod
