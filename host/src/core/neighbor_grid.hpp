#pragma once
// Fixed-radius neighbour search on a uniform grid of cell size r: each query visits the 27
// cells around its own. Cells are found through a hash of the occupied ones, so a cloud
// spread over metres costs no more memory than a compact one. No neighbour lists are stored.

#include <cmath>
#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <unordered_map>
#include <vector>

namespace groovetrace {

class NeighborGrid {
 public:
  /// Indexes the valid points of `cloud` with cells of edge `cell` (m).
  NeighborGrid(const Cloud& cloud, float cell);

  /// Calls fn(j, squared_distance) for every valid point j within `radius` (<= cell) of
  /// `q`, the query point itself included when it is in the cloud.
  template <typename Fn>
  void for_each_within(const Eigen::Vector3f& q, float radius, Fn&& fn) const {
    const float r2 = radius * radius;
    const std::int64_t cx = coord(q.x()), cy = coord(q.y()), cz = coord(q.z());
    for (std::int64_t dz = -1; dz <= 1; ++dz)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          auto it = cells_.find(key(cx + dx, cy + dy, cz + dz));
          if (it == cells_.end()) continue;
          for (std::uint32_t k = it->second.first; k < it->second.second; ++k) {
            const std::uint32_t j = order_[k];
            const float ex = xs_[k] - q.x(), ey = ys_[k] - q.y(), ez = zs_[k] - q.z();
            const float d2 = ex * ex + ey * ey + ez * ez;
            if (d2 <= r2) fn(j, d2);
          }
        }
  }

  /// Occupied cells, for batched queries (see gather_cell).
  std::size_t cell_count() const { return cell_list_.size(); }

  /// The points of one cell and the candidates of all their balls, gathered once per cell:
  /// a batch of queries costs 27 cell lookups, not 27 per query.
  struct CellBlock {
    std::vector<std::uint32_t> members;  ///< the cell's points (cloud indices)
    std::vector<std::uint32_t> near;     ///< the points of the 27 cells around it
    std::vector<float> x, y, z;          ///< their coordinates (m), in `near`'s order
  };
  /// Fills `block` for cell `c` (0 <= c < cell_count()); reuses its storage.
  void gather_cell(std::size_t c, CellBlock& block) const;

 private:
  std::int64_t coord(float v) const { return static_cast<std::int64_t>(std::floor(v * inv_cell_)); }
  static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    // 21 bits per axis: +-1M cells, i.e. +-3 km at 3 mm cells.
    const std::uint64_t m = (1u << 21) - 1;
    return (static_cast<std::uint64_t>(x) & m) | ((static_cast<std::uint64_t>(y) & m) << 21) |
           ((static_cast<std::uint64_t>(z) & m) << 42);
  }

  float inv_cell_;
  std::vector<std::uint32_t> order_;  // point indices sorted by cell
  std::vector<float> xs_, ys_, zs_;   // coordinates in that order, for cache-friendly scans
  std::unordered_map<std::uint64_t, std::pair<std::uint32_t, std::uint32_t>> cells_;
  std::vector<std::uint64_t> cell_list_;  // occupied cells' keys, in sorted order
};

}  // namespace groovetrace
