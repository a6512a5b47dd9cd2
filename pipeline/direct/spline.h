// Interpolation through keyframes at increasing times: piecewise linear, or a Catmull-Rom cubic
// (paper 4.4: authored keyframes "along a cubic spline"). The Catmull-Rom form used here is the
// cubic Hermite spline whose tangent at key i is the finite difference of its neighbours,
// (p[i+1] - p[i-1]) / (t[i+1] - t[i-1]), and one-sided at the ends. It passes through every key,
// is C1, reproduces straight lines at constant speed (two keys give exactly the linear path),
// and works for uneven key spacing.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

namespace px::direct {

enum class Interpolation {
  kLinear,      // straight between keys (the taxonomy's moves, paper 4.2)
  kCatmullRom,  // cubic through every key (authored shots, paper 4.4)
};

// Index i of the key span [times[i], times[i+1]] holding t (clamped into the keys' range) and
// the fraction of the span at t. Needs at least two increasing times.
std::pair<size_t, double> KeySpan(const std::vector<double>& times, double t);

// The value at t of the curve through (times[k], values[k]). T is double or an Eigen vector.
template <typename T>
T Interpolate(const std::vector<double>& times, const std::vector<T>& values, double t, Interpolation mode) {
  const auto [i, f] = KeySpan(times, t);
  const T& p0 = values[i];
  const T& p1 = values[i + 1];
  if (mode == Interpolation::kLinear) return T(p0 + f * (p1 - p0));
  const double h = times[i + 1] - times[i];
  // Tangents (per unit time) from the neighbours, one-sided at the ends.
  const T m0 = i == 0 ? T((p1 - p0) / h) : T((p1 - values[i - 1]) / (times[i + 1] - times[i - 1]));
  const T m1 = i + 2 >= values.size() ? T((p1 - p0) / h) : T((values[i + 2] - p0) / (times[i + 2] - times[i]));
  const double f2 = f * f, f3 = f2 * f;
  const double h00 = 2 * f3 - 3 * f2 + 1, h10 = f3 - 2 * f2 + f, h01 = -2 * f3 + 3 * f2, h11 = f3 - f2;
  return T(h00 * p0 + (h10 * h) * m0 + h01 * p1 + (h11 * h) * m1);
}

}  // namespace px::direct
