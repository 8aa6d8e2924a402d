#include "steadiface_core/face/landmark_predictor.h"

#include <fstream>
#include <map>
#include <mutex>

#include <dlib/image_processing/shape_predictor.h>
#include <dlib/opencv/cv_image.h>
#include <dlib/serialize.h>

namespace steadiface {

// The model's parts, read with dlib's own serialization. We run dlib's
// cascade ourselves (same code as dlib::shape_predictor::operator()) so the
// landmarks come out with sub-pixel precision; dlib's full_object_detection
// rounds every part to whole pixels.
struct LandmarkPredictor::Impl {
  dlib::matrix<float, 0, 1> initial_shape;
  std::vector<std::vector<dlib::impl::regression_tree>> forests;
  std::vector<std::vector<unsigned long>> anchor_idx;
  std::vector<std::vector<dlib::vector<float, 2>>> deltas;
  unsigned long num_parts() const { return initial_shape.size() / 2; }
};

LandmarkPredictor::LandmarkPredictor() = default;
LandmarkPredictor::~LandmarkPredictor() = default;

Status LandmarkPredictor::Load(const std::string& path,
                               std::unique_ptr<LandmarkPredictor>* out) {
  const std::string hint =
      " (the default model ships in Debian's libdlib-data package: "
      "apt-get install libdlib-data, or run scripts/install_deps)";
  std::ifstream probe(path, std::ios::binary);
  if (!probe.good()) {
    return Status::Error("landmark model '" + path + "' cannot be opened" +
                         hint);
  }
  probe.close();
  static std::mutex cache_mutex;
  static std::map<std::string, std::weak_ptr<const Impl>> cache;
  {
    std::lock_guard<std::mutex> lock(cache_mutex);
    auto it = cache.find(path);
    if (it != cache.end()) {
      if (std::shared_ptr<const Impl> shared = it->second.lock()) {
        std::unique_ptr<LandmarkPredictor> p(new LandmarkPredictor);
        p->impl_ = shared;
        *out = std::move(p);
        return Status::Ok();
      }
    }
  }
  std::unique_ptr<LandmarkPredictor> p(new LandmarkPredictor);
  auto impl = std::make_shared<Impl>();
  try {
    std::ifstream in(path, std::ios::binary);
    int version = 0;
    dlib::deserialize(version, in);
    if (version != 1) {
      throw dlib::serialization_error("unexpected shape_predictor version " +
                                      std::to_string(version));
    }
    Impl& m = *impl;
    dlib::deserialize(m.initial_shape, in);
    dlib::deserialize(m.forests, in);
    dlib::deserialize(m.anchor_idx, in);
    dlib::deserialize(m.deltas, in);
    if (m.forests.empty() || m.forests.size() != m.anchor_idx.size() ||
        m.forests.size() != m.deltas.size()) {
      throw dlib::serialization_error("inconsistent cascade sizes");
    }
  } catch (const std::exception& e) {
    return Status::Error("landmark model '" + path +
                         "' is not a valid dlib shape predictor (" + e.what() +
                         ")" + hint);
  }
  if (impl->num_parts() != 68) {
    return Status::Error("landmark model '" + path + "' predicts " +
                         std::to_string(impl->num_parts()) +
                         " points; steadiface needs the 68-point model" + hint);
  }
  p->impl_ = impl;
  {
    std::lock_guard<std::mutex> lock(cache_mutex);
    cache[path] = impl;
  }
  *out = std::move(p);
  return Status::Ok();
}

int LandmarkPredictor::num_parts() const {
  return static_cast<int>(impl_->num_parts());
}

Status LandmarkPredictor::Predict(const cv::Mat& gray, const cv::Rect2d& box,
                                  std::vector<Eigen::Vector2d>* landmarks) const {
  if (gray.empty() || gray.type() != CV_8UC1) {
    return Status::Error("landmarks: need an 8-bit single-channel image");
  }
  if (!(box.width > 4 && box.height > 4)) {
    return Status::Error("landmarks: face box too small");
  }
  dlib::cv_image<unsigned char> img(gray);
  const dlib::rectangle r(static_cast<long>(std::lround(box.x)),
                          static_cast<long>(std::lround(box.y)),
                          static_cast<long>(std::lround(box.x + box.width - 1)),
                          static_cast<long>(std::lround(box.y + box.height - 1)));
  const Impl& m = *impl_;
  dlib::matrix<float, 0, 1> shape = m.initial_shape;
  std::vector<float> features;
  for (size_t iter = 0; iter < m.forests.size(); ++iter) {
    dlib::impl::extract_feature_pixel_values(img, r, shape, m.initial_shape,
                                             m.anchor_idx[iter], m.deltas[iter],
                                             features);
    unsigned long leaf = 0;
    for (size_t i = 0; i < m.forests[iter].size(); ++i) {
      shape += m.forests[iter][i](features, leaf);
    }
  }
  const dlib::point_transform_affine to_img = dlib::impl::unnormalizing_tform(r);
  landmarks->resize(m.num_parts());
  for (unsigned long i = 0; i < m.num_parts(); ++i) {
    const dlib::dpoint p = to_img(dlib::impl::location(shape, i));
    (*landmarks)[i] = Eigen::Vector2d(p.x(), p.y());
  }
  return Status::Ok();
}

std::vector<Eigen::Vector2d> LandmarkPredictor::MeanShape() const {
  std::vector<Eigen::Vector2d> out(impl_->num_parts());
  for (unsigned long i = 0; i < impl_->num_parts(); ++i) {
    const dlib::vector<float, 2> p = dlib::impl::location(impl_->initial_shape, i);
    out[i] = Eigen::Vector2d(p.x(), p.y());
  }
  return out;
}

}  // namespace steadiface
