// The face tracker's appearance checks: the face patch aligned on the
// eyes and mouth, its correlation with the locked face's, whole and by
// region (FaceTracker's members; face_tracker.cc has the rest).
#include "steadiface_core/face/face_tracker.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "steadiface_core/face/landmarks68.h"

namespace steadiface {
namespace {

// Normalized cross-correlation of two equal-sized CV_32F patches; 0 where
// either has no variance (a flat occluder).
double Ncc(const cv::Mat& pa, const cv::Mat& pb) {
  const cv::Mat a = pa - cv::mean(pa)[0];
  const cv::Mat b = pb - cv::mean(pb)[0];
  const double na = cv::norm(a), nb = cv::norm(b);
  return na > 1e-6 && nb > 1e-6 ? a.dot(b) / (na * nb) : 0.0;
}

// The aligned patch's parts that a hand covers one after another (fractions
// of its side; the eyes sit at 0.28/0.72 x 0.32, the mouth at 0.5 x 0.8).
struct FaceRegion {
  float x0, y0, x1, y1;
};
constexpr FaceRegion kFaceRegions[] = {{0.08f, 0.15f, 0.46f, 0.5f},   // right eye
                                       {0.54f, 0.15f, 0.92f, 0.5f},   // left eye
                                       {0.3f, 0.4f, 0.7f, 0.68f},     // nose
                                       {0.25f, 0.66f, 0.75f, 0.95f}};  // mouth

// Regions that differ by less than this from each other are not an
// occlusion (blur and turns lower them all).
constexpr double kRegionSpread = 0.35;

}  // namespace

bool FaceTracker::AlignedPatch(const cv::Mat& gray,
                               const std::vector<Eigen::Vector2d>& lm,
                               cv::Mat* patch, cv::Mat* A_out) const {
  if (lm.size() != landmarks68::kCount) return false;
  auto mean_of = [&lm](int a, int b) -> Eigen::Vector2d {
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (int i = a; i <= b; ++i) c += lm[i];
    return c / (b - a + 1);
  };
  namespace l68 = landmarks68;
  const Eigen::Vector2d eye_r = mean_of(l68::kRightEyeFirst, l68::kRightEyeLast),
                        eye_l = mean_of(l68::kLeftEyeFirst, l68::kLeftEyeLast),
                        mouth = mean_of(l68::kMouthFirst, l68::kMouthLast);
  const float P = static_cast<float>(options_.appearance_patch_px);
  const cv::Point2f src[3] = {cv::Point2f(eye_r.x(), eye_r.y()),
                              cv::Point2f(eye_l.x(), eye_l.y()),
                              cv::Point2f(mouth.x(), mouth.y())};
  const cv::Point2f dst[3] = {cv::Point2f(0.28f * P, 0.32f * P),
                              cv::Point2f(0.72f * P, 0.32f * P),
                              cv::Point2f(0.5f * P, 0.8f * P)};
  const cv::Mat A = cv::getAffineTransform(src, dst);
  if (cv::determinant(A(cv::Rect(0, 0, 2, 2))) == 0.0) return false;
  cv::Mat u8;
  cv::warpAffine(gray, u8, A, cv::Size(options_.appearance_patch_px,
                                        options_.appearance_patch_px),
                 cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  u8.convertTo(*patch, CV_32F);
  if (A_out != nullptr) *A_out = A;
  return true;
}

FaceFailure FaceTracker::CheckAppearance(const cv::Mat& gray, const Candidate& c, bool acquiring,
                                         FaceInfo* info, cv::Mat* patch, double* score_sum,
                                         int* n_scores) const {
  // The normalized correlation of the aligned patch with the locked face's
  // (not at acquisition); a passing check adds its score.
  // Each region (eyes, nose, mouth) is checked too: a hand over part of the
  // face leaves the whole patch's correlation passable while the landmarks
  // follow the hand; the covered region's correlation collapses.
  FaceFailure fail = FaceFailure::kNone;
  cv::Mat A;
  if (!AlignedPatch(gray, c.landmarks, patch, &A)) {
    fail = FaceFailure::kImplausibleShape;
  } else if (!acquiring && !reference_patch_.empty()) {
    info->appearance = Ncc(*patch, reference_patch_);
    info->region_appearance = RegionAppearance(*patch, A, gray.size());
    if (info->appearance < options_.min_appearance) {
      fail = FaceFailure::kAppearance;
    } else if (info->region_appearance < options_.min_region_appearance) {
      fail = FaceFailure::kOccluded;
    } else {
      *score_sum +=
          (info->appearance - options_.min_appearance) / (1.0 - options_.min_appearance);
      ++*n_scores;
    }
  } else {
    info->appearance = 1.0;
    info->region_appearance = 1.0;
  }
  return fail;
}

double FaceTracker::RegionAppearance(const cv::Mat& patch, const cv::Mat& A,
                                     const cv::Size& image) const {
  // The lowest correlation of the regions with the locked face's, over the
  // regions wholly inside the image (one beyond its edge is not seen, not
  // covered); 1 when none is, and 1 when the regions agree with each other
  // within kRegionSpread: a blurred or turned face lowers them all, an
  // occluder one or two.
  cv::Mat Ai;
  cv::invertAffineTransform(A, Ai);
  const float P = static_cast<float>(patch.cols);
  double lowest = 1.0, highest = -1.0;
  for (const FaceRegion& r : kFaceRegions) {
    const cv::Rect rc(cv::Point(static_cast<int>(r.x0 * P), static_cast<int>(r.y0 * P)),
                      cv::Point(static_cast<int>(r.x1 * P), static_cast<int>(r.y1 * P)));
    bool inside = true;
    for (const cv::Point& q : {rc.tl(), rc.br(), cv::Point(rc.x, rc.br().y),
                               cv::Point(rc.br().x, rc.y)}) {
      const double x = Ai.at<double>(0, 0) * q.x + Ai.at<double>(0, 1) * q.y + Ai.at<double>(0, 2);
      const double y = Ai.at<double>(1, 0) * q.x + Ai.at<double>(1, 1) * q.y + Ai.at<double>(1, 2);
      inside = inside && x >= 0.0 && y >= 0.0 && x <= image.width - 1.0 && y <= image.height - 1.0;
    }
    if (!inside) continue;
    const double ncc = Ncc(patch(rc), reference_patch_(rc));
    lowest = std::min(lowest, ncc);
    highest = std::max(highest, ncc);
  }
  return highest - lowest > kRegionSpread ? lowest : 1.0;
}

}  // namespace steadiface
