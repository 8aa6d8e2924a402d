#include "steadiface_core/face/landmark_predictor.h"

#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>

#include <dlib/opencv/cv_image.h>
#include <dlib/serialize.h>

#include "face/landmark_predictor_impl.h"
#include "steadiface_core/common/model_cache.h"
#include "steadiface_core/face/landmarks68.h"

namespace steadiface {

void LandmarkPredictor::Impl::Pack() {
  const size_t n = initial_shape.size();
  if (forests.empty() || forests[0].empty() || n == 0) return;
  trees = forests[0].size();
  splits_per_tree = forests[0][0].splits.size();
  leaves_per_tree = forests[0][0].leaf_values.size();
  if (leaves_per_tree != splits_per_tree + 1) return;
  for (const auto& forest : forests) {
    if (forest.size() != trees) return;
    for (const auto& tree : forest) {
      if (tree.splits.size() != splits_per_tree ||
          tree.leaf_values.size() != leaves_per_tree) {
        return;
      }
      for (const auto& leaf : tree.leaf_values) {
        if (static_cast<size_t>(leaf.size()) != n) return;
      }
      for (const auto& sp : tree.splits) {
        if (sp.idx1 > UINT32_MAX || sp.idx2 > UINT32_MAX) return;
      }
    }
  }
  if (!AllocateLeaves(forests.size() * trees * leaves_per_tree * n)) return;
  splits.reserve(forests.size() * trees * splits_per_tree);
  float* dst = owned_leaves;
  for (auto& forest : forests) {
    for (auto& tree : forest) {
      for (const auto& sp : tree.splits) {
        splits.push_back(Split{static_cast<uint32_t>(sp.idx1),
                               static_cast<uint32_t>(sp.idx2), sp.thresh});
      }
      for (const auto& leaf : tree.leaf_values) {
        std::memcpy(dst, &leaf(0), n * sizeof(float));
        dst += n;
      }
      // The packed copy is the one used: do not hold the model twice.
      tree.leaf_values.clear();
      tree.leaf_values.shrink_to_fit();
      tree.splits.clear();
      tree.splits.shrink_to_fit();
    }
  }
#ifdef __GLIBC__
  // dlib's 80 000 small leaf blocks are free now, but scattered through the
  // heap: glibc keeps such pages unless asked (~60 MB of RSS in the soak).
  malloc_trim(0);
#endif
}

LandmarkPredictor::LandmarkPredictor() = default;
LandmarkPredictor::~LandmarkPredictor() = default;

namespace {

using Impl = LandmarkPredictor::Impl;

constexpr char kModelHint[] =
    " (a one-time step that rosdep cannot do: on Debian or Ubuntu, "
    "'sudo apt-get install libdlib-data' puts the default model at "
    "/usr/share/dlib/shape_predictor_68_face_landmarks.dat; elsewhere, "
    "download shape_predictor_68_face_landmarks.dat.bz2 from dlib.net/files, "
    "bunzip2 it and set face/landmark_model to its path; "
    "or set landmark_source to 'none' for gyro-only stabilization)";

// Models this process has loaded, by path (shared while any predictor
// holds one).
struct ProcessCache {
  std::mutex mutex;
  std::map<std::string, std::weak_ptr<const Impl>> models;
};
ProcessCache& Loaded() {
  static ProcessCache cache;
  return cache;
}

std::shared_ptr<const Impl> FindLoaded(const std::string& path) {
  ProcessCache& c = Loaded();
  std::lock_guard<std::mutex> lock(c.mutex);
  const auto it = c.models.find(path);
  return it == c.models.end() ? nullptr : it->second.lock();
}

void RememberLoaded(const std::string& path, const std::shared_ptr<const Impl>& model) {
  ProcessCache& c = Loaded();
  std::lock_guard<std::mutex> lock(c.mutex);
  c.models[path] = model;
}

bool Consistent(const Impl& m) {
  return m.num_parts() == landmarks68::kCount && m.forests.size() == m.anchor_idx.size() &&
         m.forests.size() == m.deltas.size();
}

// The model from the disk cache: the packed form, else dlib's structures
// (packed and rewritten as the packed form). Null when neither is usable.
std::shared_ptr<Impl> FromDiskCache(const std::string& cache_dir, const std::string& cache_file,
                                    const LandmarkModelKey& key, bool* packed_from_cache) {
  auto impl = std::make_shared<Impl>();
  if (impl->ReadPackedCache(cache_file, key) && Consistent(*impl)) {
    *packed_from_cache = true;
    return impl;
  }
  // No packed cache (a plain one, a damaged one, or none): dlib's structures.
  impl = std::make_shared<Impl>();
  if (impl->ReadCache(cache_file, key) && Consistent(*impl) && !impl->forests.empty()) {
    impl->Pack();
    // A plain cache of a packable model (as older versions wrote): packed
    // from now on.
    if (impl->packed()) impl->WritePackedCache(cache_dir, cache_file, key);
    *packed_from_cache = false;
    return impl;
  }
  return nullptr;
}

// dlib's own serialization of a 68-point shape predictor.
Status ReadDlibModel(const std::string& path, Impl* m) {
  try {
    std::ifstream in(path, std::ios::binary);
    int version = 0;
    dlib::deserialize(version, in);
    if (version != 1) {
      throw dlib::serialization_error("unexpected shape_predictor version " +
                                      std::to_string(version));
    }
    dlib::deserialize(m->initial_shape, in);
    dlib::deserialize(m->forests, in);
    dlib::deserialize(m->anchor_idx, in);
    dlib::deserialize(m->deltas, in);
    if (m->forests.empty() || m->forests.size() != m->anchor_idx.size() ||
        m->forests.size() != m->deltas.size()) {
      throw dlib::serialization_error("inconsistent cascade sizes");
    }
  } catch (const std::exception& e) {
    return Status::Error("landmark model '" + path + "' is not a valid dlib shape predictor (" +
                         e.what() + ")" + kModelHint);
  }
  if (m->num_parts() != landmarks68::kCount) {
    return Status::Error("landmark model '" + path + "' predicts " +
                         std::to_string(m->num_parts()) +
                         " points; steadiface needs the 68-point model" + kModelHint);
  }
  return Status::Ok();
}

}  // namespace

Status LandmarkPredictor::Load(const std::string& path, std::unique_ptr<LandmarkPredictor>* out,
                               const std::string& cache_dir) {
  if (!std::ifstream(path, std::ios::binary).good()) {
    return Status::Error("landmark model '" + path + "' cannot be opened" + kModelHint);
  }
  std::unique_ptr<LandmarkPredictor> p(new LandmarkPredictor);
  if (std::shared_ptr<const Impl> shared = FindLoaded(path)) {
    p->impl_ = shared;
    *out = std::move(p);
    return Status::Ok();
  }
  LandmarkModelKey key;
  const bool cacheable = !cache_dir.empty() && StatLandmarkModel(path, &key);
  const std::string cache_file = cacheable ? LandmarkCacheFile(cache_dir, key) : std::string();
  bool packed_from_cache = false;
  std::shared_ptr<Impl> impl =
      cacheable ? FromDiskCache(cache_dir, cache_file, key, &packed_from_cache) : nullptr;
  const bool from_cache = impl != nullptr;
  if (!from_cache) {
    impl = std::make_shared<Impl>();
    const Status s = ReadDlibModel(path, impl.get());
    if (!s.ok()) return s;
    impl->Pack();
    if (cacheable && impl->packed()) {
      impl->WritePackedCache(cache_dir, cache_file, key);
    } else if (cacheable) {
      impl->WriteCache(cache_dir, cache_file, key);  // Pack() left dlib's trees
    }
  }
  // The process remembers it for the next Load of the same file.
  RememberLoaded(path, impl);
  p->impl_ = std::move(impl);
  p->from_cache_ = from_cache;
  p->packed_from_cache_ = packed_from_cache;
  *out = std::move(p);
  return Status::Ok();
}

int LandmarkPredictor::num_parts() const {
  return static_cast<int>(impl_->num_parts());
}

Status LandmarkPredictor::Predict(
    const cv::Mat& gray, const cv::Rect2d& box,
    std::vector<Eigen::Vector2d>* landmarks) const {
  if (gray.empty() || gray.type() != CV_8UC1) {
    return Status::Error("landmarks: need an 8-bit single-channel image");
  }
  if (!(box.width > 4 && box.height > 4)) {
    return Status::Error("landmarks: face box too small");
  }
  dlib::cv_image<unsigned char> img(gray);
  const dlib::rectangle r(
      static_cast<long>(std::lround(box.x)),
      static_cast<long>(std::lround(box.y)),
      static_cast<long>(std::lround(box.x + box.width - 1)),
      static_cast<long>(std::lround(box.y + box.height - 1)));
  const Impl& m = *impl_;
  dlib::matrix<float, 0, 1> shape = m.initial_shape;
  thread_local std::vector<float> features;
  thread_local std::vector<const float*> leaves;
  float* s = &shape(0);
  const long n = shape.size();
  const size_t line_floats = 64 / sizeof(float);
  constexpr size_t kAhead = 6;  // leaves prefetched ahead of the sum
  for (size_t iter = 0; iter < m.forests.size(); ++iter) {
    dlib::impl::extract_feature_pixel_values(img, r, shape, m.initial_shape,
                                             m.anchor_idx[iter], m.deltas[iter],
                                             features);
    // dlib's tree walks first (they read only the small split tables and
    // this cascade's features), then the leaves' sum in the same order as
    // dlib's (bit-identical), each leaf fetched from memory a few leaves
    // ahead: the ~4 MB of leaves a fit touches in the 65 MB model are what
    // the predictor waits on.
    if (m.packed()) {
      // dlib's regression_tree::operator() on the packed splits.
      const Impl::Split* sp = &m.splits[iter * m.trees * m.splits_per_tree];
      const float* lv = m.leaves + iter * m.trees * m.leaves_per_tree * n;
      const float* f = features.data();
      leaves.resize(m.trees);
      for (size_t t = 0; t < m.trees; ++t, sp += m.splits_per_tree) {
        size_t i = 0;
        while (i < m.splits_per_tree) {
          i = f[sp[i].idx1] - f[sp[i].idx2] > sp[i].thresh ? 2 * i + 1
                                                           : 2 * i + 2;
        }
        leaves[t] = lv + (t * m.leaves_per_tree + (i - m.splits_per_tree)) * n;
      }
    } else {
      const auto& forest = m.forests[iter];
      leaves.resize(forest.size());
      for (size_t i = 0; i < forest.size(); ++i) {
        unsigned long leaf = 0;
        leaves[i] = &forest[i](features, leaf)(0);
      }
    }
    auto prefetch = [&](size_t i) {
      for (long k = 0; k < n; k += static_cast<long>(line_floats)) {
        __builtin_prefetch(leaves[i] + k);
      }
    };
    for (size_t i = 0; i < std::min(kAhead, leaves.size()); ++i) prefetch(i);
    for (size_t i = 0; i < leaves.size(); ++i) {
      if (i + kAhead < leaves.size()) prefetch(i + kAhead);
      const float* v = leaves[i];
      for (long k = 0; k < n; ++k) s[k] += v[k];
    }
  }
  const dlib::point_transform_affine to_img =
      dlib::impl::unnormalizing_tform(r);
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
    const dlib::vector<float, 2> p =
        dlib::impl::location(impl_->initial_shape, i);
    out[i] = Eigen::Vector2d(p.x(), p.y());
  }
  return out;
}

}  // namespace steadiface
