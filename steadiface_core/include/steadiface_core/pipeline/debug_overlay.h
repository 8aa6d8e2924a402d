#pragma once

#include "steadiface_core/warp/warper.h"

#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/face/face_types.h"
#include "steadiface_core/stabilizer/stabilizer.h"
#include "steadiface_core/warp/protrusion.h"

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

/// Layered warp: draws onto the debug image (input coordinates) the subject
/// region's outline (orange) and the band's inner and outer edges (blue),
/// each traced in the output and mapped into the input through the final
/// mesh, and a text line with the blend, the offsets and the worst cell.
void DrawLayeredOverlay(const WarpMesh& mesh, const SubjectRegion& region,
                        const LayerBlendReport& blend, int output_width, int output_height,
                        cv::Mat* out);

class Compositor;

/// Composite warp: draws onto the debug image (input coordinates) the
/// matte's outline (magenta; traced in the background layer's output and
/// mapped into the input through its mesh), the plate's age as an inset at
/// the top right (green where fresh, fading to black, black where never
/// seen), and a text line with the matte, the uncovered pixels and the
/// plate's and the fallback's shares.
void DrawCompositeOverlay(const WarpMesh& background_mesh, const Compositor& compositor,
                          cv::Mat* out);

}  // namespace steadiface
