#pragma once

#include <vector>

#include <Eigen/Core>

namespace steadiface {

/// High-pass RMS of a 2D trajectory sampled at `fps` [Hz]: per axis, the
/// least-squares linear trend removed and the DFT bins under `cutoff_hz`
/// zeroed, then the RMS of what is left over both axes [the trajectory's
/// units]. 0 for fewer than 4 samples. The jitter measure of the
/// scorecard and of the bag tool's report.
double HighPassRms(const std::vector<Eigen::Vector2d>& x, double fps,
                   double cutoff_hz);

/// What HighPassRms takes the RMS of: the high-passed trajectory, per
/// sample (x's size; zeros for fewer than 4 samples).
std::vector<Eigen::Vector2d> HighPass(const std::vector<Eigen::Vector2d>& x,
                                      double fps, double cutoff_hz);

}  // namespace steadiface
