// The soft z-buffer weight of the paper's equation (1) (ALGORITHM.md section 5): 1 for depth gaps up
// to gamma, a raised cosine down to 0 at rho - gamma, 0 beyond; rho is the scene's depth range and
// gamma = rho / 10 in the paper. Used forwards (gap behind the nearest surface: the soft z-buffer)
// and in reverse (gap in front of the farthest: hole filling prefers the background).
#pragma once

#include <algorithm>
#include <cmath>

namespace px::render {

class SoftZ {
 public:
  SoftZ() = default;
  // rho_m > 0, gamma_fraction in (0, 0.5).
  SoftZ(double rho_m, double gamma_fraction)
      : rho_(static_cast<float>(rho_m)),
        gamma_(static_cast<float>(rho_m * gamma_fraction)),
        inv_span_(static_cast<float>(1.0 / (rho_m - 2.0 * rho_m * gamma_fraction))) {}

  // w_z(dz), dz in metres (>= 0 in use; a negative gap weighs 1).
  float Weight(float dz) const {
    if (dz <= gamma_) return 1.0f;
    if (dz > rho_ - gamma_) return 0.0f;
    constexpr float kPi = 3.14159265358979f;
    return 0.5f * (1.0f + std::cos(kPi * (dz - gamma_) * inv_span_));
  }

  float rho() const { return rho_; }
  float gamma() const { return gamma_; }

 private:
  float rho_ = 1.0f;
  float gamma_ = 0.1f;
  float inv_span_ = 1.25f;
};

}  // namespace px::render
