// The local-search moves and the descent of the edge selection (moves.h): chain moves, pair
// exchanges and compound moves (ejection chains) on a SelectionState, and flip_search, which
// takes single flips, swaps, chains, compound moves and pair exchanges while they lower Eq. 9.
#include "select/moves.h"

namespace quadlod::select_detail {

namespace {

bool chain_moves(SelectionState& st, const Groups& g, const GroupConstraints& gc, std::uint64_t target,
                 const SelectionParams& params, const Stopwatch& clock, double seconds, FlipSearchStats& stats) {
  const double n = double(target), band = params.epsilon_n * n;
  const Index applied = chain_walk(
      st, g, gc, params, clock, seconds, [&](std::int64_t c) { return std::abs(double(c) - n); },
      [&](std::int64_t c) { return std::abs(double(c) - n) <= band; });
  stats.chains += applied;
  return applied > 0;
}

// Pair exchanges: keep one collapsed group and collapse one kept group *anywhere* on the mesh,
// as one move. The count term alone blocks most single flips near N (each costs |ΔN'|), and
// adjacent swaps only see neighbours; an exchange pairs, e.g., keeping a group whose collapse
// emptied an Eq. 6 cluster (−λ_geo) with collapsing a cheap group of about the same ΔN' elsewhere.
// Candidates come from a table of the best single moves per ΔN' value (the two flips' deltas add
// up when the groups share no face or cluster); every candidate is re-evaluated exactly before it
// is applied (the second flip's delta is computed after the first), so a move is taken only if it
// lowers Eq. 9 and keeps Eq. 2's band and Eq. 8. Returns whether something was applied.
bool pair_exchanges(SelectionState& st, const Groups& g, std::uint64_t target, const SelectionParams& params,
                    const Stopwatch& clock, double seconds, FlipSearchStats& stats) {
  const double n = double(target), band = params.epsilon_n * n, eps = 1e-9;
  auto count_term = [&](std::int64_t c) { return std::abs(double(c) - n); };
  auto in_band = [&](std::int64_t c) { return std::abs(double(c) - n) <= band; };
  struct Move {
    std::int64_t dc;
    double dr;
    Index grp;
  };
  // Single moves, sorted by ΔN' and then by their other cost; the best `per_bucket` of each ΔN'.
  constexpr std::size_t per_bucket = 3;
  std::vector<Move> collapse, keep;
  for (Index grp = 0; grp < g.count; ++grp) {
    if (g.fixed[grp]) continue;
    if (st.y[grp]) {
      if (!st.may_collapse(grp)) continue;
      const std::int64_t dc = st.delta_count(grp);
      if (dc < 0) collapse.push_back({dc, st.delta_rest(grp, params), grp});
    } else {
      const std::int64_t dc = st.delta_count(grp);
      if (dc > 0) keep.push_back({dc, st.delta_rest(grp, params), grp});
    }
  }
  auto buckets = [&](std::vector<Move>& moves) {
    std::sort(moves.begin(), moves.end(), [](const Move& l, const Move& r) {
      return l.dc != r.dc ? l.dc < r.dc : (l.dr != r.dr ? l.dr < r.dr : l.grp < r.grp);
    });
    std::vector<std::size_t> starts;  // first index of each ΔN' value
    for (std::size_t i = 0; i < moves.size(); ++i)
      if (i == 0 || moves[i].dc != moves[i - 1].dc) starts.push_back(i);
    starts.push_back(moves.size());
    return starts;
  };
  const std::vector<std::size_t> cs = buckets(collapse), ks = buckets(keep);
  struct Candidate {
    double gain;
    Index a, b;  // collapse a, keep b
  };
  std::vector<Candidate> candidates;
  const std::int64_t c0 = st.count;
  for (std::size_t i = 0; i + 1 < cs.size(); ++i) {
    const Move& a = collapse[cs[i]];
    for (std::size_t j = 0; j + 1 < ks.size(); ++j) {
      const Move& b = keep[ks[j]];
      const std::int64_t c = c0 + a.dc + b.dc;
      if (!in_band(c)) continue;
      const double base = count_term(c) - count_term(c0);
      if (base + a.dr + b.dr >= -eps) continue;
      for (std::size_t x = cs[i]; x < std::min(cs[i + 1], cs[i] + per_bucket); ++x)
        for (std::size_t z = ks[j]; z < std::min(ks[j + 1], ks[j] + per_bucket); ++z) {
          const double gain = base + collapse[x].dr + keep[z].dr;
          if (gain < -eps) candidates.push_back({gain, collapse[x].grp, keep[z].grp});
        }
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& l, const Candidate& r) {
    return l.gain != r.gain ? l.gain < r.gain : (l.a != r.a ? l.a < r.a : l.b < r.b);
  });
  std::vector<std::uint8_t> used(g.count, 0);
  bool applied = false;
  for (const Candidate& cand : candidates) {
    if (clock.seconds() >= seconds) break;
    if (used[cand.a] || used[cand.b] || !st.y[cand.a] || st.y[cand.b]) continue;
    const std::int64_t before = st.count;
    const double rb = st.delta_rest(cand.b, params);
    const std::int64_t db = st.delta_count(cand.b);
    st.flip(cand.b, db);
    bool take = st.may_collapse(cand.a);
    std::int64_t da = 0;
    if (take) {
      da = st.delta_count(cand.a);
      take = in_band(st.count + da) &&
             count_term(st.count + da) - count_term(before) + rb + st.delta_rest(cand.a, params) < -eps;
    }
    if (take) {
      st.flip(cand.a, da);
      used[cand.a] = used[cand.b] = 1;
      ++stats.exchanges;
      applied = true;
    } else {
      st.flip(cand.b, -db);  // undo
    }
  }
  return applied;
}

}  // namespace

// Compound moves: see moves.h.
double compound_move(SelectionState& st, Index seed, const Groups& g, const std::vector<Index>& adj_offsets,
                     const std::vector<Index>& adjacent, std::uint64_t target, const SelectionParams& params,
                     CompoundScratch& s, std::vector<std::pair<Index, std::int64_t>>& flipped) {
  const double n = double(target), band = params.epsilon_n * n;
  auto count_term = [&](std::int64_t c) { return std::abs(double(c) - n); };
  auto in_band = [&](std::int64_t c) { return std::abs(double(c) - n) <= band; };
  flipped.clear();
  if (g.fixed[seed] || (st.y[seed] && !st.may_collapse(seed))) return INFINITY;
  const std::int64_t c0 = st.count, dc0 = st.delta_count(seed);
  if (dc0 == 0) return INFINITY;  // nothing to compensate: a single flip
  const double ct0 = count_term(c0);
  double rest = st.delta_rest(seed, params);
  st.flip(seed, dc0);
  flipped.emplace_back(seed, dc0);
  const std::uint8_t v = st.y[seed];  // candidates hold the seed's new value and flip away from it
  const std::int64_t dir = dc0 > 0 ? 1 : -1;
  if (s.stamp.size() != g.count) s.stamp.assign(g.count, 0), s.round = 0;
  if (++s.round == 0) std::fill(s.stamp.begin(), s.stamp.end(), 0), s.round = 1;
  s.queue.assign(1, seed);
  s.stamp[seed] = s.round;
  s.candidates.clear();
  const std::size_t max_candidates = params.compound_candidates, max_visits = 8 * max_candidates;
  for (std::size_t head = 0; head < s.queue.size() && s.candidates.size() < max_candidates; ++head) {
    const Index a = s.queue[head];
    if (a != seed && !g.fixed[a] && st.y[a] == v && (!v || st.may_collapse(a))) {
      const std::int64_t dc = st.delta_count(a);
      if (dc * dir < 0) s.candidates.push_back({st.delta_rest(a, params) / double(std::abs(dc)), a});
    }
    for (Index k = adj_offsets[a]; k < adj_offsets[a + 1] && s.queue.size() < max_visits; ++k)
      if (s.stamp[adjacent[k]] != s.round) {
        s.stamp[adjacent[k]] = s.round;
        s.queue.push_back(adjacent[k]);
      }
  }
  std::sort(s.candidates.begin(), s.candidates.end(), [](const CompoundScratch::Candidate& l,
                                                         const CompoundScratch::Candidate& r) {
    return l.key != r.key ? l.key < r.key : l.grp < r.grp;
  });
  double best = in_band(st.count) ? count_term(st.count) - ct0 + rest : INFINITY;
  std::size_t best_len = in_band(st.count) ? 1 : 0;
  for (const auto& cand : s.candidates) {
    if ((st.count - c0) * dir <= 0) break;  // N' is back
    const Index a = cand.grp;
    if (st.y[a] != v || (v && !st.may_collapse(a))) continue;
    const std::int64_t dc = st.delta_count(a);  // exact now: earlier flips may share its faces
    if (dc * dir >= 0) continue;
    rest += st.delta_rest(a, params);
    st.flip(a, dc);
    flipped.emplace_back(a, dc);
    const double change = count_term(st.count) - ct0 + rest;
    if (in_band(st.count) && change < best) {
      best = change;
      best_len = flipped.size();
    }
  }
  while (flipped.size() > best_len) {
    st.flip(flipped.back().first, -flipped.back().second);
    flipped.pop_back();
  }
  return best_len > 0 ? best : INFINITY;
}

namespace {

// Compound moves in the descent: every free group as a seed, a move kept when it lowers Eq. 9.
bool compound_moves(SelectionState& st, const Groups& g, const std::vector<Index>& adj_offsets,
                    const std::vector<Index>& adjacent, std::uint64_t target, const SelectionParams& params,
                    const Stopwatch& clock, double seconds, FlipSearchStats& stats) {
  CompoundScratch scratch;
  std::vector<std::pair<Index, std::int64_t>> flipped;
  bool applied = false;
  for (Index seed = 0; seed < g.count && clock.seconds() < seconds; ++seed) {
    const double change = compound_move(st, seed, g, adj_offsets, adjacent, target, params, scratch, flipped);
    if (change < -1e-9) {
      ++stats.compounds;
      applied = true;
    } else {
      while (!flipped.empty()) {
        st.flip(flipped.back().first, -flipped.back().second);
        flipped.pop_back();
      }
    }
  }
  return applied;
}

}  // namespace

// The descent (moves.h, FlipSearchStats): passes of single flips, swaps, chains, and where those
// find nothing compound moves and pair exchanges.
std::vector<std::uint8_t> flip_search(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                      std::vector<std::uint8_t> y, std::uint64_t target,
                                      const SelectionParams& params, double seconds,
                                      const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                      FlipSearchStats& stats) {
  Stopwatch clock;
  SelectionState st(g, gc, fg, std::move(y));
  const double n = double(target), band = params.epsilon_n * n, eps = 1e-9;
  auto count_term = [&](std::int64_t c) { return std::abs(double(c) - n); };
  auto in_band = [&](std::int64_t c) { return std::abs(double(c) - n) <= band; };

  bool improved = true;
  while (improved && clock.seconds() < seconds) {
    improved = false;
    ++stats.passes;
    for (Index grp = 0; grp < g.count && clock.seconds() < seconds; ++grp) {
      if (g.fixed[grp] || (st.y[grp] && !st.may_collapse(grp))) continue;
      const std::int64_t dc = st.delta_count(grp);
      if (!in_band(st.count + dc)) continue;
      if (count_term(st.count + dc) - count_term(st.count) + st.delta_rest(grp, params) < -eps) {
        st.flip(grp, dc);
        ++stats.flips;
        improved = true;
      }
    }
    if (const Index swaps = swap_walk(st, g, params, adj_offsets, adjacent, clock, seconds, count_term, in_band, true)) {
      stats.swaps += swaps;
      improved = true;
    }
    if (params.chain_moves && clock.seconds() < seconds)
      improved |= chain_moves(st, g, gc, target, params, clock, seconds, stats);
    if (params.compound_moves && !improved && clock.seconds() < seconds)
      improved = compound_moves(st, g, adj_offsets, adjacent, target, params, clock, seconds, stats);
    if (params.pair_exchanges && !improved && clock.seconds() < seconds)
      improved = pair_exchanges(st, g, target, params, clock, seconds, stats);
  }
  stats.converged = !improved;
  return std::move(st.y);
}

}  // namespace quadlod::select_detail
