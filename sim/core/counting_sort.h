// The one stable counting sort (bucket offsets plus the items in bucket order) that the
// gather maps use (particle binning sorts runs instead, sim/mpm/sparse_grid.cpp): basis entries by
// control point (sim/shell/kirchhoff_love.cpp), faces by vertex (sim/shell/loop_basis.cpp).
#pragma once
#include <cstddef>
#include <vector>

namespace shellmpm {

/// Sorts the items 0 .. n-1 by key(i) in [0, num_keys), stably: start gets num_keys + 1
/// offsets and order[start[k] .. start[k+1]) the items with key k in ascending order.
/// Index: an integer type that holds n.
template <class Index, class KeyFn>
void counting_sort(std::size_t n, std::size_t num_keys, KeyFn&& key, std::vector<Index>& start,
                   std::vector<Index>& order) {
  start.assign(num_keys + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++start[static_cast<std::size_t>(key(i)) + 1];
  for (std::size_t k = 0; k < num_keys; ++k) start[k + 1] += start[k];
  order.resize(n);
  std::vector<Index> cursor(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    order[static_cast<std::size_t>(cursor[static_cast<std::size_t>(key(i))]++)] =
        static_cast<Index>(i);
}

}  // namespace shellmpm
