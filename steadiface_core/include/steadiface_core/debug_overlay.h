#pragma once

#include <opencv2/core.hpp>

#include "steadiface_core/camera_model.h"
#include "steadiface_core/face/face_types.h"
#include "steadiface_core/protrusion.h"
#include "steadiface_core/stabilizer/stabilizer.h"

namespace steadiface {

/// Renders the debug image on a copy of the input frame (8-bit, 1/3/4
/// channels; the output is BGR): the 68 landmarks (green), the landmark
/// centre C (yellow cross), the target head centre H mapped back into the
/// input (magenta circle), the output crop window's footprint in the input
/// (cyan polygon, red where it leaves the frame), and a text block with the
/// tracking state, confidence, w_f in effect and the stabilizer's flags.
/// `face` and `frame` may be null.
void DrawDebugOverlay(const cv::Mat& input, const CameraModel& model,
                      const ProtrusionGeometry& protrusion,
                      const FaceInfo* face, const StabilizerFrame* frame,
                      cv::Mat* out);

}  // namespace steadiface
