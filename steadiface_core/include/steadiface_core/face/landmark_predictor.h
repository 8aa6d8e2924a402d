#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/status.h"

namespace steadiface {

/// Default model: Debian package libdlib-data.
constexpr const char* kDefaultShapePredictorPath =
    "/usr/share/dlib/shape_predictor_68_face_landmarks.dat";

/// dlib's 68-point shape predictor (an ensemble of regression trees), fitted
/// inside a face box, with sub-pixel output.
class LandmarkPredictor {
 public:
  ~LandmarkPredictor();
  /// Loads the model; a missing or corrupt file gives an error naming the
  /// file and the Debian package that ships it. Models are shared: loading
  /// a path that another live predictor already loaded is free (the ~100 MB
  /// model takes ~1 s to read), so a node can load it at start-up.
  static Status Load(const std::string& path,
                     std::unique_ptr<LandmarkPredictor>* out);

  /// Fits the 68 landmarks in `box` (full-image pixels) of `gray`.
  Status Predict(const cv::Mat& gray, const cv::Rect2d& box,
                 std::vector<Eigen::Vector2d>* landmarks) const;

  int num_parts() const;

  /// The model's mean shape (its initial shape), in the unit box
  /// coordinates of dlib ([0, 1] x [0, 1] over the detector box).
  std::vector<Eigen::Vector2d> MeanShape() const;

 private:
  LandmarkPredictor();
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace steadiface
