#include "pipeline/lattice/axis_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace px::lattice {
namespace {

// Gaps stronger than this z add no more to a comb's score: one huge gap must not carry a comb.
constexpr double kZCap = 30.0;
// A comb's gaps may each move this fraction of the period to their own evidence.
constexpr double kGapSlackOfPeriod = 0.08;
// The comb as a whole may be offset and stretched by these fractions of the period.
constexpr double kCombOffsetOfPeriod = 0.12;
constexpr double kCombStretch = 0.06;
// The gaps of one lattice look alike: every gap of a comb must reach this fraction of the
// strongest line along the axis (content lines that happen to fit a comb are much weaker).
constexpr double kRelativeGapStrength = 0.3;
// A profile that correlates with itself this much at a short lag is a fine periodic pattern.
constexpr double kPeriodicCorrelation = 0.45;
constexpr double kPeriodicDip = 0.15;

struct Comb {
  std::vector<double> gaps;
  std::vector<double> z;
  double score = 0;
  double weakest = 0;
};

// Best comb of count-1 gaps for `count` tiles: offset and stretch searched, then each gap moved
// to its strongest evidence within the slack.
Comb FitComb(const BoundaryProfile& profile, int count) {
  const int size = profile.size();
  const double period = static_cast<double>(size) / count;
  const int slack = std::max(2, static_cast<int>(kGapSlackOfPeriod * period));
  Comb best;
  best.score = -1e30;
  const int max_offset = static_cast<int>(kCombOffsetOfPeriod * period);
  const int stretch_steps = count > 2 ? static_cast<int>(std::ceil(kCombStretch * period * (count - 1) / 2)) : 0;
  for (int st = -stretch_steps; st <= stretch_steps; ++st) {
    const double p = period * (1.0 + (stretch_steps == 0 ? 0.0 : kCombStretch * st / stretch_steps));
    for (int offset = -max_offset; offset <= max_offset; ++offset) {
      double score = 0;
      for (int k = 1; k < count; ++k) {
        const int x = static_cast<int>(std::lround(0.5 * size + (k - 0.5 * count) * p + offset));
        if (x < 1 || x >= size - 1) {
          score -= kZCap;
          continue;
        }
        score += std::min<double>(kZCap, profile.z[profile.ArgMaxZ(x - 2, x + 3)]);
      }
      if (score > best.score) {
        best.score = score;
        best.gaps.clear();
        for (int k = 1; k < count; ++k) best.gaps.push_back(0.5 * size + (k - 0.5 * count) * p + offset);
      }
    }
  }
  best.weakest = count > 1 ? 1e30 : 0;
  for (double& gap : best.gaps) {
    const int x = profile.ArgMaxZ(static_cast<int>(gap) - slack, static_cast<int>(gap) + slack + 1);
    gap = x;
    best.z.push_back(profile.z[x]);
    best.weakest = std::min<double>(best.weakest, profile.z[x]);
  }
  return best;
}

std::string Positions(const Comb& comb, const AxisSearch& search) {
  std::ostringstream out;
  for (size_t k = 0; k < comb.gaps.size(); ++k) {
    char text[64];
    std::snprintf(text,
                  sizeof(text),
                  "%s%c=%.0f (z %.1f)",
                  k ? ", " : "",
                  search.coordinate,
                  comb.gaps[k] * search.to_sensor,
                  comb.z[k]);
    out << text;
  }
  return out.str();
}

// The shortest lag at which the (clipped) evidence repeats strongly, or 0: the autocorrelation
// must first fall below kPeriodicDip (past the width of one line) and then peak above
// kPeriodicCorrelation.
int FinePeriod(const BoundaryProfile& profile, int max_lag) {
  const int size = profile.size();
  std::vector<double> v(size);
  double mean = 0;
  for (int x = 0; x < size; ++x) mean += v[x] = std::clamp<double>(profile.z[x], 0.0, kZCap);
  mean /= size;
  double var = 0;
  for (double& value : v) {
    value -= mean;
    var += value * value;
  }
  if (var <= 0) return 0;
  std::vector<double> c(max_lag + 2, 0.0);
  for (int lag = 1; lag <= max_lag + 1 && lag < size; ++lag) {
    double sum = 0;
    for (int x = 0; x + lag < size; ++x) sum += v[x] * v[x + lag];
    c[lag] = sum / (var * (size - lag) / size);
  }
  bool dipped = false;
  for (int lag = 2; lag <= max_lag && lag + 1 < static_cast<int>(c.size()); ++lag) {
    if (c[lag] < kPeriodicDip) dipped = true;
    if (dipped && c[lag] > kPeriodicCorrelation && c[lag] >= c[lag - 1] && c[lag] >= c[lag + 1]) return lag;
  }
  return 0;
}

// The grid of `comb`'s count - 1 gaps.
AxisGrid GridOfComb(const BoundaryProfile& profile, const Comb& comb) {
  AxisGrid grid;
  grid.count = static_cast<int>(comb.gaps.size()) + 1;
  grid.gaps = comb.gaps;
  grid.gap_z = comb.z;
  grid.weakest_z = comb.gaps.empty() ? 0 : comb.weakest;
  for (double gap : comb.gaps) {
    const int x = static_cast<int>(gap);
    grid.gap_polarity.push_back(profile.polarity[x]);
    grid.gap_half_width.push_back(profile.half_width[x]);
  }
  return grid;
}

}  // namespace

