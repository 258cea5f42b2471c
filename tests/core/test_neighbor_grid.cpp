// The CPU reference's uniform grid (neighbor_grid.cpp): ball queries and the per-cell batches
// that the robust method's candidate stage walks, against brute force.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "core/neighbor_grid.hpp"

namespace groovetrace {
namespace {

Cloud random_cloud(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.03f, 0.03f);
  Cloud c;
  c.resize(n);
  c.width = static_cast<std::uint32_t>(n);
  for (std::size_t i = 0; i < n; ++i) {
    c.x[i] = u(rng);
    c.y[i] = u(rng);
    c.z[i] = 0.4f + 0.2f * u(rng);
  }
  c.x[7] = NAN;  // invalid points take no part
  return c;
}

TEST(NeighborGrid, BallQueryFindsExactlyThePointsWithinTheRadius) {
  const Cloud c = random_cloud(3000, 1);
  const float r = 0.005f;
  const NeighborGrid grid(c, r);
  for (std::size_t q = 0; q < c.size(); q += 37) {
    if (!c.valid(q)) continue;
    std::vector<std::uint32_t> found;
    grid.for_each_within(c.point(q), r, [&](std::uint32_t j, float) { found.push_back(j); });
    std::sort(found.begin(), found.end());
    std::vector<std::uint32_t> brute;
    for (std::size_t j = 0; j < c.size(); ++j) {
      if (c.valid(j) && (c.point(j) - c.point(q)).squaredNorm() <= r * r) {
        brute.push_back(static_cast<std::uint32_t>(j));
      }
    }
    EXPECT_EQ(found, brute) << "query " << q;
  }
}

TEST(NeighborGrid, CellBlocksHoldEveryMembersBall) {
  const Cloud c = random_cloud(3000, 2);
  const float r = 0.006f;
  const NeighborGrid grid(c, r);
  NeighborGrid::CellBlock block;
  std::size_t members = 0;
  for (std::size_t cell = 0; cell < grid.cell_count(); ++cell) {
    grid.gather_cell(cell, block);
    ASSERT_EQ(block.near.size(), block.x.size());
    members += block.members.size();
    std::vector<std::uint32_t> near = block.near;
    std::sort(near.begin(), near.end());
    for (std::size_t k = 0; k < block.near.size(); ++k) {
      EXPECT_EQ(block.x[k], c.x[block.near[k]]);
    }
    for (std::uint32_t m : block.members) {
      EXPECT_TRUE(std::binary_search(near.begin(), near.end(), m));
      for (std::size_t j = 0; j < c.size(); ++j) {
        if (c.valid(j) && (c.point(j) - c.point(m)).squaredNorm() <= r * r) {
          EXPECT_TRUE(std::binary_search(near.begin(), near.end(), static_cast<std::uint32_t>(j)))
              << "member " << m << " misses " << j;
        }
      }
    }
  }
  EXPECT_EQ(members, c.count_valid());  // every valid point in exactly one cell
}

}  // namespace
}  // namespace groovetrace
