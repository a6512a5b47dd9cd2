// H(V), the paper's hole metric (4.2.1), measured through the renderer's Coverage at a reduced
// size and expressed at the output size.
//
// Scaling. H = sum over hole pixels of d(p)^3 / (w h), d the distance to the nearest covered
// pixel. Rendered at scale s, every distance shrinks by s and the pixel count by s^2, as does
// w h, so H_s = s^3 H: the estimate at output size is H_s / s^3 = H_s (W / w)^3.
// Discretisation. That holds for holes many pixels wide. A thin hole (a border strip or crack a
// few output pixels wide) is at most one pixel wide at scale s, where its d is 1 although the
// hole's edge is only half a pixel away: at output size its pixels lie about (d - 0.5) / s + 0.5
// from the edge, not d / s. H_s / s^3 then over-reads thin holes by up to (2 / (1 + s))^3
// (1.0 at s = 1, 2.4 at 1/2, 4.1 at 1/4, 5.6 at 1/8). The estimate divides by that factor. It
// stays conservative for holes narrower than a reduced pixel (they read as a whole pixel or
// vanish); `parallax eval direction` prints how often reduced-size and full-size validity agree.
#pragma once

#include <deque>
#include <mutex>
#include <optional>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/coverage_report.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace px::direct {

// (2 / (1 + s))^3: how much H_s / s^3 over-reads a hole one reduced pixel wide.
double ThinHoleBias(double scale);

class CoverageProbe {
 public:
  // `coverage` must outlive the probe. `scale` in (0, 1]; `valid_hole_score` is the output-size
  // threshold (2 in the paper). `concurrent`: `coverage` may be called from several threads at
  // once (the splat and CpuSceneRenderer's Coverage may; a GL renderer's may not), so the search
  // may split its grid.
  CoverageProbe(const CoverageFunction* coverage, double scale, double valid_hole_score, bool concurrent = false)
      : coverage_(coverage), scale_(scale), valid_hole_score_(valid_hole_score), concurrent_(concurrent) {}

  // H(V) at the size of `output_camera` (a pinhole of the clip's size), estimated as above. The
  // last kRemembered answers are kept: a viewpoint asked for again (candidate paths share ends;
  // an end not pulled back is checked again after the other was) is not measured again.
  StatusOr<double> HoleScore(const CameraModel& output_camera, const Rigid3& cam_from_world);
  // HoleScore < valid_hole_score.
  StatusOr<bool> Valid(const CameraModel& output_camera, const Rigid3& cam_from_world);

  double scale() const { return scale_; }
  double valid_hole_score() const { return valid_hole_score_; }
  bool concurrent() const { return concurrent_; }
  int calls() const;  // coverage measurements made (answers remembered are not counted)
  double ms() const;  // summed over threads

 private:
  static constexpr size_t kRemembered = 32;
  struct Remembered {
    CameraModel camera;
    Rigid3 cam_from_world;
    double score = 0;
  };
  std::optional<double> Recall(const CameraModel& output_camera, const Rigid3& cam_from_world) const;

  const CoverageFunction* coverage_;
  double scale_;
  double valid_hole_score_;
  bool concurrent_;
  mutable std::mutex mutex_;  // guards the counters and the remembered answers
  int calls_ = 0;
  double ms_ = 0;
  std::deque<Remembered> remembered_;  // newest last
};

}  // namespace px::direct