StatusOr<AxisGrids> FindAxisGrid(const BoundaryProfile& profile, const AxisSearch& search) {
  const int size = profile.size();
  std::vector<Comb> combs(search.max_count + 1);
  std::vector<int> passing;
  const double strongest = profile.z[profile.ArgMaxZ(0, size)];
  const double needed = std::max(search.min_z, kRelativeGapStrength * strongest);
  const int first = search.expected_count > 0 ? search.expected_count : 2;
  const int last = search.expected_count > 0 ? search.expected_count : search.max_count;
  for (int count = first; count <= last; ++count) {
    if (count < 2) continue;
    combs[count] = FitComb(profile, count);
    if (combs[count].weakest >= needed) passing.push_back(count);
  }
  AxisGrids grids;
  if (search.expected_count == 1) return AxisGrids{{AxisGrid{}}, ""};
  if (search.expected_count > 1 && passing.empty()) {
    return NotFoundError("no lattice with " + std::to_string(search.expected_count) + " " + search.axis_name +
                         ": the gaps at " + Positions(combs[search.expected_count], search) +
                         " do not all stand out (need z >= " + std::to_string(static_cast<int>(needed)) +
                         ", the strongest line's " + std::to_string(static_cast<int>(strongest)) + " x " +
                         std::to_string(kRelativeGapStrength).substr(0, 3) + ", at least " +
                         std::to_string(static_cast<int>(search.min_z)) + ")");
  }
  // A fine periodic pattern (a micro-lens array) passes combs by chance: refuse it outright.
  const int fine = FinePeriod(profile, std::max(4, size / (search.max_count + 1)));
  if (fine > 0) {
    char text[240];
    std::snprintf(text,
                  sizeof(text),
                  "no lattice: the frame repeats every %.0f px along %c (%d cells), finer than a lattice of at "
                  "most %d tiles per axis: a micro-lens (plenoptic) image?",
                  fine * search.to_sensor,
                  search.coordinate,
                  size / fine,
                  search.max_count);
    return NotFoundError(text);
  }
  if (passing.empty()) return AxisGrids{{AxisGrid{}}, ""};
  const int count = passing.back();
  // A smaller comb whose gaps are all gaps of the larger one is explained by it (a 2-comb catching
  // one gap of a 5x4 lattice); one with a gap the larger comb lacks makes the period ambiguous.
  const double slack = std::max(2.0, kGapSlackOfPeriod * size / count);
  auto explained = [&](const Comb& smaller) {
    for (double gap : smaller.gaps) {
      bool near = false;
      for (double g : combs[count].gaps) near = near || std::abs(g - gap) <= slack;
      if (!near) return false;
    }
    return true;
  };
  for (int other : passing) {
    if (count % other != 0 && !explained(combs[other])) {
      grids.ambiguity = "ambiguous period: the " + search.axis_name + " fit both " + std::to_string(other) +
                        " tiles (gaps at " + Positions(combs[other], search) + ") and " + std::to_string(count) + " (" +
                        Positions(combs[count], search) + ")";
      break;
    }
  }
  if (grids.ambiguity.empty()) return AxisGrids{{GridOfComb(profile, combs[count])}, ""};
  for (auto it = passing.rbegin(); it != passing.rend(); ++it)
    grids.candidates.push_back(GridOfComb(profile, combs[*it]));
  grids.candidates.push_back(AxisGrid{});
  return grids;
}

}  // namespace px::lattice
