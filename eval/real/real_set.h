// Real multi-view captures as the product receives them, for `parallax eval real`: each set is an
// image set (one frame per view, upright, with the lens's focal length where the capture says it),
// posed later by the product's own calibration. Layouts read:
//  - a folder of photos (JPEG, PNG; ../shared/data/handheld, stereo_face, the Lytro 5x5), a 3D
//    camera's MPO file or a wigglegram's animated GIF or WebP (capture/import_images.h); a folder
//    is read as `parallax clip FOLDER` reads it (RecordingFromFolder);
//  - an LLFF folder (poses_bounds.npy, images_8/): the photos with the focal length the set's
//    metadata gives (a phone's EXIF would), its poses ignored;
//  - an HCI light field folder (parameters.cfg): its 3x3 of every 4th view (the 9x9's corners,
//    edge centres and centre, the widest Pop9-like lattice in it), with the focal length;
//  - one photo of a lattice of views (a film scan, a multi-lens frame): a lattice frame without a
//    rig calibration, its lattice found blind (or of the size given) and its tiles posed by
//    structure from motion, as `parallax clip FRAME.jpg` does.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/core/frame_set.h"
#include "pipeline/core/status.h"
#include "pipeline/lattice/lattice_options.h"

namespace px::eval {

struct RealSet {
  std::string name;  // "handheld/kpankov_office_4views": the path under the data folder
  std::filesystem::path path;
  std::string layout;                   // "photo folder", "LLFF", "HCI light field", "lattice photo", ...
  FrameSet capture;                     // kImageSet, frame i = view i; or kLatticeFrame, one photo
  LatticeOptions lattice;               // a lattice photo's: finding its lattice blind (tiles upright)
  std::vector<std::string> view_names;  // a file name per frame
  // The views held out in turn: every view of a set of up to 9; in larger sets every 8th
  // (LLFF's protocol: 0, 8, 16, ...), each still left out alone. Empty for a lattice photo, whose
  // views (tiles) are known once it is split: HeldOutViews of their number.
  std::vector<int> held_out;
};

// The real multi-view sets under `data_dir` that `parallax eval real` scores by default (those
// present; `missing` names the absent ones).
std::vector<std::filesystem::path> StandardRealSets(const std::filesystem::path& data_dir,
                                                    std::vector<std::string>* missing);

// Reads the set at `path` by its layout; `name` labels it; `lattice` ("auto" or "RxC") is the
// size of a lattice photo's lattice. Errors name the file and the reason: no such path, no
// images, an image that cannot be decoded.
StatusOr<RealSet> LoadRealSet(const std::filesystem::path& path,
                              const std::string& name,
                              const std::string& lattice = "auto");

// Which frames a set of `num_views` holds out (see RealSet::held_out).
std::vector<int> HeldOutViews(int num_views);

}  // namespace px::eval
