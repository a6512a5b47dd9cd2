// Photos taken elsewhere (a phone, a camera's card, a 3D camera) as a recording: one image set, a
// frame per view, as the USB still camera's source would have delivered them (drivers/ptp):
// upright, full size, RGB888, with the lens's focal length from each JPEG's EXIF for structure
// from motion. A view per photo (JPEG, PNG), per image of a stereo camera's MPO file (mpo.h), or
// per frame of a wigglegram's animated GIF or WebP, its repeated frames left out
// (animation_frames.h).
#pragma once

#include <filesystem>
#include <vector>

#include "capture/recording.h"
#include "pipeline/core/status.h"

namespace px {

// The JPEG, PNG, MPO, GIF and WebP files among `inputs`: files as given (in that order), folders'
// images sorted by name. Errors: an input that does not exist, a file that is none of those by its
// name, a folder with no images.
StatusOr<std::vector<std::filesystem::path>> ListImages(const std::vector<std::filesystem::path>& inputs);

// The frames of every file, in order (sequence = index). Errors name the file: one that cannot be
// decoded (an MPO with a broken index, a damaged animation); fewer than 2 views in all (an image
// set needs two viewpoints). One JPEG or PNG alone holds views only as a lattice: it becomes
// RecordingFromLatticePhoto's recording, its lattice found blind, and `warnings` says so (a lone
// GIF or WebP is an animation: refused when it holds one frame). A JPEG whose EXIF cannot be
// read is imported with its focal length unknown (self-calibrated later), and `warnings` says so, as it does of
// repeated frames left out.
StatusOr<Recording> RecordingFromImages(const std::vector<std::filesystem::path>& files,
                                        std::vector<std::string>* warnings);

// A folder's images (ListImages) as one capture: RecordingFromImages, except that when two or
// more of its files hold several views each (MPO files, animations; a still GIF or WebP is a
// photo), each is a capture of its own, not views of one scene from one set of places (a
// wigglegram maker's rectified and raw versions of one shot, two stereo pairs): the first of them
// by name is taken alone and `warnings` names what is left out. A folder of one JPEG or PNG is a
// lattice photo, as in RecordingFromImages.
StatusOr<Recording> RecordingFromFolder(const std::filesystem::path& folder,
                                        const std::vector<std::filesystem::path>& files,
                                        std::vector<std::string>* warnings);

// One photo holding a lattice of views (a film scan of a Nishika, Nimslo, ActionSampler or Pop9
// frame; a frame from a multi-lens or "wiggle" lens; a side-by-side stereo JPEG) as a lattice-frame
// recording without a rig calibration: the photo upright (EXIF orientation), its focal length from
// EXIF, and `hint` (the lattice's size when known, 0 = found blind; its tiles upright) for the
// pipeline to split it. Errors name the file: missing, undecodable.
StatusOr<Recording> RecordingFromLatticePhoto(const std::filesystem::path& file,
                                              const LatticeHint& hint,
                                              std::vector<std::string>* warnings);

// Whether `file` is a still photo by its name, a JPEG or a PNG (any case): a file that alone holds
// views only as a lattice (RecordingFromLatticePhoto), where an MPO or an animation holds a view
// per image.
bool IsStillPhotoName(const std::filesystem::path& file);

// "auto" (0x0: found blind) or "RxC" (rows x columns, each 1..16, at least 2 tiles).
StatusOr<LatticeHint> ParseLatticeSize(const std::string& text);

}  // namespace px
