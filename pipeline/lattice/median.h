// The median of a few values (edge positions, gap widths, tile sizes); 0 for none.
#pragma once

#include <algorithm>
#include <vector>

namespace px::lattice {

inline double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  auto mid = v.begin() + v.size() / 2;
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace px::lattice
