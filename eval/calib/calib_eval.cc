#include "eval/calib/calib_eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "eval/calib/pose_alignment.h"
#include "eval/calib/sim_lattice_shot.h"
#include "eval/datasets/hci_light_field.h"
#include "eval/datasets/image_folder.h"
#include "eval/datasets/llff.h"
#include "eval/datasets/middlebury_mview.h"
#include "pipeline/calib/rig_refinement.h"

namespace px::eval {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Fills the error figures of `row` from estimated and reference poses (and focal lengths).
Status SetErrors(const std::vector<Rigid3>& estimated,
                 const std::vector<Rigid3>& reference,
                 const std::vector<double>& estimated_focal,
                 const std::vector<double>& reference_focal,
                 CalibEvalRow* row) {
  if (estimated.size() < 2) return OkStatus();
  PX_ASSIGN_OR_RETURN(PoseErrors errors, ComparePoses(estimated, reference, estimated_focal, reference_focal));
  row->has_reference = true;
  row->rotation_max_deg = PoseErrors::Max(errors.rotation_deg);
  row->rotation_mean_deg = PoseErrors::Mean(errors.rotation_deg);
  row->centre_max_relative = PoseErrors::Max(errors.centre_relative);
  row->focal_max_percent = errors.focal_relative.empty() ? 0 : 100 * PoseErrors::Max(errors.focal_relative);
  return OkStatus();
}

std::vector<Rigid3> Poses(const RigCalibration& rig) {
  std::vector<Rigid3> poses;
  for (const LensCalibration& lens : rig.lenses) poses.push_back(lens.cam_from_rig);
  return poses;
}

std::vector<double> Focals(const RigCalibration& rig) {
  std::vector<double> focals;
  for (const LensCalibration& lens : rig.lenses) focals.push_back(lens.camera.fx);
  return focals;
}

std::vector<calib::SfmImage> ImagesOf(const std::vector<View>& views, bool known_intrinsics) {
  std::vector<calib::SfmImage> images;
  for (const View& view : views) {
    calib::SfmImage image;
    image.image = view.image;
    if (known_intrinsics) {
      image.intrinsics = view.camera;
      image.camera_id = view.id.value;  // exact per-view cameras (HCI's principal points differ)
    }
    images.push_back(image);
  }
  return images;
}

std::vector<Rigid3> PosesOf(const std::vector<View>& views) {
  std::vector<Rigid3> poses;
  for (const View& view : views) poses.push_back(view.cam_from_world);
  return poses;
}

std::vector<double> FocalsOf(const std::vector<View>& views) {
  std::vector<double> focals;
  for (const View& view : views) focals.push_back(view.camera.fx);
  return focals;
}

bool Exists(const fs::path& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

bool HasParFile(const fs::path& dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 8 && name.substr(name.size() - 8) == "_par.txt") return true;
  }
  return false;
}

