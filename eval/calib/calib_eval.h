// `parallax eval calib`: calibration quality per data set. Lattice shots (simulated rigs whose
// lenses moved off the factory calibration) are evaluated before and after per-shot
// refinement; image sets (Middlebury templeSparseRing, the HCI central 3x3, LLFF fern,
// hand-held folders) through hand-held structure from motion. Poses are compared after a
// similarity alignment (pose_alignment.h) to the set's reference.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "eval/datasets/hci_light_field.h"
#include "pipeline/calib/incremental_sfm.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "sim/synthetic/sim_camera.h"

namespace px::eval {

struct CalibEvalRow {
  std::string set;        // "sim 3x3 perturbed (seed 3)", "hci_4dlf_antinous 3x3", ...
  std::string method;     // "factory", "refined", "sfm, focal from metadata", "sfm, self-calibrated"
  std::string reference;  // "exact", "COLMAP", "none"
  int views_total = 0;
  int views_registered = 0;
  bool has_reference = false;  // the error figures below are set
  double rotation_max_deg = 0;
  double rotation_mean_deg = 0;
  double centre_max_relative = 0;  // of the reference baseline (median nearest-neighbour distance)
  double focal_max_percent = 0;
  // Structure from motion: false when the focal length was self-calibrated from views without
  // rotation between them (focal_max_percent then measures nothing; "n/o" in the table).
  bool focal_observable = true;
  double max_view_rotation_deg = 0;  // largest rotation between two registered views (SfM)
  double rms_px = 0;                 // reprojection RMS
  double time_ms = 0;
  std::string note;  // fallback reason, failure, warnings
};

using EvalProgress = std::function<void(const std::string& message)>;

// A simulated lattice shot of `spec` whose lenses are perturbed by `perturb_seed`: two rows,
// the factory calibration and the refined one, against the true lenses.
StatusOr<std::vector<CalibEvalRow>> EvalSimulatedRig(const std::string& name,
                                                     const SimCameraSpec& spec,
                                                     uint64_t perturb_seed);

// Structure from motion on `images`; `reference` (one per image, or empty) gives the error
// figures, `reference_focal_px` (one per image, or empty) the focal error.
StatusOr<CalibEvalRow> EvalStructureFromMotion(const std::string& name,
                                               const std::string& method,
                                               const std::vector<calib::SfmImage>& images,
                                               const std::vector<Rigid3>& reference,
                                               const std::vector<double>& reference_focal_px,
                                               const std::string& reference_name,
                                               const calib::SfmOptions& options = {});

// The HCI views as photos with metadata: the focal length from parameters.cfg (as EXIF gives it
// for a photo) and each view's lens shift (principal point) from its `offset` (the focus plane's
// disparity) and the view's place in the grid (its file number), as a shift lens records it.
// No pose is given.
std::vector<calib::SfmImage> HciMetadataImages(const HciLightField& field, const std::vector<View>& views);

// SfM options for images whose intrinsics come from an exact calibration (not EXIF): the focal
// length is held to 0.1 %. On a grid of parallel cameras (HCI) focal length and depth are one
// ambiguity: images alone cannot fix the focal length, and a loose prior lets it trade with rotation.
calib::SfmOptions ExactIntrinsicsSfm();

// Every set of a data folder, by its layout: HCI (parameters.cfg: the central 3x3 with the
// intrinsics from parameters.cfg, and self-calibrated), LLFF (poses_bounds.npy), Middlebury multi-view (*_par.txt), a
// folder of photos (hand-held), or a folder of such folders (../shared/data itself, or data/handheld). Errors when
// `dir` holds none of these.
StatusOr<std::vector<CalibEvalRow>> EvalDataFolder(const std::filesystem::path& dir, const EvalProgress& progress);

}  // namespace px::eval
