// The moves of the local search of the edge selection (beyond the paper; docs/formulation.md,
// "Speed"), all on a SelectionState (groups.h) by exact incremental deltas of Eq. 9 under
// Eq. 2's band and Eq. 8: the walks of chain and swap moves under any count term (the descent's
// |N' − N| and the priced μ N' of recombine.cpp), compound moves (ejection chains; also taken by
// the annealing, anneal.cpp), and flip_search, the descent that polishes every start.
#pragma once

#include "select/groups.h"
#include "util/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace quadlod::select_detail {

// Local search over single-group flips (beyond the paper; docs/formulation.md, "Speed"): from a
// feasible selection, repeatedly flip one group (collapse a kept one, or keep a collapsed one)
// whenever that lowers Eq. 9 and keeps Eq. 2's band and Eq. 8, by exact incremental deltas, until
// a full pass finds nothing or time runs out. Then pairs of adjacent groups are swapped (one
// collapsed, one kept), which keeps the count roughly where it is, so that moves the count term
// alone would block are found too. Milliseconds per pass on the largest corpus meshes.
struct FlipSearchStats {
  Index passes = 0;
  Index flips = 0;
  Index swaps = 0;
  Index exchanges = 0;
  Index chains = 0;
  Index compounds = 0;
  bool converged = false;
};

std::vector<std::uint8_t> flip_search(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                      std::vector<std::uint8_t> y, std::uint64_t target,
                                      const SelectionParams& params, double seconds,
                                      const std::vector<Index>& adj_offsets, const std::vector<Index>& adjacent,
                                      FlipSearchStats& stats);

// Chain moves: flip a run of groups linked by λ_tri split pairs (consecutive segments of one
// poly-chord, cut by breakpoints §3.2.2) as one move. Flipping one segment of a chord whose
// neighbours stay splits two quad side pairs (+2 λ_tri), so single flips cannot walk a chord
// segment by segment even where collapsing the whole run pays. From each seed the run grows
// breadth-first over split partners that have the seed's value, flipping each (exact incremental
// deltas; a collapse only where Eq. 8 allows it), up to `max_chain` groups; the prefix with the
// best Eq. 9 change that lies in Eq. 2's band is kept if it lowers Eq. 9, the rest is undone.
//
//     seg 1     seg 2     seg 3          collapsing seg 2 alone splits the quads at both
//   ┌──┬──┐  ┌──┬──┐  ┌──┬──┐          breakpoints (2 λ_tri); seg 1–3 together split none
//   └──┴──┘  └──┴──┘  └──┴──┘
//
// chain_walk is that walk under any count term: `count_term(N')` replaces |N' − N| and only
// prefixes with `in_band(N')` count (the priced descent of the recombination passes μ N' and
// no band). Returns the number of chains applied.
template <class CountTerm, class InBand>
Index chain_walk(SelectionState& st, const Groups& g, const GroupConstraints& gc, const SelectionParams& params,
                 const Stopwatch& clock, double seconds, CountTerm&& count_term, InBand&& in_band) {
  constexpr std::size_t max_chain = 64;
  constexpr double eps = 1e-9;
  std::vector<Index> stamp(g.count, kInvalidIndex), queue;
  std::vector<std::pair<Index, std::int64_t>> flipped;  // group, Δcount when flipped
  Index applied = 0;
  for (Index seed = 0; seed < g.count && clock.seconds() < seconds; ++seed) {
    if (g.fixed[seed]) continue;
    const std::uint8_t v = st.y[seed];
    // Only seeds with a partner of the same value: otherwise this is a single flip.
    if (std::none_of(gc.group_split[seed].begin(), gc.group_split[seed].end(),
                     [&](Index b) { return !g.fixed[b] && st.y[b] == v; }))
      continue;
    const std::int64_t c0 = st.count;
    const double ct0 = count_term(c0);
    double rest = 0.0, best_gain = -eps;
    std::size_t best_len = 0;
    flipped.clear();
    queue.assign(1, seed);
    stamp[seed] = seed;
    for (std::size_t head = 0; head < queue.size() && flipped.size() < max_chain; ++head) {
      const Index a = queue[head];
      if (st.y[a] != v || (v && !st.may_collapse(a))) continue;
      const std::int64_t dc = st.delta_count(a);
      rest += st.delta_rest(a, params);
      st.flip(a, dc);
      flipped.emplace_back(a, dc);
      const double gain = count_term(st.count) - ct0 + rest;
      if (in_band(st.count) && gain < best_gain) {
        best_gain = gain;
        best_len = flipped.size();
      }
      for (Index b : gc.group_split[a])
        if (!g.fixed[b] && stamp[b] != seed && st.y[b] == v) {
          stamp[b] = seed;
          queue.push_back(b);
        }
    }
    while (flipped.size() > best_len) {  // undo beyond the best prefix, last flip first
      st.flip(flipped.back().first, -flipped.back().second);
      flipped.pop_back();
    }
    applied += best_len > 0;
  }
  return applied;
}

