// Greedy selection (greedy.h): groups collapsed cheapest per removed triangle-equivalent first,
// never jumping below Eq. 2's band and never breaking Eq. 8.
#include "select/greedy.h"

#include <cmath>
#include <queue>

namespace quadlod::select_detail {

GreedyResult greedy_select(const Groups& g, const GroupConstraints& gc, const FaceGroups& fg,
                           std::uint64_t target, const SelectionParams& params) {
  SelectionState st(g, gc, fg, std::vector<std::uint8_t>(g.count, 1));
  struct Entry {
    double key;
    Index group;
    std::int64_t delta;
    bool operator<(const Entry& o) const { return key > o.key || (key == o.key && group > o.group); }
  };
  std::priority_queue<Entry> heap;
  // Key: cost per removed triangle-equivalent of collapsing a kept group.
  auto push = [&](Index grp) {
    const std::int64_t d = -st.delta_count(grp);
    if (d > 0) heap.push({st.delta_rest(grp, params) / double(d), grp, d});
  };
  for (Index grp = 0; grp < g.count; ++grp)
    if (!g.fixed[grp]) push(grp);

  const double lowest = (1.0 - params.epsilon_n) * double(target);
  // The candidate that would have jumped below the band but lands closest to the target: taken at
  // the end if the band was never reached and it gets closer than where the greedy stopped.
  Index closest_skipped = kInvalidIndex;
  double closest_distance = INFINITY;
  while (st.count > std::int64_t(target) && !heap.empty()) {
    const Entry top = heap.top();
    heap.pop();
    if (!st.y[top.group]) continue;
    const std::int64_t d = -st.delta_count(top.group);
    if (d <= 0) continue;
    const double key = st.delta_rest(top.group, params) / double(d);
    if (d != top.delta || key != top.key) {  // stale entry: its neighbours changed
      heap.push({key, top.group, d});
      continue;
    }
    if (!st.may_collapse(top.group)) continue;
    // A group that would jump below the band is skipped: smaller ones may still fit.
    if (double(st.count) - double(d) < lowest) {
      const double distance = std::abs(double(st.count) - double(d) - double(target));
      if (distance < closest_distance) {
        closest_distance = distance;
        closest_skipped = top.group;
      }
      continue;
    }
    st.flip(top.group, -d);
    for (Index partner : gc.group_split[top.group])  // their λ_tri cost just dropped
      if (st.y[partner] && !g.fixed[partner]) push(partner);
  }
  if (double(st.count) > (1.0 + params.epsilon_n) * double(target) && closest_skipped != kInvalidIndex &&
      st.y[closest_skipped] && st.may_collapse(closest_skipped)) {
    const std::int64_t d = -st.delta_count(closest_skipped);
    if (d > 0 && std::abs(double(st.count) - double(d) - double(target)) <
                     std::abs(double(st.count) - double(target)))
      st.flip(closest_skipped, -d);
  }
  return {std::move(st.y), static_cast<std::uint64_t>(st.count)};
}

}  // namespace quadlod::select_detail
