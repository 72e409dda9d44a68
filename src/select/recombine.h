// Recombination of independent parts of the edge selection (beyond the paper; docs/formulation.md,
// "Speed"): priced descents and other annealing runs offer every independent component
// alternatives, and a dynamic programme over N' − N picks the combination with the lowest Eq. 9
// in Eq. 2's band.
#pragma once

#include "select/groups.h"

#include <cstdint>
#include <vector>

namespace quadlod::select_detail {

// ------------------------------------------------------------------------------------------
// Recombination of independent parts (beyond the paper; docs/formulation.md, "Speed"). The free
// groups fall into components that share no term of Eq. 9 and no constraint: two free groups are
// in one component if they share a face (t_f), an Eq. 6 cluster, an Eq. 7 cluster or an Eq. 8
// pair of clusters (split pairs share a face). Only the count row |N' − N| (Eqs. 1–2) couples the
// components, so Eq. 9 = |Σ_c N'_c + N'_fixed − N| + Σ_c cost_c(y_c). A price μ per
// triangle-equivalent in place of the count term makes the problem separable (a Lagrangian
// relaxation of Eq. 1): a descent on cost + μ N' from the incumbent improves every component on
// its own. Each price's end state offers every component an alternative (ΔN'_c, Δcost_c); a
// multiple-choice knapsack over the count offset (a dynamic programme over N' − N within Eq. 2's
// band) then picks one alternative per component (or its incumbent) minimising Eq. 9 exactly.
// A component collapsing a chord at a loss of less than a triangle-equivalent per removed one
// can so be paired with a component keeping a chord elsewhere for more than that — a pair the
// count term's price of 1 in both directions hides from every single move and from regions that
// do not hold both parts. c172p (an aircraft of many separate parts) has 968 components, the
// largest of 554 of its 22 131 free groups.

struct RecombineStats {
  Index rounds = 0, improved = 0, components = 0, moved = 0;
  Index largest = 0;  // free groups of the largest component
};

// Rounds of: one priced descent per price from the incumbent, then the dynamic programme over
// the components' alternatives; a round that does not lower Eq. 9 ends the search. y must lie in
// Eq. 2's band; the result does too.
std::vector<std::uint8_t> recombine_components(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                                               std::vector<std::uint8_t> y, std::uint64_t target,
                                               const SelectionParams& params, double seconds,
                                               const std::vector<Index>& adj_offsets,
                                               const std::vector<Index>& adjacent, RecombineStats& stats,
                                               const std::vector<std::vector<std::uint8_t>>& alternatives = {});

}  // namespace quadlod::select_detail
