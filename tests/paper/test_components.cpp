// Connected components of the masked points (detect.hpp) against a breadth-first search over
// all pairs, on clouds large enough for the parallel union-find to interleave its threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <groovetrace/paper.hpp>
#include <queue>
#include <random>

namespace groovetrace {
namespace {

// Labels by brute force: components of the graph "masked, within d", largest first, ties by
// their smallest index.
std::vector<int> brute_force_labels(const Cloud& c, const std::vector<std::uint8_t>& mask,
                                    float d) {
  const std::size_t n = c.size();
  std::vector<int> comp(n, -1);
  std::vector<std::vector<std::size_t>> members;
  for (std::size_t s = 0; s < n; ++s) {
    if (!mask[s] || comp[s] >= 0 || !c.valid(s)) continue;
    const int id = static_cast<int>(members.size());
    members.emplace_back();
    std::queue<std::size_t> todo;
    todo.push(s);
    comp[s] = id;
    while (!todo.empty()) {
      const std::size_t i = todo.front();
      todo.pop();
      members[id].push_back(i);
      for (std::size_t j = 0; j < n; ++j) {
        if (!mask[j] || comp[j] >= 0 || !c.valid(j)) continue;
        if ((c.point(i) - c.point(j)).squaredNorm() <= d * d) {
          comp[j] = id;
          todo.push(j);
        }
      }
    }
  }
  std::vector<int> order(members.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return members[a].size() > members[b].size(); });
  std::vector<int> rank(members.size());
  for (std::size_t k = 0; k < order.size(); ++k) rank[order[k]] = static_cast<int>(k);
  std::vector<int> labels(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (comp[i] >= 0) labels[i] = rank[comp[i]];
  }
  return labels;
}

TEST(ConnectedComponents, MatchBreadthFirstSearch) {
  for (unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 0.25f);
    Cloud c;
    c.resize(6000);
    c.width = 6000;
    std::vector<std::uint8_t> mask(c.size());
    for (std::size_t i = 0; i < c.size(); ++i) {
      c.x[i] = u(rng);
      c.y[i] = u(rng);
      c.z[i] = 0.4f + 0.01f * u(rng);
      mask[i] = (i % 7) != 0;
    }
    c.x[5] = NAN;  // invalid, though masked
    const float d = 0.003f;
    const Components got = connected_components(c, mask, d);
    const std::vector<int> want = brute_force_labels(c, mask, d);
    ASSERT_EQ(got.label.size(), c.size());
    std::size_t components = 0;
    for (int l : want) components = std::max<std::size_t>(components, l + 1);
    ASSERT_GT(components, 50u) << "the cloud splits into many components";
    ASSERT_EQ(got.sizes.size(), components) << "seed " << seed;
    for (std::size_t k = 1; k < got.sizes.size(); ++k) EXPECT_GE(got.sizes[k - 1], got.sizes[k]);
    for (std::size_t i = 0; i < c.size(); ++i) {
      ASSERT_EQ(got.label[i], want[i]) << "seed " << seed << ", point " << i;
    }
  }
}

}  // namespace
}  // namespace groovetrace
