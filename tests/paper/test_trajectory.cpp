// Geometric median against independent oracles, tool orientation, Euler angles, and the
// paper's trajectory on synthetic V-grooves whose root line is known.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <groovetrace/error.hpp>
#include <groovetrace/paper.hpp>
#include <groovetrace/rotation.hpp>
#include <groovetrace/trajectory.hpp>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

using groovetrace::Cloud;
using groovetrace::geometric_median;
using groovetrace::Normals;
using groovetrace::Trajectory;
using Points = std::vector<Eigen::Vector3d>;

constexpr double kPi = 3.14159265358979323846;

groovetrace::Waypoint waypoint(const Eigen::Quaterniond& q) {
  groovetrace::Waypoint w;
  w.position.setZero();
  w.orientation = q;
  w.rotation_vector.setZero();  // Eigen members are not initialized by Waypoint
  w.euler_zyx_deg.setZero();
  return w;
}

double sum_of_distances(const Points& points, const Eigen::Vector3d& y) {
  double s = 0.0;
  for (const auto& p : points) s += (p - y).norm();
  return s;
}

/// A certified lower bound on min_y sum |y - x_i| (convex duality): for any u_i with
/// |u_i| <= 1 and sum u_i = 0, sum u_i . (y - x_i) is the same for every y and is at most
/// the minimum. The u_i are built from the unit vectors at the candidate y, so the bound is
/// tight exactly when y is a median.
double dual_lower_bound(const Points& points, const Eigen::Vector3d& y) {
  std::vector<Eigen::Vector3d> u(points.size(), Eigen::Vector3d::Zero());
  std::vector<std::size_t> at_y;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d d = y - points[i];
    if (d.norm() == 0.0) {
      at_y.push_back(i);
    } else {
      u[i] = d.normalized();
      sum += u[i];
    }
  }
  if (!at_y.empty()) {
    // A data point's term is free in the unit ball: let those points balance the others.
    for (std::size_t i : at_y) u[i] = -sum / static_cast<double>(at_y.size());
  } else {
    const Eigen::Vector3d mean = sum / static_cast<double>(points.size());
    for (auto& v : u) v -= mean;
  }
  double largest = 1.0;
  for (const auto& v : u) largest = std::max(largest, v.norm());
  double bound = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) bound += u[i].dot(y - points[i]) / largest;
  return bound;
}

/// Brute force: a grid over the bounding box, repeatedly zoomed onto its best node. Slow
/// and simple, sharing nothing with Weiszfeld.
Eigen::Vector3d grid_minimum(const Points& points) {
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Eigen::Vector3d center = 0.5 * (lo + hi);
  Eigen::Vector3d half = (0.5 * (hi - lo)).cwiseMax(1e-12);
  const int n = 10;  // nodes -n..n per axis
  for (int level = 0; level < 45; ++level) {
    Eigen::Vector3d best = center;
    double best_f = sum_of_distances(points, center);
    for (int i = -n; i <= n; ++i)
      for (int j = -n; j <= n; ++j)
        for (int k = -n; k <= n; ++k) {
          const Eigen::Vector3d y =
              center + Eigen::Vector3d(i * half.x(), j * half.y(), k * half.z()) / n;
          const double f = sum_of_distances(points, y);
          if (f < best_f) {
            best_f = f;
            best = y;
          }
        }
    center = best;
    half *= 0.5;  // keeps +-5 old cells around the best node: safe for convex objectives
  }
  return center;
}

void expect_near_optimal(const Points& points, const Eigen::Vector3d& median,
                         const std::string& what) {
  const double f = sum_of_distances(points, median);
  const double lower = dual_lower_bound(points, median);
  EXPECT_LE(f - lower, 1e-9 * f) << what << ": f=" << f << " lower bound=" << lower;
}

TEST(GeometricMedian, EmptyThrowsSmallSetsAreExact) {
  EXPECT_THROW(geometric_median({}), std::invalid_argument);
  const Eigen::Vector3d a(0.1, -0.2, 0.5), b(0.3, 0.1, 0.45);
  EXPECT_EQ(geometric_median({a}), a);
  EXPECT_NEAR(sum_of_distances({a, b}, geometric_median({a, b})), (a - b).norm(), 1e-15);
  EXPECT_EQ(geometric_median({a, a, a}), a);
}

