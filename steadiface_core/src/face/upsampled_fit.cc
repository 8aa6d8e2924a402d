#include "steadiface_core/face/upsampled_fit.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace steadiface {

Status FitLandmarksUpsampled(const LandmarkPredictor& predictor,
                             const cv::Mat& gray, const cv::Rect2d& box,
                             double min_box_px,
                             std::vector<Eigen::Vector2d>* landmarks) {
  if (!(min_box_px > 0.0) || !(box.width > 0.0) || box.width >= min_box_px ||
      gray.empty() || gray.type() != CV_8UC1) {
    return predictor.Predict(gray, box, landmarks);
  }
  // The trees' features reach a little beyond the box; half a box on each
  // side holds them.
  const cv::Rect2d around(box.x - 0.5 * box.width, box.y - 0.5 * box.height,
                          2.0 * box.width, 2.0 * box.height);
  const cv::Rect crop =
      cv::Rect(cv::Point(static_cast<int>(std::floor(around.x)),
                         static_cast<int>(std::floor(around.y))),
               cv::Point(static_cast<int>(std::ceil(around.br().x)),
                         static_cast<int>(std::ceil(around.br().y)))) &
      cv::Rect(0, 0, gray.cols, gray.rows);
  if (crop.width < 2 || crop.height < 2)
    return predictor.Predict(gray, box, landmarks);
  const double f = min_box_px / box.width;
  cv::Mat up;
  cv::resize(gray(crop), up, cv::Size(), f, f, cv::INTER_LINEAR);
  // cv::resize maps source pixel x to (x + 0.5) f - 0.5 in the copy.
  auto to_up = [&](double x, int origin) {
    return (x - origin + 0.5) * f - 0.5;
  };
  const cv::Rect2d up_box(to_up(box.x, crop.x), to_up(box.y, crop.y),
                          box.width * f, box.height * f);
  Status s = predictor.Predict(up, up_box, landmarks);
  if (!s.ok()) return s;
  for (Eigen::Vector2d& p : *landmarks) {
    p = Eigen::Vector2d((p.x() + 0.5) / f - 0.5 + crop.x,
                        (p.y() + 0.5) / f - 0.5 + crop.y);
  }
  return Status::Ok();
}

}  // namespace steadiface
