#include "eval/real/real_set.h"

#include <algorithm>
#include <cctype>
#include <opencv2/imgcodecs.hpp>

#include "capture/import_images.h"
#include "eval/datasets/hci_light_field.h"
#include "eval/datasets/npy.h"
#include "pipeline/core/pixel_format.h"

namespace px::eval {
namespace {

namespace fs = std::filesystem;

// Sets with more views than this hold out every 8th view instead of each in turn.
constexpr int kMaxViewsHeldOutEach = 9;
constexpr int kHoldOutEvery = 8;

Status AddFrame(
    const cv::Mat& bgr, double focal_px, const std::string& focal_source, const std::string& name, RealSet* set) {
  Frame frame;
  PX_ASSIGN_OR_RETURN(frame.image, FromBgr(bgr, PixelFormat::kRgb888));
  frame.sequence = set->capture.frames.size();
  frame.focal_length_px = focal_px;
  frame.focal_length_source = focal_source;
  set->capture.frames.push_back(std::move(frame));
  set->view_names.push_back(name);
  return OkStatus();
}

Status LoadPhotoFolder(const fs::path& path, RealSet* set) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  set->layout = fs::is_directory(path) ? "photo folder" : extension == ".mpo" ? "MPO file" : "animation";
  PX_ASSIGN_OR_RETURN(std::vector<fs::path> files, ListImages({path}));
  std::vector<std::string> warnings;
  // A folder is read as `parallax clip FOLDER` reads it: of several files each holding views
  // (a wigglegram maker's rectified and raw versions of one shot), only the first.
  PX_ASSIGN_OR_RETURN(
      Recording recording,
      fs::is_directory(path) ? RecordingFromFolder(path, files, &warnings) : RecordingFromImages(files, &warnings));
  set->capture = std::move(recording.frames);
  if (files.size() == set->capture.frames.size()) {
    for (const fs::path& file : files) set->view_names.push_back(file.filename().string());
  } else {  // views from inside a file
    for (size_t i = 0; i < set->capture.frames.size(); ++i) set->view_names.push_back("view " + std::to_string(i));
  }
  return OkStatus();
}

// LLFF: the photos of images_8/ with the focal length of poses_bounds.npy (H, W, f at full size).
Status LoadLlffPhotos(const fs::path& path, RealSet* set) {
  set->layout = "LLFF";
  PX_ASSIGN_OR_RETURN(NpyArray poses, ReadNpyFloat64(path / "poses_bounds.npy"));
  if (poses.shape.size() != 2 || poses.shape[1] != 17 || poses.shape[0] == 0) {
    return DataLossError((path / "poses_bounds.npy").string() + ": shape is not (N, 17)");
  }
  const double full_width = poses.values[1 * 5 + 4], full_focal = poses.values[2 * 5 + 4];
  PX_ASSIGN_OR_RETURN(std::vector<fs::path> files, ListImages({path / "images_8"}));
  for (const fs::path& file : files) {
    cv::Mat bgr = cv::imread(file.string(), cv::IMREAD_COLOR);
    if (bgr.empty()) return DataLossError(file.string() + ": cannot be decoded as an image");
    if (!(full_width > 0 && full_focal > 0)) {
      return DataLossError((path / "poses_bounds.npy").string() + ": row 0 has no (H, W, f)");
    }
    PX_RETURN_IF_ERROR(AddFrame(
        bgr, full_focal * bgr.cols / full_width, "LLFF poses_bounds.npy focal length", file.filename().string(), set));
  }
  return OkStatus();
}

// HCI: the 3x3 of every 4th view of the 9x9 (corners, edge centres, centre), as photos.
Status LoadHciPhotos(const fs::path& path, RealSet* set) {
  set->layout = "HCI light field";
  PX_ASSIGN_OR_RETURN(HciLightField field, LoadHciLightField(path));
  const int step = std::max(1, (field.rows - 1) / 2);
  for (int r = 0; r < field.rows; r += step) {
    for (int c = 0; c < field.cols; c += step) {
      const View& view = field.views[static_cast<size_t>(r * field.cols + c)];
      char name[32];
      std::snprintf(name, sizeof(name), "input_Cam%03d.png", r * field.cols + c);
      PX_RETURN_IF_ERROR(AddFrame(view.image, field.focal_px, "HCI parameters.cfg focal length", name, set));
    }
  }
  return OkStatus();
}

bool IsSinglePhoto(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error) && IsStillPhotoName(path);
}

