#include "sim/synthetic/procedural.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace px::sim {
namespace {

// A 32-bit integer hash with good avalanche (after Chris Wellons' "lowbias32").
inline uint32_t Mix(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

// Perlin-style lattice: a permutation and a table of values, built once. Lookups are a few
// loads instead of a hash per corner; the pattern repeats every 256 cells, which the seed
// offsets and per-octave rotations hide.
struct Lattice {
  uint8_t perm[512];
  float value[256];
  Lattice() {
    for (int i = 0; i < 256; ++i) perm[i] = static_cast<uint8_t>(i);
    uint32_t state = 0x2545f491U;
    for (int i = 255; i > 0; --i) {  // Fisher-Yates with a fixed hash sequence
      state = Mix(state + 0x9e3779b9U);
      std::swap(perm[i], perm[state % (i + 1)]);
    }
    for (int i = 0; i < 256; ++i) perm[256 + i] = perm[i];
    for (int i = 0; i < 256; ++i) value[i] = static_cast<float>(Mix(0x68e31da4U + i) >> 8) * (1.0f / 16777216.0f);
  }
};

const Lattice& TheLattice() {
  static const Lattice lattice;
  return lattice;
}

inline double Smooth(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }  // C2 quintic fade

}  // namespace

float ValueNoise(double x, double y, uint32_t seed) {
  const Lattice& lattice = TheLattice();
  const uint32_t h = Mix(seed);
  const double fx = std::floor(x), fy = std::floor(y);
  // Cell indices modulo 256, shifted by the seed so different seeds give unrelated fields.
  const int ix = static_cast<int>(static_cast<int64_t>(fx) + (h & 0xff)) & 0xff;
  const int iy = static_cast<int>(static_cast<int64_t>(fy) + ((h >> 8) & 0xff)) & 0xff;
  const uint8_t* perm = lattice.perm;
  const int a = perm[ix] + iy, b = perm[ix + 1] + iy;
  const float v00 = lattice.value[perm[a]], v01 = lattice.value[perm[a + 1]];
  const float v10 = lattice.value[perm[b]], v11 = lattice.value[perm[b + 1]];
  const double tx = Smooth(x - fx), ty = Smooth(y - fy);
  const double top = v00 + (v10 - v00) * tx;
  const double bottom = v01 + (v11 - v01) * tx;
  return static_cast<float>(top + (bottom - top) * ty);
}

float FractalNoise(double x, double y, double scale, int octaves, double persistence, double footprint, uint32_t seed) {
  // Each octave is rotated by atan(3/4) relative to the previous one and offset, so the lattices
  // of different octaves never line up.
  constexpr double kCos = 0.8, kSin = 0.6;
  double u = x / scale, v = y / scale;
  double wavelength = scale;
  double amplitude = 1.0, sum = 0.0, total = 0.0;
  for (int i = 0; i < octaves; ++i) {
    // Full weight while the wavelength spans >= 4 footprints, none below 2 (Nyquist with margin).
    const double keep = std::clamp(wavelength / footprint * 0.5 - 1.0, 0.0, 1.0);
    if (keep <= 0.0) {
      // This and all finer octaves are below the footprint: each contributes its mean.
      for (int j = i; j < octaves; ++j) {
        sum += amplitude * 0.5;
        total += amplitude;
        amplitude *= persistence;
      }
      break;
    }
    const double n = ValueNoise(u, v, seed + static_cast<uint32_t>(i) * 1013U);
    sum += amplitude * (keep * n + (1.0 - keep) * 0.5);
    total += amplitude;
    const double ru = kCos * u - kSin * v, rv = kSin * u + kCos * v;
    u = 2.0 * ru + 17.31;
    v = 2.0 * rv + 5.77;
    wavelength *= 0.5;
    amplitude *= persistence;
  }
  return total > 0 ? static_cast<float>(sum / total) : 0.5f;
}

float FilteredChecker(double x, double y, double square, double footprint) {
  // Integral of the +-1 square wave of period 2 over [p - w/2, p + w/2], divided by w
  // (the analytic box filter of a checker, after I. Quilez "filterable procedurals").
  const double w = std::max(footprint / square, 1e-6);
  // The square wave's integral is 1 - 2 tri(p), so its box average is the difference below.
  auto filtered_wave = [w](double p) {
    auto tri = [](double q) { return std::abs(q * 0.5 - std::floor(q * 0.5) - 0.5); };
    return 2.0 * (tri(p - 0.5 * w) - tri(p + 0.5 * w)) / w;
  };
  const double sx = filtered_wave(x / square), sy = filtered_wave(y / square);
  return static_cast<float>(0.5 - 0.5 * sx * sy);
}

}  // namespace px::sim
