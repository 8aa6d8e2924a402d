#include "steadiface_core/face/face_detector.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/revision.h>
#include <dlib/opencv/cv_image.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include "steadiface_core/common/model_cache.h"

namespace steadiface {
namespace {

// Detector boxes down to this fraction of min_face_px are kept.
constexpr double kBoxTolerance = 0.8;

// The copy of `roi` of `gray` the detector sees: scaled by `scale` if it
// is > 0 (area-averaged down, bilinear up), else shrunk so its longest
// side is <= max_side. Returns the scale applied.
double ScaledCopy(const cv::Mat& gray, const cv::Rect& roi, double scale, int max_side,
                  cv::Mat* out) {
  double s = scale;
  if (!(s > 0.0)) {
    const int longest = std::max(roi.width, roi.height);
    s = longest > max_side ? static_cast<double>(max_side) / longest : 1.0;
  }
  if (s < 1.0) {
    cv::resize(gray(roi), *out, cv::Size(), s, s, cv::INTER_AREA);
  } else if (s > 1.0) {
    cv::resize(gray(roi), *out, cv::Size(), s, s, cv::INTER_LINEAR);
  } else {
    *out = gray(roi);
  }
  return s;
}

void SortLargestFirst(std::vector<FaceBox>* faces) {
  std::stable_sort(faces->begin(), faces->end(),
                   [](const FaceBox& a, const FaceBox& b) {
                     return a.rect.area() > b.rect.area();
                   });
}

Status CheckInput(const cv::Mat& gray, const cv::Rect& roi) {
  if (gray.empty() || gray.type() != CV_8UC1) {
    return Status::Error("face detector: need a non-empty 8-bit gray image");
  }
  if ((roi & cv::Rect(0, 0, gray.cols, gray.rows)) != roi || roi.area() <= 0) {
    return Status::Error("face detector: region outside the image");
  }
  return Status::Ok();
}

// A box (x, y, w, h) found in the region scaled by s, in the frame's pixels.
FaceBox InFrame(const cv::Rect& roi, double s, double x, double y, double w, double h,
                double score) {
  FaceBox f;
  f.rect = cv::Rect2d(roi.x + x / s, roi.y + y / s, w / s, h / s);
  f.score = score;
  return f;
}

// dlib's frontal face detector ships compressed inside the library and
// takes ~0.35 s to decode; its dlib serialization reads in ~2 ms. The
// serialized copy is kept in the model cache (DefaultModelCacheDir()),
// keyed by dlib's version, behind a header with the payload's size and
// FNV-1a hash; anything that does not check out is decoded afresh and the
// cache rewritten.
dlib::frontal_face_detector LoadFrontalFaceDetector(const std::string& cache_dir) {
  static const char kMagic[] = "SFFDCACHE1";
  std::ostringstream name;
  name << cache_dir << "/frontal_face_detector_dlib" << DLIB_MAJOR_VERSION << "."
       << DLIB_MINOR_VERSION << "." << DLIB_PATCH_VERSION << ".sfcache";
  const std::string file = name.str();
  std::string bytes;
  if (!cache_dir.empty() && ReadWholeFile(file, &bytes)) {
    std::istringstream in(bytes);
    std::string magic;
    uint64_t size = 0, hash = 0;
    if (std::getline(in, magic) && magic == kMagic && in >> size >> hash &&
        in.get() == '\n') {
      const std::string payload = bytes.substr(static_cast<size_t>(in.tellg()));
      if (payload.size() == size && Fnv1a64(payload) == hash) {
        try {
          std::istringstream pin(payload);
          dlib::frontal_face_detector d;
          dlib::deserialize(d, pin);
          if (d.num_detectors() > 0) return d;
        } catch (const std::exception&) {
          // Decoded afresh below.
        }
      }
    }
  }
  dlib::frontal_face_detector d = dlib::get_frontal_face_detector();
  if (!cache_dir.empty() && MakeCacheDirs(cache_dir)) {
    std::ostringstream payload;
    dlib::serialize(d, payload);
    const std::string p = payload.str();
    std::ostringstream out;
    out << kMagic << "\n" << p.size() << " " << Fnv1a64(p) << "\n" << p;
    WriteFileAtomically(file, out.str());
  }
  return d;
}

// What both detectors share: the region scaled (at most max_side_px long),
// searched by DetectScaled, and the boxes sorted largest first.
class ScaledDetector : public FaceDetector {
 public:
  explicit ScaledDetector(const FaceDetectorOptions& o) : options_(o) {}

