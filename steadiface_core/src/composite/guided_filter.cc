#include "steadiface_core/composite/guided_filter.h"

#include <opencv2/imgproc.hpp>

namespace steadiface {

void GuidedFilterCoefficients(const cv::Mat& I, const cv::Mat& p, int radius, double eps,
                              cv::Mat* mean_a, cv::Mat* mean_b) {
  const cv::Size box(2 * radius + 1, 2 * radius + 1);
  auto mean = [&](const cv::Mat& m) {
    cv::Mat r;
    cv::boxFilter(m, r, CV_32F, box, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
    return r;
  };
  const cv::Mat mean_I = mean(I), mean_p = mean(p);
  const cv::Mat cov_Ip = mean(I.mul(p)) - mean_I.mul(mean_p);
  const cv::Mat var_I = mean(I.mul(I)) - mean_I.mul(mean_I);
  cv::Mat a;
  cv::divide(cov_Ip, var_I + eps, a);
  const cv::Mat b = mean_p - a.mul(mean_I);
  *mean_a = mean(a);
  *mean_b = mean(b);
}

void GuidedFilter(const cv::Mat& I, const cv::Mat& p, int radius, double eps, cv::Mat* out) {
  cv::Mat a, b;
  GuidedFilterCoefficients(I, p, radius, eps, &a, &b);
  *out = a.mul(I) + b;
}

}  // namespace steadiface
