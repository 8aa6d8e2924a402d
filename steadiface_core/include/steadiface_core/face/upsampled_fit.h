#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/common/status.h"
#include "steadiface_core/face/landmark_predictor.h"

namespace steadiface {

/// Fits the landmarks in `box` of `gray` (full-image pixels), on a crop
/// around the box upsampled so that the box is `min_box_px` wide when it
/// is narrower. dlib's regression trees read single pixels and its box
/// snaps to whole pixels, so on a 30 px face both steps are a thirtieth of
/// the face; on the bilinear upsampled crop they are finer. Against the fit
/// at full size, faces 24-40 px wide fitted on a crop upsampled to 60 px
/// are about a fifth closer (small_face_test.cc); from about 45 px on the
/// gain is lost in the fit's own noise. Faces at least `min_box_px` wide
/// (or min_box_px <= 0) are fitted as they are.
Status FitLandmarksUpsampled(const LandmarkPredictor& predictor,
                             const cv::Mat& gray, const cv::Rect2d& box,
                             double min_box_px,
                             std::vector<Eigen::Vector2d>* landmarks);

}  // namespace steadiface