  Status Detect(const cv::Mat& gray, const cv::Rect& roi, std::vector<FaceBox>* faces,
                double scale) override {
    faces->clear();
    const Status st = CheckInput(gray, roi);
    if (!st.ok()) return st;
    cv::Mat small;
    const double s = ScaledCopy(gray, roi, scale, options_.max_side_px, &small);
    DetectScaled(small, roi, s, faces);
    SortLargestFirst(faces);
    return Status::Ok();
  }

 protected:
  // The faces in `small`, the region `roi` scaled by s, in the frame's pixels.
  virtual void DetectScaled(cv::Mat small, const cv::Rect& roi, double s,
                            std::vector<FaceBox>* faces) = 0;

  const FaceDetectorOptions options_;
};

class DlibHogDetector : public ScaledDetector {
 public:
  explicit DlibHogDetector(const FaceDetectorOptions& o)
      : ScaledDetector(o), detector_(LoadFrontalFaceDetector(DefaultModelCacheDir())) {}

  // dlib's HOG window is 80 px square; its boxes come out from ~70 px.
  double window_px() const override { return 75.0; }

 private:
  void DetectScaled(cv::Mat small, const cv::Rect& roi, double s,
                    std::vector<FaceBox>* faces) override {
    if (small.cols < 40 || small.rows < 40) return;
    if (!small.isContinuous()) small = small.clone();
    dlib::cv_image<unsigned char> img(small);
    std::vector<dlib::rect_detection> dets;
    detector_(img, dets, options_.dlib_threshold);
    for (const auto& d : dets) {
      const dlib::rectangle& r = d.rect;
      const FaceBox f =
          InFrame(roi, s, r.left(), r.top(), r.width(), r.height(), d.detection_confidence);
      // A box is a rough measure of the face (+-10 %): keep those that may
      // be min_face_px wide.
      if (f.rect.width >= kBoxTolerance * options_.min_face_px) faces->push_back(f);
    }
  }

  dlib::frontal_face_detector detector_;
};

class CascadeDetector : public ScaledDetector {
 public:
  explicit CascadeDetector(const FaceDetectorOptions& o) : ScaledDetector(o) {}
  bool Load() { return cascade_.load(options_.cascade_path); }

  // The frontal cascades' windows are 20-24 px.
  double window_px() const override { return 24.0; }

 private:
  void DetectScaled(cv::Mat small, const cv::Rect& roi, double s,
                    std::vector<FaceBox>* faces) override {
    std::vector<cv::Rect> rects;
    std::vector<int> neighbours;
    const int min_px = std::max(20, static_cast<int>(options_.min_face_px * s));
    cascade_.detectMultiScale(small, rects, neighbours, 1.1, 4, 0, cv::Size(min_px, min_px));
    for (size_t i = 0; i < rects.size(); ++i) {
      const cv::Rect& r = rects[i];
      faces->push_back(InFrame(roi, s, r.x, r.y, r.width, r.height,
                               i < neighbours.size() ? neighbours[i] : 0));
    }
  }

  cv::CascadeClassifier cascade_;
};

}  // namespace

Status ValidateFaceDetectorOptions(const FaceDetectorOptions& o) {
  std::ostringstream err;
  if (o.max_side_px < 64 || o.max_side_px > 8192) {
    err << "face.detector_max_side must be in [64, 8192] px, got "
        << o.max_side_px;
  } else if (!std::isfinite(o.dlib_threshold) || o.dlib_threshold < -2.0 ||
             o.dlib_threshold > 5.0) {
    err << "face.dlib_threshold must be in [-2, 5], got " << o.dlib_threshold;
  } else if (o.min_face_px < 8 || o.min_face_px > 4096) {
    err << "face.min_face_px must be in [8, 4096], got " << o.min_face_px;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

Status FaceDetector::Create(const FaceDetectorOptions& options,
                            std::unique_ptr<FaceDetector>* out) {
  Status s = ValidateFaceDetectorOptions(options);
  if (!s.ok()) return s;
  if (options.type == FaceDetectorType::kDlibHog) {
    out->reset(new DlibHogDetector(options));
    return Status::Ok();
  }
  std::unique_ptr<CascadeDetector> c(new CascadeDetector(options));
  if (!c->Load()) {
    return Status::Error("face cascade '" + options.cascade_path +
                         "' cannot be loaded (the ROS package ships OpenCV's frontal "
                         "face cascade as package://steadiface/data/"
                         "haarcascade_frontalface_default.xml; Debian's and "
                         "Ubuntu's opencv-data ship all of OpenCV's cascades)");
  }
  *out = std::move(c);
  return Status::Ok();
}

}  // namespace steadiface
