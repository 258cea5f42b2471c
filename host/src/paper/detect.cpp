#include <algorithm>
#include <atomic>
#include <cmath>
#include <groovetrace/paper.hpp>
#include <numeric>

#include "core/neighbor_grid.hpp"

namespace groovetrace {

double otsu_threshold(const std::vector<float>& descriptor) {
  std::vector<double> logs;
  logs.reserve(descriptor.size());
  for (float d : descriptor) {
    if (std::isfinite(d) && d > 0) logs.push_back(std::log(static_cast<double>(d)));
  }
  if (logs.size() < 2) return NAN;
  const auto [lo_it, hi_it] = std::minmax_element(logs.begin(), logs.end());
  const double lo = *lo_it, hi = *hi_it;
  if (!(hi > lo)) return NAN;
  constexpr int kBins = 512;
  std::vector<double> hist(kBins, 0.0);
  const double scale = kBins / (hi - lo);
  for (double v : logs) hist[std::min(kBins - 1, static_cast<int>((v - lo) * scale))] += 1;
  // Maximise the between-class variance w0 w1 (m0 - m1)^2 over the split bin.
  const double total = static_cast<double>(logs.size());
  double sum_all = 0;
  for (int b = 0; b < kBins; ++b) sum_all += hist[b] * b;
  double w0 = 0, sum0 = 0, best = -1;
  int best_bin = 0;
  for (int b = 0; b < kBins - 1; ++b) {
    w0 += hist[b];
    sum0 += hist[b] * b;
    const double w1 = total - w0;
    if (w0 == 0 || w1 == 0) continue;
    const double m0 = sum0 / w0, m1 = (sum_all - sum0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) {
      best = between;
      best_bin = b;
    }
  }
  return std::exp(lo + (best_bin + 1) / scale);
}

namespace {
int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// The root of i in a forest that other threads link concurrently (path halving; a stale read
// only costs a step).
int find_root(std::vector<std::atomic<int>>& parent, int i) {
  for (;;) {
    const int p = parent[i].load(std::memory_order_relaxed);
    if (p == i) return i;
    const int g = parent[p].load(std::memory_order_relaxed);
    int expected = p;
    if (g != p) parent[i].compare_exchange_weak(expected, g, std::memory_order_relaxed);
    i = g;
  }
}

// Joins the sets of a and b; the root with the larger index is linked under the smaller, by a
// compare-and-swap that fails (and retries) when another thread linked it first. Each set's
// root is therefore its smallest index, whatever the order of the unions.
void unite(std::vector<std::atomic<int>>& parent, int a, int b) {
  for (;;) {
    a = find_root(parent, a);
    b = find_root(parent, b);
    if (a == b) return;
    if (a < b) std::swap(a, b);
    int expected = a;
    if (parent[a].compare_exchange_strong(expected, b, std::memory_order_relaxed)) return;
  }
}

}  // namespace

Components connected_components(const Cloud& cloud, const std::vector<std::uint8_t>& mask,
                                float link_distance) {
  const std::size_t n = cloud.size();
  Cloud masked = cloud;  // only masked points take part in the search
  for (std::size_t i = 0; i < n; ++i) {
    if (!mask[i]) masked.x[i] = NAN;
  }
  const NeighborGrid grid(masked, link_distance);
  std::vector<std::atomic<int>> linked(n);
  for (std::size_t i = 0; i < n; ++i)
    linked[i].store(static_cast<int>(i), std::memory_order_relaxed);
  const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(dynamic, 4096)
  for (std::int64_t i = 0; i < count; ++i) {
    if (!masked.valid(i)) continue;
    grid.for_each_within(masked.point(i), link_distance, [&](std::uint32_t j, float) {
      if (j < i) unite(linked, static_cast<int>(i), static_cast<int>(j));
    });
  }
  std::vector<int> parent(n);
  for (std::size_t i = 0; i < n; ++i) parent[i] = linked[i].load(std::memory_order_relaxed);
  std::vector<std::size_t> root_size(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (masked.valid(i)) ++root_size[find_root(parent, static_cast<int>(i))];
  }
  std::vector<int> roots;
  for (std::size_t i = 0; i < n; ++i) {
    if (root_size[i] > 0) roots.push_back(static_cast<int>(i));
  }
  std::stable_sort(roots.begin(), roots.end(),
                   [&](int a, int b) { return root_size[a] > root_size[b]; });
  std::vector<int> root_label(n, -1);
  Components out;
  for (std::size_t k = 0; k < roots.size(); ++k) {
    root_label[roots[k]] = static_cast<int>(k);
    out.sizes.push_back(root_size[roots[k]]);
  }
  out.label.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    if (masked.valid(i)) out.label[i] = root_label[find_root(parent, static_cast<int>(i))];
  }
  return out;
}

Detection detect_groove(const Cloud& cloud, const std::vector<float>& descriptor, double threshold,
                        int min_component, float link_distance) {
  Detection det;
  det.threshold = std::isnan(threshold) ? otsu_threshold(descriptor) : threshold;
  const std::size_t n = cloud.size();
  std::vector<std::uint8_t> above(n, 0);
  if (std::isfinite(det.threshold)) {
    for (std::size_t i = 0; i < n; ++i) {
      above[i] = (cloud.valid(i) && descriptor[i] > det.threshold) ? 1 : 0;
      det.above_threshold += above[i];
    }
  }
  const Components parts = connected_components(cloud, above, link_distance);
  det.groove.assign(n, 0);
  det.component_label.assign(n, -1);
  for (std::size_t k = 0; k < parts.sizes.size(); ++k) {
    if (parts.sizes[k] < static_cast<std::size_t>(std::max(1, min_component))) break;
    det.component_sizes.push_back(parts.sizes[k]);
  }
  det.components = det.component_sizes.size();
  for (std::size_t i = 0; i < n; ++i) {
    const int l = parts.label[i];
    if (l >= 0 && static_cast<std::size_t>(l) < det.components) {
      det.groove[i] = 1;
      det.component_label[i] = l;
    }
  }
  return det;
}

}  // namespace groovetrace
