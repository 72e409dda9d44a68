// Recombination of independent parts (recombine.h): per-component totals of N' and Eq. 9's other
// terms, the priced descent (cost + μ N'), the rounds of priced descents and the dynamic
// programme over the components' alternatives, and the test entry point detail::recombine
// (selection.h).
#include "select/recombine.h"

#include "select/moves.h"
#include "util/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace quadlod {

namespace select_detail {

namespace {

// Per component: its N'_c (faces with a free group in it) and cost_c (Eq. 9 without the count
// term: λ_edge, λ_geo and λ_tri terms of its groups, clusters and split pairs).
void component_totals(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg, const FreeComponents& fc,
                      const std::vector<std::uint8_t>& y, const SelectionParams& params,
                      std::vector<std::int64_t>& count, std::vector<double>& cost) {
  count.assign(fc.count, 0);
  cost.assign(fc.count, 0.0);
  for (Index f = 0; f + 1 < fg.offsets.size(); ++f)
    for (Index i = fg.offsets[f]; i < fg.offsets[f + 1]; ++i)
      if (const Index c = fc.of_group[fg.group[i]]; c != kInvalidIndex) {
        count[c] += face_count(fg, f, y);
        break;
      }
  for (Index x = 0; x < g.count; ++x)
    if (fc.of_group[x] != kInvalidIndex) cost[fc.of_group[x]] -= params.lambda_edge * y[x] * g.importance[x];
  for (const auto& cl : gc.geo)
    if (std::none_of(cl.begin(), cl.end(), [&](Index x) { return y[x]; })) cost[fc.of_group[cl[0]]] += params.lambda_geo;
  for (const auto& [a, b] : gc.split_pairs)
    if (y[a] != y[b]) cost[fc.of_group[g.fixed[a] ? b : a]] += params.lambda_tri;
}

// Descent on cost + μ N' (no count term, no band: the recombination enforces Eq. 2): single
// flips, swaps with an adjacent group of the other value, and chains along split partners (as
// chain_moves), while they lower it; Eq. 8 is kept.
void priced_descent(SelectionState& st, const Groups& g, const GroupConstraints& gc, double mu,
                    const SelectionParams& params, const std::vector<Index>& adj_offsets,
                    const std::vector<Index>& adjacent, const Stopwatch& clock, double seconds) {
  constexpr double eps = 1e-9;
  int passes = 0;
  for (bool improved = true; improved && clock.seconds() < seconds && passes < params.recombination_passes;) {
    improved = false;
    ++passes;
    for (Index a = 0; a < g.count; ++a) {
      if (g.fixed[a]) continue;
      const std::int64_t dc = st.delta_count(a);
      if (st.delta_rest(a, params) + mu * double(dc) < -eps && (!st.y[a] || st.may_collapse(a))) {
        st.flip(a, dc);
        improved = true;
      }
    }
    improved |= swap_walk(
                    st, g, params, adj_offsets, adjacent, clock, seconds, [&](std::int64_t c) { return mu * double(c); },
                    [](std::int64_t) { return true; }, false) > 0;
    improved |= chain_walk(
                    st, g, gc, params, clock, seconds, [&](std::int64_t c) { return mu * double(c); },
                    [](std::int64_t) { return true; }) > 0;
  }
}

}  // namespace

// Rounds of priced descents and the programme: see recombine.h.
std::vector<std::uint8_t> recombine_components(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                               std::vector<std::uint8_t> y, std::uint64_t target,
                                               const SelectionParams& params, double seconds,
                                               const std::vector<Index>& adj_offsets,
                                               const std::vector<Index>& adjacent, RecombineStats& stats,
                                               const std::vector<std::vector<std::uint8_t>>& alternatives) {
  Stopwatch clock;
  const FreeComponents fc = free_components(g, gc, fg);
  stats.components = fc.count;
  for (Index c = 0; c < fc.count; ++c) stats.largest = std::max(stats.largest, fc.offsets[c + 1] - fc.offsets[c]);
  const std::vector<double>& prices = params.recombination_prices;
  if (fc.count == 0 || (prices.empty() && alternatives.empty())) return y;
  const auto n = static_cast<std::int64_t>(target);
  const auto band = static_cast<std::int64_t>(std::floor(params.epsilon_n * double(target)));
  std::vector<std::int64_t> count0, count1;
  std::vector<double> cost0, cost1;
  // The alternatives (other annealing runs), then the end states of the priced descents; an
  // option names its state in a byte.
  std::vector<std::vector<std::uint8_t>> states(std::min<std::size_t>(alternatives.size() + prices.size(), 255));
  struct Option {
    std::int64_t dc;
    double dcost;
    std::uint8_t state;
  };
  std::vector<std::vector<Option>> options(fc.count);
  std::vector<double> dp, next;
  std::vector<std::uint8_t> choice;
  std::vector<Index> with_options;
  while (clock.seconds() < seconds && stats.rounds < params.recombination_rounds) {
    ++stats.rounds;
    component_totals(g, gc, fg, fc, y, params, count0, cost0);
    std::int64_t total = 0;
    {
      SelectionState st(g, gc, fg, y);
      total = st.count;
    }
    for (auto& o : options) o.clear();
    // The count term's slope at the incumbent: 0 between its two sides at N' = N (prices go up
    // from there: keeping a group always gains λ_edge Q), ±1 near the band's edges, where one
    // direction is closed (cg57 sits on the upper edge); the prices are offsets from it.
    const double slope = count_slope(total - n, band);
    for (std::size_t k = 0; k < states.size() && clock.seconds() < seconds; ++k) {
      if (k < alternatives.size()) {
        states[k] = alternatives[k];
      } else {
        const double mu = prices[k - alternatives.size()];
        SelectionState st(g, gc, fg, y);
        priced_descent(st, g, gc, slope + (slope < 0.0 ? -mu : mu), params, adj_offsets, adjacent, clock, seconds);
        states[k] = std::move(st.y);
      }
      component_totals(g, gc, fg, fc, states[k], params, count1, cost1);
      for (Index c = 0; c < fc.count; ++c) {
        const std::int64_t dc = count1[c] - count0[c];
        const double dcost = cost1[c] - cost0[c];
        if (dc == 0 && dcost >= -1e-9) continue;  // no better than the incumbent
        auto& opts = options[c];
        auto same = std::find_if(opts.begin(), opts.end(), [&](const Option& o) { return o.dc == dc; });
        if (same == opts.end()) opts.push_back({dc, dcost, static_cast<std::uint8_t>(k)});
        else if (dcost < same->dcost) *same = {dc, dcost, static_cast<std::uint8_t>(k)};
      }
    }
    // The programme (also when the time cut the descents short: every state they reached is a
    // valid alternative, and the programme takes milliseconds): dp[s] = least Σ Δcost over the components so far with N' − N = s + lo; the
    // range covers Eq. 2's band and the incumbent's count (which may lie outside it: then any
    // combination in the band is taken), widened by the largest |ΔN'| the components' options
    // can add up to, so that partial sums outside the band that end inside it are not lost (the
    // programme is then exact); the widening is capped at max(2 × band, 1 024) for memory.
    std::int64_t reach = 0;
    for (const auto& opts : options) {
      std::int64_t most = 0;
      for (const Option& o : opts) most = std::max(most, std::abs(o.dc));
      reach += most;
    }
    reach = std::min(reach, std::max<std::int64_t>(2 * band, 1024));
    const std::int64_t d0 = total - n, lo = std::min(-band, d0) - reach, hi = std::max(band, d0) + reach;
    const std::size_t width = std::size_t(hi - lo + 1);
    dp.assign(width, INFINITY);
    with_options.clear();
    for (Index c = 0; c < fc.count; ++c)
      if (!options[c].empty()) with_options.push_back(c);
    if (with_options.empty()) break;
    dp[std::size_t(d0 - lo)] = 0.0;
    choice.assign(with_options.size() * width, 0);
    for (std::size_t i = 0; i < with_options.size(); ++i) {
      const auto& opts = options[with_options[i]];
      next = dp;  // choice 0: the incumbent
      std::uint8_t* ch = &choice[i * width];
      for (std::size_t s = 0; s < width; ++s) {
        if (!(dp[s] < INFINITY)) continue;
        for (std::size_t k = 0; k < opts.size(); ++k) {
          const std::int64_t t = std::int64_t(s) + opts[k].dc;
          if (t < 0 || t >= std::int64_t(width)) continue;
          const double v = dp[s] + opts[k].dcost;
          if (v < next[std::size_t(t)] - 1e-12) next[std::size_t(t)] = v, ch[t] = static_cast<std::uint8_t>(k + 1);
        }
      }
      dp.swap(next);
    }
    const double before = std::abs(d0) <= band ? double(std::abs(d0)) : INFINITY;
    std::size_t best_s = std::size_t(d0 - lo);
    double best = before;  // every incumbent kept
    for (std::int64_t d = -band; d <= band; ++d) {
      const std::size_t s = std::size_t(d - lo);
      if (dp[s] < INFINITY && dp[s] + double(std::llabs(d)) < best - 1e-9) best = dp[s] + double(std::llabs(d)), best_s = s;
    }
    if (!(best < before - 1e-9) || !(best < INFINITY)) break;
    // Back-track: component i's choice at state s; the previous state is s − its Δcount.
    for (std::size_t i = with_options.size(); i-- > 0;) {
      const std::uint8_t k = choice[i * width + best_s];
      if (k == 0) continue;
      const Index c = with_options[i];
      const Option& o = options[c][k - 1];
      for (Index j = fc.offsets[c]; j < fc.offsets[c + 1]; ++j) y[fc.groups[j]] = states[o.state][fc.groups[j]];
      best_s = std::size_t(std::int64_t(best_s) - o.dc);
      ++stats.moved;
    }
    ++stats.improved;
  }
  return y;
}

}  // namespace select_detail

namespace detail {

using namespace select_detail;

std::vector<std::uint8_t> recombine(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                    std::uint64_t target, const SelectionParams& params,
                                    const std::vector<std::uint8_t>& edge_kept, Index* components,
                                    const std::vector<std::vector<std::uint8_t>>& alternatives) {
  Prepared p = prepare(mesh, conn, analysis, params, edge_kept);
  p.with_adjacency();
  std::vector<std::vector<std::uint8_t>> states;
  for (const std::vector<std::uint8_t>& kept : alternatives) states.push_back(prepare(mesh, conn, analysis, params, kept).y);
  RecombineStats stats;
  const std::vector<std::uint8_t> y = recombine_components(p.groups, p.gc, p.fg, p.y, target, params, INFINITY,
                                                           p.adj_offsets, p.adjacent, stats, states);
  if (components) *components = stats.components;
  return p.edge_bits(conn, y);
}

}  // namespace detail

}  // namespace quadlod