TEST(GeometricMedian, SymmetricAndCollinearSetsHaveKnownMedians) {
  // Square corners: the centre.
  const Points square = {{1, 1, 0}, {-1, 1, 0}, {-1, -1, 0}, {1, -1, 0}};
  EXPECT_LT(geometric_median(square).norm(), 1e-12);
  // Collinear, odd count: the middle point (not the mean, which is pulled by the outlier).
  const Points odd = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {40, 40, 40}};
  EXPECT_LT((geometric_median(odd) - Eigen::Vector3d(2, 2, 2)).norm(), 1e-9);
  // Collinear, even count: every point between the middle two is a median.
  const Points even = {{0, 0, 1}, {0, 1, 1}, {0, 3, 1}, {0, 10, 1}};
  const Eigen::Vector3d m = geometric_median(even);
  EXPECT_NEAR(sum_of_distances(even, m), 12.0, 1e-9);  // (10 - 0) + (3 - 1)
  EXPECT_NEAR(m.x(), 0.0, 1e-12);
  EXPECT_NEAR(m.z(), 1.0, 1e-12);
  EXPECT_GE(m.y(), 1.0 - 1e-12);
  EXPECT_LE(m.y(), 3.0 + 1e-12);
  expect_near_optimal(even, m, "collinear even");
}

TEST(GeometricMedian, MedianOnADataPoint) {
  // Start (the centroid) exactly on a data point that is the median.
  const Points star = {{0, 0, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 2, 0}, {0, -2, 0}};
  EXPECT_EQ(geometric_median(star), Eigen::Vector3d::Zero());
  // A triangle with an angle over 120 degrees: the median is that vertex, while Weiszfeld
  // from the centroid only creeps towards it.
  const Points obtuse = {{0, 0, 0}, {1, 0, 0}, {-0.9, 0.1, 0}};
  const Eigen::Vector3d m = geometric_median(obtuse);
  EXPECT_EQ(m, Eigen::Vector3d::Zero());
  expect_near_optimal(obtuse, m, "obtuse triangle");
  // Duplicated points: multiplicity 3 of 5 outweighs the rest.
  const Eigen::Vector3d heavy(0.2, 0.3, 0.4);
  const Points duplicated = {heavy, heavy, heavy, {1, 2, 3}, {-3, 0, 1}};
  EXPECT_EQ(geometric_median(duplicated), heavy);
  expect_near_optimal(duplicated, heavy, "duplicated");
}

TEST(GeometricMedian, RandomSetsMatchGridSearchAndDualBound) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> count(3, 40);
  for (int trial = 0; trial < 30; ++trial) {
    // Slice-like sets: a few mm across, half a metre from the origin.
    const Eigen::Vector3d offset(0.1 * unit(rng), 0.1 * unit(rng), 0.5);
    const double scale = 0.003;
    Points points(static_cast<std::size_t>(count(rng)));
    for (auto& p : points) p = offset + scale * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    if (trial % 5 == 1) points.push_back(points[0]);  // duplicates
    if (trial % 5 == 2) {                             // all on one line
      for (auto& p : points) p = offset + unit(rng) * scale * Eigen::Vector3d(1, 2, -1);
    }
    if (trial % 5 == 3) {  // even count of nearly collinear points
      if (points.size() % 2) points.pop_back();
      for (auto& p : points) p.z() = offset.z() + 1e-7 * unit(rng);
    }
    const std::string what = "trial " + std::to_string(trial);

    const Eigen::Vector3d precise = geometric_median(points, 100000, 1e-15);
    expect_near_optimal(points, precise, what);
    const double f_grid = sum_of_distances(points, grid_minimum(points));
    const double f_precise = sum_of_distances(points, precise);
    EXPECT_NEAR(f_precise, f_grid, 1e-9 * f_grid) << what;

    // The defaults of the pipeline (1000 iterations, 0.1 um steps) on mm-sized slices.
    const double f_default = sum_of_distances(points, geometric_median(points));
    EXPECT_LE(f_default, f_grid * (1.0 + 1e-6)) << what;
  }
}

