// Options for stage 3, segment-based multi-view stereo (depth_stage.h). Every field has a
// default, a unit and a range; Validate() names the first bad field and its value.
#pragma once

#include <cstdint>

#include "pipeline/core/status.h"

namespace px {

// Plane-sweep matching of each reference view against its neighbours.
struct MatchingOptions {
  // Fronto-parallel planes, uniform in inverse depth. 0 = automatic: as many as make one plane
  // step move the farthest neighbour used by about plane_step_px at the working scale, capped
  // at max_planes. Else [2, 1024].
  int num_planes = 0;
  double plane_step_px = 1.0;  // (0, 8]
  int max_planes = 128;        // [2, 1024]
  // Neighbour views per reference view, nearest camera centres first. [1, 16] (the best-half
  // aggregation holds at most 16 costs per pixel); fewer are used when the shot has fewer (a 3x3
  // lattice uses its 8 others). 12: on the 5x4 lattice more neighbours cut the pixels off by
  // over 5 % and the errors near depth edges (`parallax eval depth`), and 12 is where the gain
  // still pays for the CPU (16 costs twice 8's).
  int num_neighbors = 12;
  // How many of those are spread out over the widest baselines and every direction instead of
  // taken nearest first (farthest-point sampling of camera centres, neighbour_views.h): wide
  // baselines pin depth down finer, the nearest keep occlusions small. Only matters when the
  // shot has more views than num_neighbors + 1 (a lattice, a light field). [0, 16], at most
  // num_neighbors of them are spread; 0 = all nearest. Off by default: on the 3x3 test rig
  // with 4 of 8 neighbours it made a view with exposure differences worse (the light-field
  // evaluation turns it on).
  int spread_neighbors = 0;
  // ZNCC window radius in pixels at the working scale: the window is (2r+1)^2. [1, 15].
  int window_radius_px = 2;
  // Guided-filter aggregation of each cost slice (cost-volume filtering): radius in pixels at
  // the working scale [0, 15] (0 = off), and the edge threshold eps in grey variance [1e-6, 1].
  // 2 (`parallax eval depth`): a wider filter blurs depth across edges; 2 scores better than 4
  // on every Middlebury pair's bad-1 and on the simulated lattices, slightly worse on ETH3D
  // (both still under the references). Light fields take 3 (eval/depth), their baselines being
  // finer.
  int cost_filter_radius_px = 2;
  double cost_filter_eps = 1e-4;
  // Grey standard deviation (images in [0, 1]) under which a window counts as textureless: its
  // cost is neutral and its confidence 0. [0, 0.5].
  double min_texture_stddev = 0.004;
  // Semi-global aggregation over the filtered cost volume (semi_global.h): 0 = off, 4 or 8
  // paths. Penalties in cost units ([0, 2]): a step of one plane between neighbouring pixels
  // (sgm_step_penalty, [0, 1]) and a larger jump (sgm_jump_penalty, [sgm_step_penalty, 2]; a
  // third of it across grey edges).
  int sgm_paths = 4;
  double sgm_step_penalty = 0.01;
  double sgm_jump_penalty = 0.12;
};

// Over-segmentation and a plane per segment.
struct SegmentOptions {
  // SLIC superpixel side in pixels at the working scale [4, 64], compactness [1, 100] (higher =
  // more regular, less edge-following) and k-means iterations [1, 20].
  int region_size_px = 10;
  double compactness = 10;
  int iterations = 5;
  // Pixels used in plane fits: confidence at least this [0, 1].
  double min_confidence = 0.2;
  // RANSAC inlier tolerance: disparity against the nearest neighbour, pixels at the working
  // scale (0, 8].
  double inlier_px = 0.25;
  int ransac_iterations = 40;  // [1, 1000]
  // A segment whose confident inliers cover less than this fraction of it takes a neighbour's
  // plane instead (chosen by matching cost). [0, 1].
  double min_support = 0.15;
  // Matching-cost margin (ZNCC cost units, [0, 1]) within which a farther neighbour plane is
  // preferred over a nearer one when assigning planes to unfitted segments.
  double propagation_cost_margin = 0.02;
  uint64_t random_seed = 1;
  // Coplanar groups (coplanar_groups.h): adjacent fitted segments take one plane fitted to all
  // of them where it keeps at least coplanar_keep_fraction ((0, 1]; 0 = off) of the confident
  // pixel weight each segment's own plane keeps within coplanar_tolerance_px (disparity against
  // the nearest neighbour at the working scale, (0, 8]). They keep one surface on one plane, so
  // that the close-ups a dolly in ends on show no steps between its segments (`parallax eval
  // render --group closeup`, about 1 dB); 0.85 and 0.95 score within 0.1 dB of 0.9.
  double coplanar_keep_fraction = 0.9;
  double coplanar_tolerance_px = 0.25;
  // Weak regions (weak_regions.h): touching propagated segments within weak_region_colour_lab of
  // each other in mean Lab (OpenCV's 8-bit scale, [0, 50]; 0 = off) take the one plane with the
  // lowest matching cost over the whole region, unless a member's own cost along it is worse than
  // along its plane by more than weak_region_cost_margin (cost units, [0, 1]). Keeps a plain desk
  // top on one plane instead of a chain of planes copied across it. Off by default: on the real
  // sets it lowers double images on the office and the photo booth but costs leave-one-out PSNR
  // (office 0.1 dB, photo booth 0.1 to 0.6 dB; pipeline/depth/README.md).
  double weak_region_colour_lab = 0;
  double weak_region_cost_margin = 0.02;
  // Segment-level PatchMatch after the fits (refine_segment_planes.h): in each of
  // refine_iterations sweeps ([0, 20], 0 = off) every segment tries its neighbours' planes and
  // refine_random_trials ([0, 20]) random changes of its own (depth at its centre by up to
  // refine_offset_px, each slope by up to refine_slope_px per pixel, halved at every trial;
  // disparity against the nearest neighbour at the working scale, (0, 8] and (0, 1]), and keeps
  // the plane with the lowest matching cost along it over the segment (the cost volume). Lets
  // well-matched planes spread over weakly textured surfaces. Off by default: it helps the light
  // fields' fine plane steps (HCI) but not the product's 1 px steps (worse on the simulated Pop9).
  int refine_iterations = 0;
  int refine_random_trials = 6;
  double refine_offset_px = 0.25;
  double refine_slope_px = 0.03;
  // Then segments steeper than slanted_min_slope_px (disparity px per pixel, [0, 1]; 0 = off)
  // are refined again by the same sweeps with the exact slanted cost (segment_match_cost.h: the
  // segment's pixels, and a ring of slanted_ring_px ([0, 8]) around it on the same surface,
  // carried through the plane into every neighbour), keeping within slanted_max_change_px
  // ((0, 8]) of their plane: the sweep's fronto-parallel windows are biased on steep slants (the
  // HCI floor), while the exact cost is noisier than the volume's on flat, weak texture and
  // fattens foreground edges if let jump. Needs refine_iterations > 0.
  double slanted_min_slope_px = 0;
  double slanted_max_change_px = 0.5;
  int slanted_ring_px = 2;
  // Two layers at depth edges: touching segments whose planes differ by more than
  // edge_disparity_px of disparity against the nearest neighbour (view resolution, (0, 64]) share
  // a soft band band_radius_px wide on each side ([1, 16], view resolution).
  double edge_disparity_px = 1.0;
  // 1 (a 3 px band): with the boundary matte, a narrower band mixes fewer pixels wrongly (eval
  // render and eval depth score better with 1 than with 2 on every set but HCI 3x3's BadPix.07).
  int band_radius_px = 1;
  // Coplanar groups' planes moved along the rays by up to this much disparity (view resolution,
  // against the nearest neighbour) to where the exact multi-view ZNCC over the group's interior
  // at view resolution is best (group_depth.h). [0, 4]; 0 = off.
  double group_depth_search_px = 0.1;
  // Depth-edge labels (edge_labels.h): pixels within edge_label_radius_px (view resolution) of a
  // depth edge take whichever adjacent segment's plane carries their colour most consistently
  // into the neighbour views (full resolution), with a Potts term of edge_label_smoothness per
  // differing 8-neighbour (colour levels). [0, 8]; 0 = the colour segmentation's boundaries.
  int edge_label_radius_px = 4;
  double edge_label_smoothness = 2;
  // The labels' colour cost leaves out the views where the candidate's point is hidden behind
  // the reference's own surfaces and averages the rest (edge_labels.h); false: the best half of
  // all views. A view that cannot see the candidate's point says nothing about its colour; with
  // it left out the close-ups and the Pop9's depth edges score better (eval render, eval depth),
  // for about 0.1 s more depth on 9 views.
  bool edge_label_visibility = true;
  // Pixels whose own matched depth lies within this many pixels of disparity (against the
  // nearest neighbour, view resolution) of their segment's plane keep it in depth_m instead of
  // the plane (outside the two-layer bands; pixel_depth_near_planes.h): the plane fit flattens
  // curved and steep surfaces, while pixels far off it are the matcher's outliers. [0, 64];
  // 0 = segment planes everywhere.
  // Only where matching ran at view resolution (working scale 1): below it the per-pixel depth
  // is no finer than the plane and blurs across depth edges when upsampled. Off by default: on
  // truly planar scenes (the synthetic test rigs) the plane is exact and the per-pixel depth
  // only adds noise; the light-field evaluation turns it on (curved, relief-rich scenes).
  double pixel_depth_tolerance_px = 0;
  // ... and only where its matching confidence is at least this ([0, 1]): unconfident pixels
  // (weak texture) take the plane, which sums the evidence of the whole segment.
  double pixel_depth_min_confidence = 0;
};

// Which option set the stage runs with (depth_mode.h).
enum class DepthMode {
  kAuto,        // the light-field set for a dense grid of views, these options otherwise
  kStandard,    // these options as given
  kLightField,  // LightFieldDepthOptions of these
};

struct DepthOptions {
  // kAuto: a shot of at least light_field_min_views views whose nearest neighbours lie at most
  // light_field_max_disparity_px apart over the whole depth range (median over views, view
  // resolution) is a light field (a plenoptic camera's sub-aperture views, an integral lens) and
  // gets LightFieldDepthOptions: its disparities are too small for matching at half resolution
  // in whole-pixel steps. 9 views: fewer leave sub-pixel matching too few neighbours to agree
  // on. 4 px: a Lytro's 5x5 (1.4 px) is a light field; the simulated 5x4 integral lens (6.3 px)
  // renders better with the standard set (`parallax eval render --data still_life`: 38.76 against
  // 38.70 dB), as do the Pop9 (26 px), hand-held sets and stereo pairs. [2, 1024] and (0, 64].
  DepthMode mode = DepthMode::kAuto;
  int light_field_min_views = 9;
  double light_field_max_disparity_px = 4;
  // Scene depth range swept, metres (z in the reference camera). 0 = not set: the caller fills
  // it from the rig's nominal range (WithDefaultDepthRange). When set: 0 < min < max.
  double min_depth_m = 0;
  double max_depth_m = 0;
  // Matching runs at this fraction of the view resolution; segments and layers are made at full
  // resolution. (0, 1].
  double working_scale = 0.5;
  // Small views match at a larger scale: the working scale is raised (up to 1) so that matching
  // runs on at least this many columns; hand-held photos reduced to 1000 px and 640x480 lattice
  // tiles halved have too few pixels for their windows at a fern's fronds or a face's outline.
  // [0, 4096]; 0 = working_scale as given.
  int min_working_width_px = 512;
  MatchingOptions matching;
  SegmentOptions segments;
  // Consistency between views: a pixel whose depth no other view confirms within this many
  // pixels of disparity (view resolution, (0, 16]) keeps half its confidence and counts as
  // unconfirmed in the report.
  double consistency_tolerance_px = 1.0;
  // Unconfirmed pixels also take, along their row, the farther of the confirmed depths on either
  // side in depth_m (fill_unconfirmed.h: occlusions filled from the background side; the segments
  // the renderer draws are unchanged). Needs at least two computed views.
  bool fill_unconfirmed = true;
  // Free space (free_space.h): a segment whose confidence is below free_space_max_confidence
  // ([0, 1]) and which most of the other views see through (they see a surface farther along
  // the same line of sight) takes an adjacent segment's plane that they confirm. false: off.
  bool free_space_replane = true;
  double free_space_max_confidence = 0.25;
  // A view whose median best matching cost over its textured pixels exceeds this ((0, 2]; 1 =
  // uncorrelated) matches none of its neighbours (another scene, a black or saturated frame): it
  // is reported and left out as a neighbour of the others. The cost is read before aggregation
  // (any cost_filter_radius_px). Measured: honest views 0.001-0.012 (synthetic rigs, exposure
  // differences included) and 0.02-0.095 (real: HCI, Middlebury, ETH3D, LLFF fern); views of
  // another scene 0.32 (depth_bad_input_test's random texture, 2 of 4 neighbours), 0.32-0.45
  // (real pairs of two scenes) and 0.59-0.68 (a real image in the HCI 3x3). 0.18 is about twice
  // the worst honest view and 1.8 times under the lowest view of another scene.
  double max_view_match_cost = 0.18;
  // ... and exceeds the shot's median view cost this many times: a view is told apart from the
  // others of its shot, so a shot whose views all match poorly (film-scan lenses differing in
  // exposure and vignetting, a subject moving between sequential exposures, a two-view pair) is
  // warned about and left to the consistency checks rather than thrown away whole. Measured:
  // honest real shots 0.05-0.43 with their views within 1.4x of each other; a view of another
  // scene 3.7x and more its shot's median. [1, 100].
  double view_match_outlier_ratio = 2.5;
  // Worker threads: 0 = OpenCV's default (all cores). [0, 256].
  int num_threads = 0;

  Status Validate() const;
  // A copy whose unset (0) depth bounds are taken from the rig's nominal range.
  DepthOptions WithDefaultDepthRange(double nominal_min_m, double nominal_max_m) const;
  bool HasDepthRange() const { return min_depth_m > 0 && max_depth_m > 0; }
};

// Our options for a light field (a dense grid such as HCI's 9x9): its disparities between
// neighbours are a few pixels, so match at full resolution with plane steps of 0.2 px (at most
// 64 planes), and use 16 of its many neighbours: the 4 nearest and 12 spread over the widest
// baselines (on the 9x9, the cross and the diagonals out to the grid's edge); segments of 24 px refined by
// segment-level PatchMatch, the steep ones against the exact slanted cost; a guided filter of radius 3; depth_m keeps
// the per-pixel depth within 1 px of the segment planes where its confidence is at least 0.2.
DepthOptions LightFieldDepthOptions(const DepthOptions& ours);

}  // namespace px
