// Band-limited procedural patterns for synthetic textures. Every function takes the sample
// footprint (the spacing between neighbouring rays on the surface) and removes detail finer
// than it, so distant or grazing surfaces do not alias. Pure functions of their arguments:
// the same inputs give the same bits on every thread.
#pragma once

#include <cstdint>

namespace px::sim {

// Value noise on the integer lattice, smoothly interpolated: a value in [0, 1] whose detail
// has a wavelength of about one unit.
float ValueNoise(double x, double y, uint32_t seed);

// Fractal sum of `octaves` value-noise layers: the first has wavelength `scale`, each next one
// half of it with `persistence` times the amplitude (and rotated, so no lattice axis dominates).
// Octaves whose wavelength is below about four footprints fade to their mean, gone at two.
// Result in [0, 1], mean 0.5. Units: x, y, scale and footprint in the same length unit.
float FractalNoise(double x, double y, double scale, int octaves, double persistence, double footprint, uint32_t seed);

// A checkerboard of `square` sized cells, box-filtered analytically over `footprint`: 0 or 1 on
// the cells when sharp, tending to 0.5 when the footprint spans many cells.
float FilteredChecker(double x, double y, double square, double footprint);

}  // namespace px::sim