TEST(ToolOrientation, AxesFollowNormalAndTravel) {
  std::mt19937 rng(1);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d n = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Vector3d travel(g(rng), g(rng), g(rng));
    const Eigen::Matrix3d R = groovetrace::tool_orientation(n, travel).toRotationMatrix();
    const Eigen::Vector3d x = R.col(0), y = R.col(1), z = R.col(2);
    EXPECT_LT((z + n).norm(), 1e-12);
    EXPECT_NEAR(x.dot(z), 0.0, 1e-12);
    const Eigen::Vector3d along = (travel - travel.dot(z) * z).normalized();
    EXPECT_LT((x - along).norm(), 1e-9);
    EXPECT_LT((x.cross(y) - z).norm(), 1e-12);  // right-handed
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  }
  // A non-unit normal is normalized; travel along the normal still gives a proper frame.
  const Eigen::Matrix3d R =
      groovetrace::tool_orientation(Eigen::Vector3d(0, 0, -3), Eigen::Vector3d(0, 0, 1))
          .toRotationMatrix();
  EXPECT_LT((R.col(2) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
}

Eigen::Matrix3d zyx(double yaw_deg, double pitch_deg, double roll_deg) {
  const double d = kPi / 180.0;
  return (Eigen::AngleAxisd(yaw_deg * d, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_deg * d, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_deg * d, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TEST(FillRotationRepresentations, EulerZyxAndRotationVectors) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> angle(-179.0, 179.0), pitch(-89.0, 89.0);
  Trajectory t;
  std::vector<Eigen::Vector3d> expected;
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d e(angle(rng), pitch(rng), angle(rng));
    t.waypoints.push_back(waypoint(Eigen::Quaterniond(zyx(e[0], e[1], e[2]))));
    expected.push_back(e);
  }
  groovetrace::fill_rotation_representations(t);
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const auto& w = t.waypoints[k];
    EXPECT_LT((w.euler_zyx_deg - expected[k]).norm(), 1e-9) << k;
    EXPECT_LT(groovetrace::quaternion_from_rotation_vector(w.rotation_vector)
                  .angularDistance(w.orientation),
              1e-12);
  }
  EXPECT_LE(t.waypoints[0].rotation_vector.norm(), kPi + 1e-12);  // first one is principal

  // Gimbal lock: pitch +-90 deg; yaw and roll are folded into yaw, the matrix is kept.
  for (double p : {90.0, -90.0}) {
    Trajectory lock;
    lock.waypoints.push_back(waypoint(Eigen::Quaterniond(zyx(30.0, p, 20.0))));
    groovetrace::fill_rotation_representations(lock);
    const Eigen::Vector3d e = lock.waypoints[0].euler_zyx_deg;
    EXPECT_NEAR(e[1], p, 1e-6);
    EXPECT_NEAR(e[2], 0.0, 1e-9);
    EXPECT_LT((zyx(e[0], e[1], e[2]) - zyx(30.0, p, 20.0)).norm(), 1e-7);
  }
}

// --- synthetic grooves -----------------------------------------------------------------

/// A groove scan: groove points (mask 1) on the two flanks of a V around a root curve,
/// plate points (mask 0) beside it, and points the trajectory must ignore.
struct GrooveScan {
  Cloud cloud;
  Normals normals;
  std::vector<std::uint8_t> mask;
  std::size_t groove_points = 0;  // valid groove points with normals

  void add(const Eigen::Vector3d& p, const Eigen::Vector3d& n, std::uint8_t m) {
    cloud.x.push_back(static_cast<float>(p.x()));
    cloud.y.push_back(static_cast<float>(p.y()));
    cloud.z.push_back(static_cast<float>(p.z()));
    normals.x.push_back(static_cast<float>(n.x()));
    normals.y.push_back(static_cast<float>(n.y()));
    normals.z.push_back(static_cast<float>(n.z()));
    mask.push_back(m);
    cloud.width = static_cast<std::uint32_t>(cloud.size());
  }
};

/// Root curve sample: position, lateral unit vector (across the seam) and the plate normal
/// (towards the sensor), all in the camera frame (m).
struct RootSample {
  Eigen::Vector3d root, lateral, up;
};

/// V cross-sections at each root sample: flank offsets s in [-half_width, half_width]
/// (m, across the seam), height |s| * slope above the root; flank normals exact.
/// `noise` (m) perturbs positions; points are emitted in pairs +-s so each cross-section
/// is symmetric when noise = 0.
GrooveScan make_groove(const std::vector<RootSample>& samples, double half_width, double slope,
                       int offsets, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  GrooveScan scan;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& r : samples) {
    for (int j = 0; j <= offsets; ++j) {
      const double s = half_width * j / offsets;
      for (double side : {1.0, -1.0}) {
        if (j == 0 && side < 0) continue;
        const Eigen::Vector3d p = r.root + side * s * r.lateral + s * slope * r.up;
        // The root itself gets the bisector, as a normal estimate across the crease would.
        const Eigen::Vector3d n =
            j == 0 ? r.up : Eigen::Vector3d((r.up - side * slope * r.lateral).normalized());
        const Eigen::Vector3d jitter(noise * g(rng), noise * g(rng), noise * g(rng));
        scan.add(p + jitter, n, 1);
        ++scan.groove_points;
      }
    }
    // Flat plate beside the groove: not groove, must not matter.
    for (double side : {1.0, -1.0}) {
      scan.add(r.root + side * 0.01 * r.lateral + 0.004 * r.up, r.up, 0);
    }
  }
  // Invalid returns and a groove-marked point without a normal, far away: if either were
  // used, the direction and the medians would be off by metres.
  scan.add(Eigen::Vector3d(nan, nan, nan), Eigen::Vector3d(0, 0, -1), 1);
  scan.add(Eigen::Vector3d(3.0, -2.0, 4.0), Eigen::Vector3d(nan, nan, nan), 1);
  return scan;
}

