// Options for choosing the virtual camera's move and path (paper section 4).
#pragma once

#include <cstdint>
#include <opencv2/core/types.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/direct/clip_timing.h"
#include "pipeline/direct/output_frame.h"

namespace px {

// Face detection on the reference view (OpenCV cascades, pipeline/direct/face_detector.h).
struct FaceDetectionOptions {
  bool enabled = true;        // false: no detection; only user regions are subjects
  double scale_factor = 1.1;  // detector pyramid step, (1, 2]; smaller finds more, slower
  // Overlapping raw detections a face needs, [1, 30]; more = fewer false faces. 5: the highest
  // precision at the recall of lower values (`parallax eval faces` on faces_dlib_pascalvoc).
  int min_neighbors = 5;
  int min_face_px = 20;  // smallest face side searched, pixels of the view, [8, 1024]
  // Views whose longer side is below this are upscaled to it for detection (Haar cascades miss
  // faces under ~24 px), pixels, [0, 4096]; 0 = never. 400: upscaling 500-640 px images makes
  // false faces (`parallax eval faces`, the two-face sim scene and the real photos) and finds no
  // more true ones; 320x240 views still are upscaled.
  int upscale_below_px = 400;
  bool profiles = true;  // also run the profile cascade, on the image and its mirror
  // Also search the frame padded out, for faces larger than it (FaceDetector::Detect); off where
  // the image searched is a window around a face of known size (face_confirmation.h).
  bool frame_filling = true;
  // When depth is known, a detection whose physical width at its median depth is outside this
  // range is not a face (textures that look like faces), metres, 0 < min < max.
  // Haar boxes of adult faces measure 0.14-0.22 m; 0.10 keeps children and rejects the
  // face-like patches the cascades find inside a photo's hair or clothes.
  double min_face_width_m = 0.10;
  double max_face_width_m = 0.45;
  int max_subjects = 2;  // the largest faces kept (paper: two), [0, 8]

  Status Validate() const;
};

// Valid-viewpoint search (4.2.1), parallax (4.2.2) and the lens search (4.3).
struct ViewpointSearchOptions {
  int grid_size = 12;             // grid cells per side at z = 0 (paper: 12), [2, 64]
  double grid_extent = 2.0;       // grid side / viewpoints' bounding box side (paper: 2), [1, 8]
  double valid_hole_score = 2.0;  // H(V) below which a viewpoint is valid (paper: 2, k = 3), (0, 1000]
  // Coverage is probed at this fraction of the output size (H is compensated, see
  // valid_viewpoints.h), (0, 1]: the search runs at search_scale, the chosen path is checked
  // frame by frame at verify_scale. The reduced-size estimate can read low for the segment
  // renderer's wide holes, so the chosen path is verified at the output size itself.
  double search_scale = 0.125;
  double verify_scale = 1.0;
  // The region search's probe: every splat_stride-th pixel of each view's depth splatted at
  // search_scale (pipeline/direct/splat_coverage.h, several times cheaper than the renderer's
  // Coverage); 0 = the renderer's Coverage at search_scale. [0, 64]. Off: the splat sees what
  // any view saw while the renderer blends the views nearest each ray, and it reads too many
  // viewpoints valid (direction_benchmark's BM_SearchProbeAgreement).
  int splat_stride = 0;
  int num_longest = 12;   // candidate paths whose parallax is measured (paper: 12), [1, 1000]
  int verify_frames = 9;  // frames along the chosen path checked at verify_scale, [2, 100]
  // z search: first step and the precision it stops at, as fractions of the median scene depth.
  double z_first_step = 0.05;  // (0, 1]
  double z_precision = 0.01;   // (0, z_first_step]
  // The camera never goes nearer to the scene than this fraction of the nearest depth in view
  // (5th percentile), nor farther back than max_back times the median depth. (0, 1), (0, 10].
  double max_forward = 0.6;
  double max_back = 1.0;
  // Nor so near what it aims at that it enlarges the capture's detail there more than this (the
  // move's zoom included; a clip smaller than the capture may enlarge as much more as it has
  // detail to spare): past twice, a real photo's frame shows its blur and every mismatch between
  // the views it blends at twice their size. [1, 16].
  double max_enlargement = 2.0;

  Status Validate() const;
};

struct DirectOptions {
  // The camera move (pipeline/direct/taxonomy.h): "auto" lets the scene decide; a move name
  // (establishing_dolly, establishing_dolly_out, dolly_in, dolly_out, dolly_zoom (either
  // direction), dolly_zoom_out, dolly_zoom_in, dolly) asks for it; "morph" and "pan_zoom_2d"
  // ask for the flat clips (pipeline/direct/view_morph.h, pan_zoom_2d.h).
  std::string move = "auto";
  // "auto" (none, a depth-of-field change or a focus pull, drawn), or an effect name: none,
  // dof_change, focus_pull, saturation, brightness, desaturate_background, dim_background.
  std::string effect = "auto";
  uint64_t seed = 1;        // draws the move and effect; the same seed gives the same clip
  double duration_s = 5.0;  // clip length in seconds, (0, 60]
  double fps = 30.0;        // frames per second, (0, 240]
  // How the clip plays the move: once (then an optional hold), loop or boomerang, eased
  // smoothly by default so the camera neither lurches off nor stops dead (clip_timing.h).
  ClipTiming timing;
  // The clip's size and aspect (output_frame.h); default: the centre view's.
  OutputFrameOptions output;
  // Subjects given by the user: rectangles (x, y, width, height) in pixels of `subject_view`
  // (-1 = the centre view). When any is given, face detection is not run.
  std::vector<cv::Rect2d> subject_boxes_px;
  int subject_view = -1;
  FaceDetectionOptions faces;
  ViewpointSearchOptions search;
  double zoom_in = 1.5;          // focal of a subject close-up / the capture's f (paper: 1.5), [1, 4]
  double framing_margin = 0.03;  // subjects stay this fraction of the width inside the frame, [0, 0.3]
  double max_dolly_zoom = 2.0;   // largest focal ratio across a dolly zoom, (1, 4]
  double max_aperture_m = 0.05;  // aperture search limit, metres, (0, 1]
  // Depth the pipeline may trust. Its geometry first: the fraction of pixels whose depth another
  // view confirms must reach min_consistent_fraction, [0, 1]. Real captures whose held-out views
  // the 3D render predicts well (eval real) measure 65-100 %; a hand-held pair of a person who
  // moved, a set whose poses are off, a film scan whose lenses fired in sequence, 35-46 %. Unlike
  // the confident fraction, it does not fall when depth is matched at a higher resolution.
  double min_consistent_fraction = 0.5;
  // And some of it must be confident: below this fraction of confident pixels over the views (or
  // in the reference view, or inside a subject's box) there is too little texture to hold a 3D
  // move, [0, 1]. Textureless walls are never confident: good real sets measure 17-87 %.
  double min_confident_fraction = 0.1;

  Status Validate() const;
};

// "auto", "dolly_zoom" and every taxonomy move, for Validate and help texts.
bool IsKnownMove(const std::string& move);
std::string KnownMovesText();  // "auto, establishing_dolly, ..."
std::string KnownEffectsText();

}  // namespace px
