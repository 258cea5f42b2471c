// Geometric median by Weiszfeld's iteration with the Vardi-Zhang (2000) modification, which
// keeps the iteration defined and convergent when an iterate lands on a data point.

#include <algorithm>
#include <groovetrace/paper.hpp>
#include <limits>
#include <stdexcept>

namespace groovetrace {

namespace {

double sum_of_distances(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& y) {
  double sum = 0.0;
  for (const auto& p : points) sum += (p - y).norm();
  return sum;
}

}  // namespace

Eigen::Vector3d geometric_median(const std::vector<Eigen::Vector3d>& points, int max_iterations,
                                 double tolerance) {
  if (points.empty()) throw std::invalid_argument("geometric_median: no points");
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  // One point is its own median; for two, every point of the segment is one.
  if (points.size() <= 2) return centroid;

  double spread = 0.0;
  for (const auto& p : points) spread = std::max(spread, (p - centroid).norm());
  if (spread == 0.0) return centroid;
  // Distances this small relative to the point set count as "on the data point": 1/d would
  // otherwise swamp every other weight (or overflow) without changing the answer.
  const double coincide = spread * 1e-13;

  Eigen::Vector3d y = centroid;
  for (int it = 0; it < max_iterations; ++it) {
    Eigen::Vector3d pull = Eigen::Vector3d::Zero();  // sum of (p - y) / |p - y|
    double weight = 0.0;                             // sum of 1 / |p - y|
    int at_y = 0;
    for (const auto& p : points) {
      const Eigen::Vector3d diff = p - y;
      const double d = diff.norm();
      if (d <= coincide) {
        ++at_y;
        continue;
      }
      pull += diff / d;
      weight += 1.0 / d;
    }
    if (weight == 0.0) break;
    // The plain Weiszfeld step, written relative to y to keep digits for clouds far from the
    // origin: T(y) - y = pull / weight.
    Eigen::Vector3d step = pull / weight;
    if (at_y > 0) {
      // y is a data point of multiplicity at_y. It is the median iff the unit pulls of the
      // others cannot outweigh it; otherwise move only part of the way (Vardi-Zhang).
      const double r = pull.norm();
      if (r <= at_y) break;
      step *= 1.0 - at_y / r;
    }
    y += step;
    if (step.norm() < tolerance) break;
  }

  // Weiszfeld creeps only linearly towards a median that sits on a data point, where the
  // objective has a kink; the nearest data point is then the better answer.
  std::size_t nearest = 0;
  double nearest_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = (points[i] - y).squaredNorm();
    if (d < nearest_d) {
      nearest_d = d;
      nearest = i;
    }
  }
  if (sum_of_distances(points, points[nearest]) <= sum_of_distances(points, y)) {
    return points[nearest];
  }
  return y;
}

}  // namespace groovetrace