std::vector<RootSample> straight_root(const Eigen::Vector3d& start, const Eigen::Vector3d& dir,
                                      const Eigen::Vector3d& up, double length, double spacing) {
  std::vector<RootSample> samples;
  const Eigen::Vector3d lateral = up.cross(dir).normalized();
  const int n = static_cast<int>(std::round(length / spacing));
  for (int i = 0; i <= n; ++i) samples.push_back({start + (length * i / n) * dir, lateral, up});
  return samples;
}

/// Orthonormal groove axes in the camera frame: travel roughly along +x on a plate facing
/// the sensor at the origin (normal roughly -z).
void groove_axes(Eigen::Vector3d& dir, Eigen::Vector3d& up) {
  up = Eigen::Vector3d(0.0, -0.1, -1.0).normalized();
  dir = Eigen::Vector3d(1.0, 0.2, 0.05);
  dir = (dir - dir.dot(up) * up).normalized();
}

double distance_to_line(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& dir) {
  const Eigen::Vector3d d = p - a;
  return (d - d.dot(dir) * dir).norm();
}

TEST(PaperTrajectory, StraightGrooveFollowsTheRootLine) {
  Eigen::Vector3d dir, up;
  groove_axes(dir, up);
  const Eigen::Vector3d start(-0.1, 0.02, 0.5);
  const double length = 0.2, half_width = 0.0004, slope = 1.0;  // 90 degree V
  const int slices = 50;
  // 401 root samples: no cross-section lies on a slice boundary (401 is prime), so every
  // slice holds whole, symmetric cross-sections.
  const GrooveScan scan = make_groove(straight_root(start, dir, up, length, length / 401),
                                      half_width, slope, 4, 0.0, 1);
  const Trajectory t = groovetrace::paper_trajectory(scan.cloud, scan.normals, scan.mask, slices);

  EXPECT_EQ(t.frame, "camera");
  ASSERT_EQ(t.waypoints.size(), static_cast<std::size_t>(slices));
  EXPECT_GT(t.direction.dot(dir), 1.0 - 1e-9);
  EXPECT_GT(t.direction.x(), 0.0);
  EXPECT_NEAR(t.length, length, 1e-6);
  const Eigen::Vector3d lateral = up.cross(dir).normalized();
  std::size_t support = 0;
  for (std::size_t i = 0; i < t.waypoints.size(); ++i) {
    const auto& w = t.waypoints[i];
    const Eigen::Vector3d rel = w.position - start;
    // The median lies in the V's hull (height <= half_width * slope above the root) and on
    // its symmetry plane.
    EXPECT_LT(distance_to_line(w.position, start, dir), 0.0005) << i;
    EXPECT_NEAR(rel.dot(lateral), 0.0, 2e-6) << i;
    EXPECT_GE(rel.dot(up), -2e-6) << i;
    EXPECT_LE(rel.dot(up), half_width * slope + 2e-6) << i;
    if (i > 0) {
      EXPECT_GT(w.position.x(), t.waypoints[i - 1].position.x()) << i;
    }
    const Eigen::Matrix3d R = w.orientation.toRotationMatrix();
    EXPECT_LT((R.col(2) + up).norm(), 1e-6) << i;  // mean flank normal = plate normal
    EXPECT_LT((R.col(0) - dir).norm(), 1e-6) << i;
    EXPECT_LT(groovetrace::quaternion_from_rotation_vector(w.rotation_vector)
                  .angularDistance(w.orientation),
              1e-9);
    if (i > 0) {
      EXPECT_LT((w.rotation_vector - t.waypoints[i - 1].rotation_vector).norm(), 1e-3);
    }
    support += static_cast<std::size_t>(w.support);
  }
  EXPECT_EQ(support, scan.groove_points);
  // Slices of equal width: waypoints (slice medians) are one slice width apart.
  const double spacing = (t.waypoints[25].position - t.waypoints[24].position).dot(t.direction);
  EXPECT_NEAR(spacing, length / slices, 0.0006);
}

