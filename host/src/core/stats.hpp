#pragma once
// Small robust statistics and unit conversions (internal). Each keeps the exact arithmetic of
// the hand-written copies it replaced: the outputs are compared byte for byte, so the order of
// the operations matters (x * kRadToDeg is not x * 180 / pi).

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace groovetrace {

/// A Gaussian's sigma per median absolute deviation (unitless).
constexpr double kMadToSigma = 1.4826;
/// Tukey biweight's cut-off in sigmas: 95 % efficiency on Gaussian noise (unitless).
constexpr double kTukeyC = 4.685;
/// Degrees per radian.
constexpr double kRadToDeg = 57.295779513082320876;

/// The element at n/2 of the sorted values (the upper of the two middle ones for even n), in
/// the values' unit; NaN when empty.
template <typename T>
T upper_median(std::vector<T> v) {
  if (v.empty()) return static_cast<T>(NAN);
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

/// kMadToSigma times the upper median of |v - centre|, in the values' unit: a Gaussian's sigma,
/// robust to outliers. The deviations are taken in T (float values: float deviations).
template <typename T>
double mad_sigma(std::vector<T> v, double centre) {
  for (T& x : v) x = static_cast<T>(std::abs(x - centre));
  return kMadToSigma * upper_median(std::move(v));
}

/// Tukey's biweight (1 - (r/c)^2)^2 for |r| < c, else 0 (unitless; r and c in one unit).
/// Needs c > 0: c = 0 gives NaN for r = 0.
inline double tukey_weight(double r, double c) {
  const double t = r / c;
  return std::abs(t) >= 1 ? 0.0 : (1 - t * t) * (1 - t * t);
}

/// tukey_weight, but 1 when c is not positive (no scale yet, as on noise-free data: every point
/// counts fully).
inline double tukey_weight_or_one(double r, double c) {
  if (!(c > 0)) return 1.0;
  return tukey_weight(r, c);
}

/// Tricube kernel (1 - (|d|/h)^3)^3 for |d| < h, else 0 (unitless; d and h in one unit).
inline double tricube_weight(double d, double h) {
  if (std::abs(d) >= h) return 0.0;
  const double t = 1 - std::pow(std::abs(d) / h, 3);
  return t * t * t;
}

/// Radians to degrees.
constexpr double rad_to_deg(double rad) { return rad * kRadToDeg; }

/// Degrees to radians (deg * pi / 180, in that order).
constexpr double deg_to_rad(double deg) { return deg * M_PI / 180; }

}  // namespace groovetrace
