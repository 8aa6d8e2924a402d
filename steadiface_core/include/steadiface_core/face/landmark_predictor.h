#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/common/model_cache.h"
#include "steadiface_core/common/status.h"

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
  /// a path that another live predictor already loaded is free, so a node
  /// can load it at start-up.
  ///
  /// dlib's file stores every float in a portable packed form that takes
  /// ~0.5 s to decode (the 68-point model: 100 MB). The decoded model is
  /// kept in `cache_dir` (created if needed; "" = no cache) as plain
  /// arrays, keyed by the model's path, size and modification time, and
  /// read from there next time (the same floats; the leaves, most of it,
  /// are mapped from the file rather than read, so a run pages in only
  /// those its fits reach; the file is only ever replaced whole). A missing,
  /// stale, foreign or damaged cache file is ignored and rewritten
  /// (atomically); a cache that cannot be written is not an error.
  static Status Load(const std::string& path,
                     std::unique_ptr<LandmarkPredictor>* out,
                     const std::string& cache_dir = DefaultModelCacheDir());

  /// Whether this predictor's model came from the cache (for tests and
  /// logs).
  bool loaded_from_cache() const { return from_cache_; }
  /// Whether the cache was read straight into the packed trees (the fast
  /// load: no dlib tree objects); false for a model file, or a cache whose
  /// trees are not all alike (for tests and logs).
  bool loaded_packed_from_cache() const { return packed_from_cache_; }

  /// Fits the 68 landmarks in `box` (full-image pixels) of `gray`.
  Status Predict(const cv::Mat& gray, const cv::Rect2d& box,
                 std::vector<Eigen::Vector2d>* landmarks) const;

  int num_parts() const;

  /// The model's mean shape (its initial shape), in the unit box
  /// coordinates of dlib ([0, 1] x [0, 1] over the detector box).
  std::vector<Eigen::Vector2d> MeanShape() const;

  /// The model (landmark_predictor_impl.h): internal, named here for the
  /// cache's tests.
  struct Impl;

 private:
  LandmarkPredictor();
  std::shared_ptr<const Impl> impl_;
  bool from_cache_ = false;
  bool packed_from_cache_ = false;
};

}  // namespace steadiface