TEST(PaperTrajectory, DirectionSignDoesNotDependOnPointOrderOrSense) {
  Eigen::Vector3d dir, up;
  groove_axes(dir, up);
  // The same groove described from its other end.
  const Eigen::Vector3d end = Eigen::Vector3d(-0.1, 0.02, 0.5) + 0.2 * dir;
  const GrooveScan scan =
      make_groove(straight_root(end, -dir, up, 0.2, 0.0005), 0.0004, 1.0, 4, 0.0, 1);
  const Trajectory t = groovetrace::paper_trajectory(scan.cloud, scan.normals, scan.mask, 20);
  EXPECT_GT(t.direction.dot(dir), 1.0 - 1e-9);
  for (std::size_t i = 1; i < t.waypoints.size(); ++i) {
    EXPECT_GT(t.waypoints[i].position.x(), t.waypoints[i - 1].position.x());
  }
  // Perpendicular to x: +y decides.
  for (double sense : {1.0, -1.0}) {
    const Eigen::Vector3d along_y(0.0, sense, 0.0), facing(0.0, 0.0, -1.0);
    const GrooveScan y_scan = make_groove(
        straight_root(Eigen::Vector3d(0.0, -0.05 * sense, 0.4), along_y, facing, 0.1, 0.0005),
        0.0004, 1.0, 4, 0.0, 2);
    const Trajectory ty =
        groovetrace::paper_trajectory(y_scan.cloud, y_scan.normals, y_scan.mask, 10);
    EXPECT_GT(ty.direction.y(), 1.0 - 1e-9);
    EXPECT_GT(ty.waypoints.back().position.y(), ty.waypoints.front().position.y());
  }
}

TEST(PaperTrajectory, NoisyGrooveStaysWithinHalfAMillimetre) {
  Eigen::Vector3d dir, up;
  groove_axes(dir, up);
  const Eigen::Vector3d start(-0.08, 0.0, 0.45);
  const double noise = 0.00005;  // 0.05 mm per axis
  const GrooveScan scan =
      make_groove(straight_root(start, dir, up, 0.16, 0.0004), 0.0006, 0.577, 6, noise, 3);
  const Trajectory t = groovetrace::paper_trajectory(scan.cloud, scan.normals, scan.mask, 55);
  ASSERT_EQ(t.waypoints.size(), 55u);
  for (std::size_t i = 0; i < t.waypoints.size(); ++i) {
    EXPECT_LT(distance_to_line(t.waypoints[i].position, start, dir), 0.0005) << i;
    // Noise moves points across slice boundaries, so a slice can hold more of one flank:
    // its mean normal then leans towards that flank's normal (30 degrees off) a little.
    const Eigen::Vector3d z = t.waypoints[i].orientation * Eigen::Vector3d::UnitZ();
    EXPECT_GT(z.dot(-up), std::cos(2.0 * kPi / 180.0)) << i;
  }
}

