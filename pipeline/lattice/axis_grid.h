// How many tiles lie along one axis of the frame, and where their boundaries are (coarsely):
// a comb of equally spaced gaps fitted to a BoundaryProfile for each possible count, then each
// gap moved to its own strongest evidence nearby (tiles may be unequal and offset).
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/lattice/boundary_profile.h"

namespace px::lattice {

struct AxisGrid {
  int count = 1;                    // tiles along the axis
  std::vector<double> gaps;         // count - 1 internal gap centres, working pixels
  std::vector<double> gap_z;        // their evidence (z-scores)
  std::vector<int> gap_polarity;    // -1 dark band, +1 bright band
  std::vector<int> gap_half_width;  // band half-width that responded, working pixels
  double weakest_z = 0;             // min(gap_z); 0 without internal gaps
};

struct AxisSearch {
  int expected_count = 0;  // 0 = any count in [1, max_count]
  int max_count = 8;
  double min_z = 6.0;
  std::string axis_name;   // "columns" or "rows", for messages
  char coordinate = 'x';   // for messages
  double to_sensor = 1.0;  // working pixels -> sensor pixels, for messages
};

// What the gaps along one axis fit: one grid when the period is clear, or, when it is ambiguous,
// every count whose gaps pass plus a count of 1 (none of them a lattice), largest first, for the
// tiles' own pictures to decide (tile_agreement.h).
struct AxisGrids {
  std::vector<AxisGrid> candidates;  // never empty
  std::string ambiguity;             // empty when the period is clear, else why it is not
};

// The largest count whose every gap passes min_z and 0.3 x the strongest line's z. The counts
// that fit are ambiguous when they do not divide each other and the larger count does not explain
// the smaller's gaps. NOT_FOUND when expected_count's gaps are weak, or when the profile repeats
// with a period finer than max_count allows (a micro-lens image). A count of 1 (no internal gap)
// is not an error here.
StatusOr<AxisGrids> FindAxisGrid(const BoundaryProfile& profile, const AxisSearch& search);

}  // namespace px::lattice