// `path` when it is one JPEG or PNG, or a folder's only image when that is one: a lattice photo
// (as parallax clip takes it); empty otherwise.
fs::path LonePhoto(const fs::path& path) {
  if (IsSinglePhoto(path)) return path;
  std::error_code error;
  if (!fs::is_directory(path, error)) return {};
  StatusOr<std::vector<fs::path>> files = ListImages({path});
  return files.ok() && files->size() == 1 && IsSinglePhoto(files->front()) ? files->front() : fs::path();
}

Status LoadLatticePhoto(const fs::path& path, const std::string& size, RealSet* set) {
  set->layout = "lattice photo";
  PX_ASSIGN_OR_RETURN(LatticeHint hint, ParseLatticeSize(size));
  std::vector<std::string> warnings;
  PX_ASSIGN_OR_RETURN(Recording recording, RecordingFromLatticePhoto(path, hint, &warnings));
  set->capture = std::move(recording.frames);
  set->lattice.rows = hint.rows;
  set->lattice.cols = hint.cols;
  set->lattice.orientation = hint.orientation;
  set->view_names = {path.filename().string()};
  return OkStatus();
}

}  // namespace

std::vector<int> HeldOutViews(int num_views) {
  std::vector<int> held_out;
  const int every = num_views > kMaxViewsHeldOutEach ? kHoldOutEvery : 1;
  for (int i = 0; i < num_views; i += every) held_out.push_back(i);
  return held_out;
}

std::vector<fs::path> StandardRealSets(const fs::path& data_dir, std::vector<std::string>* missing) {
  static const char* const kSets[] = {
      "handheld/kpankov_office_4views",
      "handheld/kpankov_frenchpress_4views",
      "handheld/ddd_lego_excavator_3views",
      "handheld/ddd_seattle_portrait_2views",
      "stereo_face/ddd_frame31_stereo",
      "llff_fern",
      "llff_flower",
      "hci_4dlf_antinous",
      "lytro_illum_2067_center5x5",
      "lattice_frames/nishika_n8000_scan_1x4/img_small.jpg",
      "lattice_frames/wigglelens_3view_plants/plants.jpg",
      "lattice_frames/actionsampler_2x2_face/imm000_0.jpg",
      "lattice_frames/raytrix_r42_lenslet_crop/sc2_klein.png",
      "multicam/actionsampler_onomichi_4frames/onomichi.gif",
      "multicam/photobooth_pi_4cam_person/wigglegram-example-charuco-calibrated.webp",
      "multicam/photobooth_pi_4cam_person/wigglegram-example-charuco-not-calibrated.webp",
      "mpo/nintendo3ds_mpo/sugarshack.mpo",
      "mpo/nintendo3ds_mpo/frozenpond.mpo",
      "mpo/nintendo3ds_mpo/3DS-big-endian.mpo",
      "mpo/panasonic_gx8_3dlens_mpo/Panasonic-DMC-GX8.mpo",
  };
  std::vector<fs::path> sets;
  for (const char* name : kSets) {
    const fs::path path = data_dir / name;
    std::error_code error;
    if (fs::exists(path, error)) {
      sets.push_back(path);
    } else if (missing != nullptr) {
      missing->push_back(path.string());
    }
  }
  return sets;
}

StatusOr<RealSet> LoadRealSet(const fs::path& path, const std::string& name, const std::string& lattice) {
  std::error_code error;
  if (!fs::exists(path, error)) return NotFoundError(path.string() + ": no such file or folder");
  RealSet set;
  set.name = name;
  set.path = path;
  set.capture.kind = FrameSetKind::kImageSet;
  if (fs::exists(path / "poses_bounds.npy", error)) {
    PX_RETURN_IF_ERROR(LoadLlffPhotos(path, &set));
  } else if (fs::exists(path / "parameters.cfg", error)) {
    PX_RETURN_IF_ERROR(LoadHciPhotos(path, &set));
  } else if (const fs::path photo = LonePhoto(path); !photo.empty()) {
    PX_RETURN_IF_ERROR(LoadLatticePhoto(photo, lattice, &set));
    return set;
  } else {
    PX_RETURN_IF_ERROR(LoadPhotoFolder(path, &set));
  }
  set.held_out = HeldOutViews(static_cast<int>(set.capture.frames.size()));
  return set;
}

}  // namespace px::eval