TEST(PaperTrajectory, CurvedGrooveFollowsTheArc) {
  // Root: an arc of radius 0.15 m over 60 degrees on a plate facing the sensor.
  const Eigen::Vector3d up(0.0, 0.0, -1.0);
  const Eigen::Vector3d chord = Eigen::Vector3d(1.0, 0.1, 0.0).normalized();
  const Eigen::Vector3d radial0 = chord.cross(up).normalized();  // in the plate plane
  const double radius = 0.15;
  const Eigen::Vector3d center = Eigen::Vector3d(0.0, 0.0, 0.5) - radius * radial0;
  std::vector<RootSample> samples;
  const int n = 320;
  for (int i = 0; i <= n; ++i) {
    const double phi = (-30.0 + 60.0 * i / n) * kPi / 180.0;
    const Eigen::Vector3d radial = std::cos(phi) * radial0 + std::sin(phi) * chord;
    samples.push_back({center + radius * radial, radial, up});
  }
  const double half_width = 0.0004, slope = 1.0;
  const GrooveScan scan = make_groove(samples, half_width, slope, 4, 0.0, 4);
  const int slices = 50;
  const Trajectory t = groovetrace::paper_trajectory(scan.cloud, scan.normals, scan.mask, slices);
  ASSERT_EQ(t.waypoints.size(), static_cast<std::size_t>(slices));
  EXPECT_GT(t.direction.dot(chord), 1.0 - 1e-6);
  // The chord, plus the outer flank's reach beyond each end (half_width * sin 30 deg).
  EXPECT_NEAR(t.length, (2.0 * radius + 2.0 * half_width) * std::sin(30.0 * kPi / 180.0), 1e-6);
  Eigen::Vector3d mean_z = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < t.waypoints.size(); ++i) {
    const Eigen::Vector3d rel = t.waypoints[i].position - center;
    const double height = rel.dot(up);
    const double in_plane = (rel - height * up).norm();
    EXPECT_LT(std::hypot(in_plane - radius, height), 0.0005) << i;
    // Nearly on the arc: slices cut across the chord, not across the local tangent, so a
    // slice can hold one flank of a cross-section without the other (the flank offsets
    // reach up to half_width * sin 30 deg along the chord). That moves a slice's median and
    // tilts its mean normal a little; the tilts of neighbouring slices cancel on average.
    EXPECT_LT(std::abs(in_plane - radius), 1e-4) << i;
    if (i > 0) {
      EXPECT_GT(t.waypoints[i].position.x(), t.waypoints[i - 1].position.x()) << i;
    }
    const Eigen::Vector3d z = t.waypoints[i].orientation * Eigen::Vector3d::UnitZ();
    EXPECT_GT(z.dot(-up), std::cos(5.0 * kPi / 180.0)) << i;
    mean_z += z;
  }
  EXPECT_GT(mean_z.normalized().dot(-up), std::cos(0.5 * kPi / 180.0));
}

TEST(PaperTrajectory, DegenerateInputsThrowNoGroove) {
  using groovetrace::NoGrooveError;
  Eigen::Vector3d dir, up;
  groove_axes(dir, up);
  GrooveScan scan = make_groove(straight_root(Eigen::Vector3d(0, 0, 0.5), dir, up, 0.05, 0.001),
                                0.0004, 1.0, 2, 0.0, 5);
  // Nothing marked.
  std::vector<std::uint8_t> none(scan.mask.size(), 0);
  EXPECT_THROW(groovetrace::paper_trajectory(scan.cloud, scan.normals, none, 50), NoGrooveError);
  // One slice only.
  EXPECT_THROW(groovetrace::paper_trajectory(scan.cloud, scan.normals, scan.mask, 1),
               NoGrooveError);
  // Marked points without normals.
  Normals no_normals;
  no_normals.resize(scan.cloud.size());
  EXPECT_THROW(groovetrace::paper_trajectory(scan.cloud, no_normals, scan.mask, 50), NoGrooveError);
  // A single groove point, and many copies of one point (zero length).
  GrooveScan one;
  one.add(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(0, 0, -1), 1);
  EXPECT_THROW(groovetrace::paper_trajectory(one.cloud, one.normals, one.mask, 50), NoGrooveError);
  for (int k = 0; k < 10; ++k) one.add(Eigen::Vector3d(0, 0, 0.5), Eigen::Vector3d(0, 0, -1), 1);
  EXPECT_THROW(groovetrace::paper_trajectory(one.cloud, one.normals, one.mask, 50), NoGrooveError);
  try {
    groovetrace::paper_trajectory(one.cloud, one.normals, one.mask, 50);
  } catch (const groovetrace::Error& e) {
    EXPECT_EQ(e.code(), groovetrace::ExitCode::kNoGroove);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
  // Mismatched inputs are a caller bug, not a missing groove.
  std::vector<std::uint8_t> short_mask(3, 1);
  EXPECT_THROW(groovetrace::paper_trajectory(scan.cloud, scan.normals, short_mask, 50),
               groovetrace::InternalError);
  EXPECT_THROW(groovetrace::paper_trajectory(scan.cloud, scan.normals, scan.mask, 0),
               groovetrace::UsageError);
}

}  // namespace
