#include "core/neighbor_grid.hpp"

#include <algorithm>
#include <numeric>

namespace groovetrace {

NeighborGrid::NeighborGrid(const Cloud& cloud, float cell) : inv_cell_(1.0f / cell) {
  require_in_range(cloud);  // cell keys stay far inside their integers
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
      cell_list_.push_back(keyed[k].first);
    }
    cells_[keyed[k].first].second = static_cast<std::uint32_t>(k + 1);
  }
}

void NeighborGrid::gather_cell(std::size_t c, CellBlock& block) const {
  const std::uint64_t k0 = cell_list_[c];
  const auto own = cells_.at(k0);
  block.members.assign(order_.begin() + own.first, order_.begin() + own.second);
  block.near.clear();
  block.x.clear();
  block.y.clear();
  block.z.clear();
  // The key's three 21-bit fields, sign-extended back to cell coordinates.
  auto field = [&](int shift) {
    const std::int64_t v = static_cast<std::int64_t>((k0 >> shift) & ((1u << 21) - 1));
    return v >= (1 << 20) ? v - (1 << 21) : v;
  };
  const std::int64_t cx = field(0), cy = field(21), cz = field(42);
  for (std::int64_t dz = -1; dz <= 1; ++dz)
    for (std::int64_t dy = -1; dy <= 1; ++dy)
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        const auto it = cells_.find(key(cx + dx, cy + dy, cz + dz));
        if (it == cells_.end()) continue;
        const auto [lo, hi] = it->second;
        block.near.insert(block.near.end(), order_.begin() + lo, order_.begin() + hi);
        block.x.insert(block.x.end(), xs_.begin() + lo, xs_.begin() + hi);
        block.y.insert(block.y.end(), ys_.begin() + lo, ys_.begin() + hi);
        block.z.insert(block.z.end(), zs_.begin() + lo, zs_.begin() + hi);
      }
}

}  // namespace groovetrace
