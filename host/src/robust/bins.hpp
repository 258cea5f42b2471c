#pragma once
// Points binned on a uniform grid for ball queries of any radius. NeighborGrid visits only the
// 27 cells around a query, so its cell must be as large as the radius; the robust method asks
// for 20-30 mm balls in clouds with 0.3 mm spacing, where small cells cut the points visited
// about tenfold.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <unordered_map>
#include <utility>
#include <vector>

namespace groovetrace {

class BoxBins {
 public:
  /// Bins the valid points of `cloud` in cells of edge `cell` (m).
  BoxBins(const Cloud& cloud, double cell) : inv_cell_(1.0 / cell) {
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
    keyed.reserve(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (!cloud.valid(i)) continue;
      keyed.emplace_back(key(coord(cloud.x[i]), coord(cloud.y[i]), coord(cloud.z[i])),
                         static_cast<std::uint32_t>(i));
    }
    std::sort(keyed.begin(), keyed.end());
    order_.resize(keyed.size());
    for (std::size_t k = 0; k < keyed.size(); ++k) {
      order_[k] = keyed[k].second;
      if (k == 0 || keyed[k].first != keyed[k - 1].first) {
        cells_[keyed[k].first] = {static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(k)};
      }
      cells_[keyed[k].first].second = static_cast<std::uint32_t>(k + 1);
    }
  }

  /// The points within `radius` (m) of q that also lie within `slab` (m) of the plane through
  /// q normal to the unit vector `t`, appended to `out` (cleared first), cell by cell (z, y, x
  /// ascending). A section's slab is a few millimetres thick in a ball of up to a decimetre:
  /// only the cells the plane passes near are visited.
  void within_slab(const Cloud& cloud, const Eigen::Vector3d& q, double radius,
                   const Eigen::Vector3d& t, double slab, std::vector<std::uint32_t>& out) const {
    out.clear();
    const double r2 = radius * radius;
    const double cell = 1.0 / inv_cell_, reach = slab + 0.8661 * cell;  // half a cell diagonal
    const std::int64_t x0 = coord(q.x() - radius), x1 = coord(q.x() + radius);
    const std::int64_t y0 = coord(q.y() - radius), y1 = coord(q.y() + radius);
    const std::int64_t z0 = coord(q.z() - radius), z1 = coord(q.z() + radius);
    for (std::int64_t cz = z0; cz <= z1; ++cz)
      for (std::int64_t cy = y0; cy <= y1; ++cy)
        for (std::int64_t cx = x0; cx <= x1; ++cx) {
          const Eigen::Vector3d centre = (Eigen::Vector3d(cx, cy, cz).array() + 0.5) * cell;
          if (std::abs((centre - q).dot(t)) > reach) continue;
          const auto it = cells_.find(key(cx, cy, cz));
          if (it == cells_.end()) continue;
          for (std::uint32_t k = it->second.first; k < it->second.second; ++k) {
            const std::uint32_t j = order_[k];
            const double dx = cloud.x[j] - q.x(), dy = cloud.y[j] - q.y(), dz = cloud.z[j] - q.z();
            if (dx * dx + dy * dy + dz * dz > r2) continue;
            // 1 nm to spare: the section's own test, summed in another order, decides.
            if (std::abs(dx * t.x() + dy * t.y() + dz * t.z()) <= slab + 1e-9) out.push_back(j);
          }
        }
  }

 private:
  std::int64_t coord(double v) const {
    return static_cast<std::int64_t>(std::floor(v * inv_cell_));
  }
  static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    const std::uint64_t m = (1u << 21) - 1;  // 21 bits per axis: +-5 km at 5 mm cells
    return (static_cast<std::uint64_t>(x) & m) | ((static_cast<std::uint64_t>(y) & m) << 21) |
           ((static_cast<std::uint64_t>(z) & m) << 42);
  }

  double inv_cell_;
  std::vector<std::uint32_t> order_;
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> cells_;
};

}  // namespace groovetrace
