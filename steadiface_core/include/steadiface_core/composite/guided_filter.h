#pragma once

#include <opencv2/core.hpp>

namespace steadiface {

/// The guided filter (He, Sun and Tang, "Guided Image Filtering", TPAMI
/// 2013, Eqs. 5-8): q = mean(a) I + mean(b) with a and b the least-squares
/// fit of p by a I + b in each (2r+1)^2 box. It refines a coarse matte `p`
/// at the edges that the guide `I` shows (hair, a collar) and keeps it soft
/// elsewhere. `guide` and `src` are CV_32FC1 of one size with values in
/// about [0, 1]; `radius` [px] and `eps` (the regularizer, in squared guide
/// units) as in the paper. Box sums by cv::boxFilter: O(1) per pixel.
void GuidedFilter(const cv::Mat& guide, const cv::Mat& src, int radius, double eps,
                  cv::Mat* out);

/// The filter's box-averaged linear coefficients, q = mean_a I + mean_b. The
/// fast guided filter (He and Sun, arXiv:1505.00996) computes them on a
/// subsampled guide and input and applies them, upsampled, to the
/// full-resolution guide.
void GuidedFilterCoefficients(const cv::Mat& guide, const cv::Mat& src, int radius, double eps,
                              cv::Mat* mean_a, cv::Mat* mean_b);

}  // namespace steadiface
