// The greedy selection (paper §3.2 in group space: N' of Eq. 1 down to the target, Eq. 2's band,
// Eq. 8), for both formulations: the start of every search in src/select/ and of the MIP solves
// of src/ilp/.
#pragma once

#include "select/groups.h"

#include <cstdint>
#include <vector>

namespace quadlod::select_detail {

// Greedy selection: collapse groups in order of cost per removed triangle-equivalent until the
// count reaches the target, never leaving the Eq. 2 band below and never breaking Eq. 8.
struct GreedyResult {
  std::vector<std::uint8_t> y;  // per group
  std::uint64_t count = 0;
};

GreedyResult greedy_select(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                           std::uint64_t target, const SelectionParams& params);

}  // namespace quadlod::select_detail
