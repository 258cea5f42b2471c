#include "neighbor_grid.hpp"

#include <algorithm>
#include <numeric>

namespace groovetrace {

NeighborGrid::NeighborGrid(const Cloud& cloud, float cell) : inv_cell_(1.0f / cell) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  keyed.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    keyed.emplace_back(key(coord(cloud.x[i]), coord(cloud.y[i]), coord(cloud.z[i])),
                       static_cast<std::uint32_t>(i));
  }
  std::sort(keyed.begin(), keyed.end());
  const std::size_t n = keyed.size();
  order_.resize(n);
  xs_.resize(n);
  ys_.resize(n);
  zs_.resize(n);
  cells_.reserve(n / 4 + 1);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = keyed[k].second;
    order_[k] = i;
    xs_[k] = cloud.x[i];
    ys_[k] = cloud.y[i];
    zs_[k] = cloud.z[i];
    if (k == 0 || keyed[k].first != keyed[k - 1].first) {
      cells_[keyed[k].first] = {static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(k)};
    }
    cells_[keyed[k].first].second = static_cast<std::uint32_t>(k + 1);
  }
}

}  // namespace groovetrace