// Swaps: keep a collapsed group b and collapse a kept neighbour a (one that shares a face), as
// one move; per b the best a is taken if the pair lowers Eq. 9 and the new count is
// `in_band`. As in chain_walk, `count_term(N')` stands for |N' − N| (the priced descent passes
// μ N' and no band). With `keep_must_pay` a b whose own change without the count term does
// not lower Eq. 9 is skipped: keeping it must pay for something besides the count. Returns the
// number of swaps applied.
template <class CountTerm, class InBand>
Index swap_walk(SelectionState& st, const Groups& g, const SelectionParams& params, const std::vector<Index>& adj_offsets,
                const std::vector<Index>& adjacent, const Stopwatch& clock, double seconds, CountTerm&& count_term,
                InBand&& in_band, bool keep_must_pay) {
  constexpr double eps = 1e-9;
  Index applied = 0;
  for (Index b = 0; b < g.count && clock.seconds() < seconds; ++b) {
    if (g.fixed[b] || st.y[b]) continue;
    const double rb = st.delta_rest(b, params);
    if (keep_must_pay && rb >= 0.0) continue;
    const std::int64_t before = st.count;
    const std::int64_t db = st.delta_count(b);
    st.flip(b, db);
    Index best_a = kInvalidIndex;
    std::int64_t best_da = 0;
    double best_gain = -eps;
    for (Index k = adj_offsets[b]; k < adj_offsets[b + 1]; ++k) {
      const Index a = adjacent[k];
      if (g.fixed[a] || !st.y[a] || !st.may_collapse(a)) continue;
      const std::int64_t da = st.delta_count(a);
      if (!in_band(st.count + da)) continue;
      const double gain = count_term(st.count + da) - count_term(before) + rb + st.delta_rest(a, params);
      if (gain < best_gain) {
        best_gain = gain;
        best_a = a;
        best_da = da;
      }
    }
    if (best_a != kInvalidIndex) {
      st.flip(best_a, best_da);
      ++applied;
    } else {
      st.flip(b, -db);  // undo
    }
  }
  return applied;
}

// Compound moves (an ejection chain; beyond the paper, docs/formulation.md, "Speed"): flip a seed
// group, then flip nearby groups the other way — cheapest Eq. 9 change per triangle-equivalent
// first — until N' is back across its value before the move. The typical one re-opens an emptied
// Eq. 6 cluster: keeping one of its groups saves λ_geo but adds its faces to N' (|ΔN'| of a long
// chord is tens of triangle-equivalents, far more than λ_geo, so the single flip and the pair
// exchanges rarely pay), and several small groups around it, collapsed, remove those faces again
// without emptying another cluster. The reverse (collapse a large group, keep small ones around
// it) comes with the same code. Candidates: groups that now hold the seed's new value (so they flip
// the other way), met by a breadth-first walk over groups that share a face, up to
// `compound_candidates`. The prefix of the chain with the
// best Eq. 9 change inside Eq. 2's band is kept (its flips are in `flipped`); the rest is undone.
// Returns that change, or +∞ with the state unchanged when no prefix lies in the band.
//
//        keep ║            ║ = the seed's chord, kept again: its cluster keeps an edge (−λ_geo),
//    ─────────╫──────      N' rises by its faces;
//     ┆   ┆   ║   ┆   ┆    ┆ = small chords around it, collapsed: N' falls back
struct CompoundScratch {
  std::vector<Index> queue;
  std::vector<std::uint32_t> stamp;
  std::uint32_t round = 0;
  struct Candidate {
    double key;
    Index grp;
  };
  std::vector<Candidate> candidates;
};

double compound_move(SelectionState& st, Index seed, const Groups& g, const std::vector<Index>& adj_offsets,
                     const std::vector<Index>& adjacent, std::uint64_t target, const SelectionParams& params,
                     CompoundScratch& s, std::vector<std::pair<Index, std::int64_t>>& flipped);

}  // namespace quadlod::select_detail
