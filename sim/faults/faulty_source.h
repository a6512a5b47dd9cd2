// A FrameSource that wraps any other and injects the faults of a plan (fault_spec.h) at the
// captures they name, deterministically (seeded). It passes everything else through, so the
// daemon and the pipeline meet exactly what a failing camera would hand them.
#pragma once

#include <memory>
#include <vector>

#include "drivers/source/frame_source.h"
#include "sim/faults/fault_spec.h"

namespace px {

// Checks the plan against what `inner` describes (a reorder needs an image set, a dropped tile
// a rig with that tile, ...) and wraps it. Errors name the fault: "faults[1]: reorder needs an
// image set; sim:sim-pop9 delivers lattice frames". An empty plan wraps too (faults pass nothing).
StatusOr<std::unique_ptr<FrameSource>> MakeFaultySource(std::unique_ptr<FrameSource> inner,
                                                        std::vector<FaultSpec> plan,
                                                        const std::string& field = "faults");

}  // namespace px
