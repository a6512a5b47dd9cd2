// Framing rules shared by every move (3D and the flat fallback): subjects stay wholly inside the
// frame with a margin, and their projected size is measured the same way everywhere.
#pragma once

#include <vector>

#include "pipeline/core/camera_model.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/direct/subject.h"

namespace px::direct {

// The largest focal length (output pixels; fy follows with the camera's aspect) at which every
// corner of every subject projects inside `camera`'s frame at least `margin_px` from each edge,
// seen from `cam_from_world`. The camera's own focal is ignored; its size, principal point and
// aspect are used. +infinity without subjects; 0 when a corner is behind the camera or the
// principal point leaves no room on its side.
double MaxFocalKeepingInside(const std::vector<Subject>& subjects,
                             const CameraModel& camera,
                             const Rigid3& cam_from_world,
                             double margin_px);

// Every corner of every subject inside the frame, at least `margin_px` from each edge.
bool SubjectsInside(const std::vector<Subject>& subjects,
                    const CameraModel& camera,
                    const Rigid3& cam_from_world,
                    double margin_px);

// Projected height in pixels of a subject: the distance between the images of the midpoints of
// its top and bottom edges. 0 when either is behind the camera.
double ProjectedHeightPx(const Subject& subject, const CameraModel& camera, const Rigid3& cam_from_world);

// Depth of the subject's centre along the camera's optical axis (metres), for focus.
double SubjectDepthIn(const Subject& subject, const Rigid3& cam_from_world);

}  // namespace px::direct