// Rows of one folder of a known layout; an empty list when it has none.
StatusOr<std::vector<CalibEvalRow>> EvalOneFolder(const fs::path& dir, const EvalProgress& progress) {
  const std::string name = dir.filename().string();
  std::vector<CalibEvalRow> rows;
  const auto say = [&](const std::string& text) {
    if (progress) progress(name + ": " + text);
  };
  if (Exists(dir / "parameters.cfg")) {
    PX_ASSIGN_OR_RETURN(HciLightField field, LoadHciLightField(dir));
    const std::vector<View> grid = field.CentreGrid(1);
    // parameters.cfg is the lenses' configuration (a calibration, not a rounded EXIF focal
    // length): its focal length is held like one (ExactIntrinsicsSfm). The same cameras as the
    // loader's reference, which derives them from the same file.
    say("central 3x3, focal and lens shifts from parameters.cfg");
    PX_ASSIGN_OR_RETURN(CalibEvalRow metadata_row,
                        EvalStructureFromMotion(name + " 3x3",
                                                "sfm, intrinsics from metadata",
                                                HciMetadataImages(field, grid),
                                                PosesOf(grid),
                                                FocalsOf(grid),
                                                "exact",
                                                ExactIntrinsicsSfm()));
    rows.push_back(metadata_row);
    say("central 3x3, self-calibrated");
    PX_ASSIGN_OR_RETURN(
        CalibEvalRow row,
        EvalStructureFromMotion(
            name + " 3x3", "sfm, self-calibrated", ImagesOf(grid, false), PosesOf(grid), FocalsOf(grid), "exact"));
    rows.push_back(row);
  } else if (Exists(dir / "poses_bounds.npy")) {
    say("images_8, self-calibrated");
    PX_ASSIGN_OR_RETURN(LlffScene scene, LoadLlffScene(dir));
    PX_ASSIGN_OR_RETURN(CalibEvalRow row,
                        EvalStructureFromMotion(name,
                                                "sfm, self-calibrated",
                                                ImagesOf(scene.views, false),
                                                PosesOf(scene.views),
                                                FocalsOf(scene.views),
                                                "COLMAP"));
    rows.push_back(row);
  } else if (HasParFile(dir)) {
    say("ring, intrinsics known");
    PX_ASSIGN_OR_RETURN(std::vector<View> views, LoadMiddleburyMview(dir));
    PX_ASSIGN_OR_RETURN(CalibEvalRow row,
                        EvalStructureFromMotion(name,
                                                "sfm, intrinsics known",
                                                ImagesOf(views, true),
                                                PosesOf(views),
                                                FocalsOf(views),
                                                "exact",
                                                ExactIntrinsicsSfm()));
    rows.push_back(row);
  } else {
    StatusOr<std::vector<FolderImage>> images = LoadImageFolder(dir);
    if (!images.ok() || images->size() < 2) return rows;
    std::vector<calib::SfmImage> sfm_images;
    std::string focal_source;
    for (const FolderImage& image : *images) {
      calib::SfmImage sfm_image;
      sfm_image.image = image.bgr;
      if (image.focal_px > 0) {
        sfm_image.intrinsics = CameraModel::Pinhole(image.bgr.cols, image.bgr.rows, image.focal_px);
        focal_source = image.focal_source;
      }
      sfm_images.push_back(sfm_image);
    }
    say(focal_source.empty() ? "hand-held, self-calibrated" : "hand-held, focal from " + focal_source);
    PX_ASSIGN_OR_RETURN(
        CalibEvalRow row,
        EvalStructureFromMotion(
            name, focal_source.empty() ? "sfm, self-calibrated" : "sfm, EXIF focal", sfm_images, {}, {}, "none"));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

std::vector<calib::SfmImage> HciMetadataImages(const HciLightField& field, const std::vector<View>& views) {
  std::vector<calib::SfmImage> images;
  for (const View& view : views) {
    calib::SfmImage image;
    image.image = view.image;
    image.intrinsics = field.MetadataCamera(view.id.value, view.image.cols, view.image.rows);
    image.camera_id = view.id.value;  // each view's own lens shift
    images.push_back(image);
  }
  return images;
}

calib::SfmOptions ExactIntrinsicsSfm() {
  calib::SfmOptions options;
  options.metadata_focal_sigma_relative = 0.001;
  return options;
}

StatusOr<std::vector<CalibEvalRow>> EvalSimulatedRig(const std::string& name,
                                                     const SimCameraSpec& spec,
                                                     uint64_t perturb_seed) {
  PX_ASSIGN_OR_RETURN(LatticeShot shot, CaptureLatticeShot(RealisticSpec(spec, perturb_seed), "still_life"));
  const Clock::time_point start = Clock::now();
  PX_ASSIGN_OR_RETURN(calib::RigRefinementResult result,
                      calib::RefineRigCalibration(shot.tiles, shot.factory, calib::RigRefinementOptions()));
  const double ms = MsSince(start);
  const calib::RigRefinementReport& report = result.report;
  std::vector<CalibEvalRow> rows(2);
  for (int i = 0; i < 2; ++i) {
    CalibEvalRow& row = rows[i];
    const RigCalibration& rig = i == 0 ? shot.factory : result.rig;
    row.set = name;
    row.method = i == 0 ? "factory" : "refined";
    row.reference = "exact";
    row.views_total = row.views_registered = shot.factory.NumViews();
    row.rms_px = i == 0 ? report.rms_before_px : (report.refined ? report.rms_after_px : report.rms_before_px);
    row.time_ms = i == 0 ? 0 : ms;
    PX_RETURN_IF_ERROR(SetErrors(Poses(rig), Poses(shot.truth), Focals(rig), Focals(shot.truth), &row));
  }
  rows[1].note = report.refined ? "" : "kept the factory calibration: " + report.fallback_reason;
  for (const std::string& warning : report.warnings) rows[1].note += (rows[1].note.empty() ? "" : "; ") + warning;
  return rows;
}

StatusOr<CalibEvalRow> EvalStructureFromMotion(const std::string& name,
                                               const std::string& method,
                                               const std::vector<calib::SfmImage>& images,
                                               const std::vector<Rigid3>& reference,
                                               const std::vector<double>& reference_focal_px,
                                               const std::string& reference_name,
                                               const calib::SfmOptions& options) {
  CalibEvalRow row;
  row.set = name;
  row.method = method;
  row.reference = reference_name;
  row.views_total = static_cast<int>(images.size());
  const Clock::time_point start = Clock::now();
  PX_ASSIGN_OR_RETURN(calib::SfmResult result, calib::RunIncrementalSfm(images, options));
  row.time_ms = MsSince(start);
  const calib::SfmReport& report = result.report;
  row.views_registered = report.num_registered;
  row.rms_px = report.rms_px;
  row.focal_observable = report.focal_observable;
  row.max_view_rotation_deg = report.max_view_rotation_deg;
  row.note = report.success ? "" : report.failure;
  for (const std::string& warning : report.warnings) row.note += (row.note.empty() ? "" : "; ") + warning;
  if (!report.success || reference.size() != images.size()) return row;
  std::vector<Rigid3> estimated, wanted;
  std::vector<double> estimated_focal, wanted_focal;
  for (size_t i = 0; i < images.size(); ++i) {
    if (!result.views[i].registered) continue;
    estimated.push_back(result.views[i].cam_from_world);
    wanted.push_back(reference[i]);
    if (reference_focal_px.size() == images.size()) {
      estimated_focal.push_back(result.views[i].camera.fx);
      wanted_focal.push_back(reference_focal_px[i]);
    }
  }
  PX_RETURN_IF_ERROR(SetErrors(estimated, wanted, estimated_focal, wanted_focal, &row));
  return row;
}

StatusOr<std::vector<CalibEvalRow>> EvalDataFolder(const fs::path& dir, const EvalProgress& progress) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return NotFoundError(dir.string() + ": not a folder");
  PX_ASSIGN_OR_RETURN(std::vector<CalibEvalRow> rows, EvalOneFolder(dir, progress));
  if (!rows.empty()) return rows;
  // A folder of data sets: the known layouts among its subfolders, in name order.
  std::vector<fs::path> subfolders;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.is_directory()) subfolders.push_back(entry.path());
  }
  std::sort(subfolders.begin(), subfolders.end());
  for (const fs::path& sub : subfolders) {
    const std::string name = sub.filename().string();
    // ../shared/data holds sets of other kinds too: only those calibration is evaluated on.
    const bool is_data_root = Exists(dir / "SOURCES.md");
    if (is_data_root && name != "hci_4dlf_antinous" && name != "llff_fern" &&
        name != "middlebury_mview_templeSparseRing" && name != "handheld") {
      continue;
    }
    StatusOr<std::vector<CalibEvalRow>> sub_rows = EvalOneFolder(sub, progress);
    if (sub_rows.ok() && sub_rows->empty()) sub_rows = EvalDataFolder(sub, progress);
    if (!sub_rows.ok()) {
      if (progress) progress(name + ": skipped: " + sub_rows.status().ToString());
      continue;
    }
    rows.insert(rows.end(), sub_rows->begin(), sub_rows->end());
  }
  if (rows.empty()) {
    return NotFoundError(dir.string() +
                         ": no data set in a known layout (HCI parameters.cfg, LLFF poses_bounds.npy, "
                         "Middlebury *_par.txt, or a folder of photos)");
  }
  return rows;
}

}  // namespace px::eval
