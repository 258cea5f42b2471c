// Stage 3 of the robust method, first half: scattered seam nodes into ordered paths.
//
// One PCA axis cannot order an S-curve, an L or a ring. The nodes are joined into a graph
// (near, and linked along the seam rather than across it), and each part's minimum spanning
// tree is walked along its longest path. curve.cpp smooths the paths.

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/neighbor_grid.hpp"
#include "robust/stages.hpp"

namespace groovetrace {
namespace {

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

struct Edge {
  double w;
  int a, b;
  bool operator<(const Edge& o) const {
    return w < o.w || (w == o.w && (a < o.a || (a == o.a && b < o.b)));
  }
};

// Farthest node from `start` in a tree (adjacency lists with weights), with parents.
int farthest(const std::vector<std::vector<std::pair<int, double>>>& adj, int start,
             std::vector<int>& parent) {
  std::vector<double> dist(adj.size(), -1);
  parent.assign(adj.size(), -1);
  std::vector<int> stack = {start};
  dist[start] = 0;
  int best = start;
  while (!stack.empty()) {
    const int u = stack.back();
    stack.pop_back();
    if (dist[u] > dist[best]) best = u;
    for (const auto& [v, w] : adj[u]) {
      if (dist[v] >= 0) continue;
      dist[v] = dist[u] + w;
      parent[v] = u;
      stack.push_back(v);
    }
  }
  return best;
}

}  // namespace

std::vector<NodePath> order_nodes(const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<Eigen::Vector3d>& tangents, double link,
                                  std::size_t min_nodes) {
  std::vector<NodePath> paths;
  const int n = static_cast<int>(points.size());
  if (n == 0) return paths;
  Cloud c;
  c.resize(points.size());
  c.width = static_cast<std::uint32_t>(n);
  for (int i = 0; i < n; ++i) {
    c.x[i] = static_cast<float>(points[i].x());
    c.y[i] = static_cast<float>(points[i].y());
    c.z[i] = static_cast<float>(points[i].z());
  }
  // Links run along the seam: across-links would weld parallel seams together. cos 60 deg
  // still lets a corner's two legs join across the corner's gap (45 deg).
  const double along = 0.5;
  std::vector<Edge> edges;
  {
    const NeighborGrid grid(c, static_cast<float>(link));
    for (int i = 0; i < n; ++i) {
      grid.for_each_within(c.point(i), static_cast<float>(link), [&](std::uint32_t j, float) {
        if (static_cast<int>(j) <= i) return;
        const Eigen::Vector3d d = points[j] - points[i];
        const double len = d.norm();
        if (len <= 0) {
          edges.push_back({0.0, i, static_cast<int>(j)});
          return;
        }
        const Eigen::Vector3d u = d / len;
        if (std::abs(u.dot(tangents[i])) < along && std::abs(u.dot(tangents[j])) < along) return;
        edges.push_back({len, i, static_cast<int>(j)});
      });
    }
  }
  std::sort(edges.begin(), edges.end());

  std::vector<std::uint8_t> removed(points.size(), 0);
  // Each round takes the longest path of every remaining part; what lies beside a path (its
  // spurs) is removed with it, what branches off further is searched again in the next round.
  for (int round = 0; round < 8; ++round) {
    std::vector<int> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    std::vector<std::vector<std::pair<int, double>>> adj(n);
    for (const Edge& e : edges) {
      if (removed[e.a] || removed[e.b]) continue;
      const int ra = find_root(parent, e.a), rb = find_root(parent, e.b);
      if (ra == rb) continue;
      parent[ra] = rb;
      adj[e.a].emplace_back(e.b, e.w);
      adj[e.b].emplace_back(e.a, e.w);
    }
    std::vector<std::vector<int>> parts(n);
    for (int i = 0; i < n; ++i) {
      if (!removed[i]) parts[find_root(parent, i)].push_back(i);
    }
    bool found = false;
    for (const auto& part : parts) {
      if (part.size() < min_nodes) continue;
      std::vector<int> par;
      const int a = farthest(adj, part.front(), par);
      const int b = farthest(adj, a, par);
      NodePath path;
      for (int v = b; v != -1; v = par[v]) path.nodes.push_back(v);
      if (path.nodes.size() < min_nodes) continue;
      found = true;
      double length = 0;
      for (std::size_t k = 1; k < path.nodes.size(); ++k) {
        length += (points[path.nodes[k]] - points[path.nodes[k - 1]]).norm();
      }
      const Eigen::Vector3d gap = points[path.nodes.back()] - points[path.nodes.front()];
      path.closed = gap.norm() <= link && length > 6 * link;
      // Spurs: nodes of this part within half a link of the path go with it.
      std::vector<Eigen::Vector3d> on_path;
      for (int v : path.nodes) on_path.push_back(points[v]);
      for (int v : part) {
        for (const auto& q : on_path) {
          if ((points[v] - q).norm() <= 0.5 * link) {
            removed[v] = 1;
            break;
          }
        }
      }
      for (int v : path.nodes) removed[v] = 1;
      paths.push_back(std::move(path));
    }
    if (!found) break;
  }
  return paths;
}

}  // namespace groovetrace
