// Stage 3 of the robust method, first half: scattered seam nodes into ordered paths.
//
// One PCA axis cannot order an S-curve, an L or a ring. The nodes are joined into a graph
// (near, and linked along the seam rather than across it), and each part's minimum spanning
// tree is walked along its longest path. curve.cpp smooths the paths.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

#include "core/neighbor_grid.hpp"
#include "robust/stages.hpp"

namespace groovetrace {
namespace {

// The root of i's set in a union-find forest, compressing the path on the way.
int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// A link between nodes a < b of length w (m); ordered by length, ties by the nodes.
struct Edge {
  double w;
  int a, b;
  bool operator<(const Edge& o) const {
    return w < o.w || (w == o.w && (a < o.a || (a == o.a && b < o.b)));
  }
};

// Per node: its tree neighbours and the links' lengths (m).
using Adjacency = std::vector<std::vector<std::pair<int, double>>>;

// Farthest node from `start` in a tree, with parents.
int farthest(const Adjacency& adj, int start, std::vector<int>& parent) {
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

// The links between nodes within `link` (m) of each other that run along the seam, sorted:
// across-links would weld parallel seams together. cos 60 deg still lets a corner's two legs
// join across the corner's gap (45 deg).
std::vector<Edge> along_links(const std::vector<Eigen::Vector3d>& points,
                              const std::vector<Eigen::Vector3d>& tangents, double link) {
  const int n = static_cast<int>(points.size());
  Cloud c;
  c.resize(points.size());
  c.width = static_cast<std::uint32_t>(n);
  for (int i = 0; i < n; ++i) {
    c.x[i] = static_cast<float>(points[i].x());
    c.y[i] = static_cast<float>(points[i].y());
    c.z[i] = static_cast<float>(points[i].z());
  }
  const double along = 0.5;
  std::vector<Edge> edges;
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
  std::sort(edges.begin(), edges.end());
  return edges;
}

// The minimum spanning forest of the nodes not `removed`, by Kruskal over the sorted `edges`;
// `parent` is left as the union-find forest of its trees.
Adjacency spanning_forest(const std::vector<Edge>& edges, const std::vector<std::uint8_t>& removed,
                          std::vector<int>& parent) {
  parent.resize(removed.size());
  std::iota(parent.begin(), parent.end(), 0);
  Adjacency adj(removed.size());
  for (const Edge& e : edges) {
    if (removed[e.a] || removed[e.b]) continue;
    const int ra = find_root(parent, e.a), rb = find_root(parent, e.b);
    if (ra == rb) continue;
    parent[ra] = rb;
    adj[e.a].emplace_back(e.b, e.w);
    adj[e.b].emplace_back(e.a, e.w);
  }
  return adj;
}

// The longest path (the diameter) of the tree holding `start`: from the node farthest from
// `start` to the node farthest from that.
std::vector<int> longest_path(const Adjacency& adj, int start) {
  std::vector<int> parent;
  const int a = farthest(adj, start, parent);
  const int b = farthest(adj, a, parent);
  std::vector<int> path;
  for (int v = b; v != -1; v = parent[v]) path.push_back(v);
  return path;
}

// A path is a ring when its ends are within `link` (m) of each other and it is long against it.
bool is_ring(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& path,
             double link) {
  double length = 0;
  for (std::size_t k = 1; k < path.size(); ++k) {
    length += (points[path[k]] - points[path[k - 1]]).norm();
  }
  const Eigen::Vector3d gap = points[path.back()] - points[path.front()];
  return gap.norm() <= link && length > 6 * link;
}

// Removes the path's nodes and its spurs: the nodes of its `part` within half a link of it.
void remove_with_spurs(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& part,
                       const std::vector<int>& path, double link,
                       std::vector<std::uint8_t>& removed) {
  std::vector<Eigen::Vector3d> on_path;
  for (int v : path) on_path.push_back(points[v]);
  for (int v : part) {
    for (const auto& q : on_path) {
      if ((points[v] - q).norm() <= 0.5 * link) {
        removed[v] = 1;
        break;
      }
    }
  }
  for (int v : path) removed[v] = 1;
}

}  // namespace

std::vector<NodePath> order_nodes(const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<Eigen::Vector3d>& tangents, double link,
                                  std::size_t min_nodes) {
  std::vector<NodePath> paths;
  const int n = static_cast<int>(points.size());
  if (n == 0) return paths;
  const std::vector<Edge> edges = along_links(points, tangents, link);
  std::vector<std::uint8_t> removed(points.size(), 0);
  // Each round takes the longest path of every remaining part; what lies beside a path (its
  // spurs) is removed with it, what branches off further is searched again in the next round.
  for (int round = 0; round < 8; ++round) {
    std::vector<int> parent;
    const Adjacency adj = spanning_forest(edges, removed, parent);
    std::vector<std::vector<int>> parts(n);
    for (int i = 0; i < n; ++i) {
      if (!removed[i]) parts[find_root(parent, i)].push_back(i);
    }
    bool found = false;
    for (const auto& part : parts) {
      if (part.size() < min_nodes) continue;
      NodePath path;
      path.nodes = longest_path(adj, part.front());
      if (path.nodes.size() < min_nodes) continue;
      found = true;
      path.closed = is_ring(points, path.nodes, link);
      remove_with_spurs(points, part, path.nodes, link, removed);
      paths.push_back(std::move(path));
    }
    if (!found) break;
  }
  return paths;
}

}  // namespace groovetrace
