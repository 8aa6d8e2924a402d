#include "steadiface_core/stabilizer/stabilizer_options.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace steadiface {
namespace {

// "key must be in [lo, hi], got v" or empty.
std::string Range(const char* key, double v, double lo, double hi) {
  if (std::isfinite(v) && v >= lo && v <= hi) return std::string();
  std::ostringstream err;
  err << key << " must be in [" << lo << ", " << hi << "], got " << v;
  return err.str();
}

Status First(std::initializer_list<std::string> checks) {
  for (const std::string& c : checks) {
    if (!c.empty()) return Status::Error(c);
  }
  return Status::Ok();
}

}  // namespace

double ProtrusionAlpha(const TermOptions& terms, double fit_weight, double nominal_fit) {
  const double share = nominal_fit > 0.0 && std::isfinite(fit_weight)
                           ? std::min(std::max(fit_weight / nominal_fit, 0.0), 1.0)
                           : 0.0;
  return terms.protrusion_alpha + share * (terms.protrusion_alpha_face - terms.protrusion_alpha);
}

Status ValidateStabilizerWeights(const StabilizerWeights& w) {
  return First({Range("weights.fit", w.fit, 0, 1e6),
                Range("weights.distortion", w.distortion, 0, 1e6),
                Range("weights.follow", w.follow, 0, 1e6),
                Range("weights.rotation_c0", w.rotation_c0, 0, 1e6),
                Range("weights.rotation_c1", w.rotation_c1, 0, 1e6),
                Range("weights.translation_c0", w.translation_c0, 1e-6, 1e6),
                Range("weights.translation_c1", w.translation_c1, 0, 1e6),
                Range("weights.protrusion", w.protrusion, 0, 1e6)});
}

Status ValidateStabilizerOptions(const StabilizerOptions& o) {
  Status s = ValidateHeadSmootherOptions(o.head);
  if (!s.ok()) return s;
  s = ValidateStabilizerWeights(o.weights);
  if (!s.ok()) return s;
  const TermOptions& t = o.terms;
  const DynamicWeightOptions& d = o.dynamic;
  s = First({
      Range("terms.distortion_threshold", t.distortion_threshold_rad, 0, 1.5),
      Range("terms.distortion_slope", t.distortion_slope, 1, 1e4),
      Range("terms.protrusion_alpha", t.protrusion_alpha, 1e-5, 1.0),
      Range("terms.protrusion_alpha_face", t.protrusion_alpha_face, 1e-5, 1.0),
      Range("terms.protrusion_shrink", t.protrusion_shrink, 0, 0.2),
      Range("terms.protrusion_samples_per_edge", t.protrusion_samples_per_edge,
            2, 256),
      Range("dynamic.fade_time", d.fade_time_s, 0, 10),
      Range("dynamic.handback_time", d.handback_time_s, 0, 10),
      Range("dynamic.gyro_window", d.gyro_window_s, 0.02, 10),
      Range("dynamic.gyro_still", d.gyro_still_rad_s, 0, 10),
      Range("dynamic.gyro_active", d.gyro_active_rad_s, d.gyro_still_rad_s + 1e-6, 20),
      Range("dynamic.gyro_still_fit_scale", d.gyro_still_fit_scale, 0, 1),
      Range("dynamic.pose_low", d.pose_low_rad, 0, 1.6),
      Range("dynamic.pose_high", d.pose_high_rad, d.pose_low_rad + 1e-6, 3.2),
      Range("dynamic.pose_min_fit_scale", d.pose_min_fit_scale, 0, 1),
      Range("dynamic.pose_smoothness_boost", d.pose_smoothness_boost, 0, 100),
      Range("dynamic.pose_pivot_depth", d.pose_pivot_depth, 0, 10),
      Range("dynamic.pose_yaw_time_constant", d.pose_yaw_time_constant_s, 0, 10),
      Range("dynamic.pose_yaw_speed_gain", d.pose_yaw_speed_gain, 0, 100),
      Range("dynamic.pose_yaw_speed_floor", d.pose_yaw_speed_floor_rad_s, 0, 20),
      Range("dynamic.pose_nod_gain", d.pose_nod_gain, 0, 2),
      Range("dynamic.pose_nod_time_constant", d.pose_nod_time_constant_s, 0.05, 60),
      Range("dynamic.pose_nod_max_yaw", d.pose_nod_max_yaw_rad, 0.01, 1.6),
      Range("dynamic.variation_window", d.variation_window, 3, 1000),
      Range("dynamic.centre_variation_low", d.centre_variation_low, 0, 1),
      Range("dynamic.centre_variation_high", d.centre_variation_high,
            d.centre_variation_low + 1e-9, 2),
      Range("dynamic.scale_variation_low", d.scale_variation_low, 0, 10),
      Range("dynamic.scale_variation_high", d.scale_variation_high,
            d.scale_variation_low + 1e-9, 20),
      Range("dynamic.variation_min_fit_scale", d.variation_min_fit_scale, 0, 1),
      Range("solver.max_iterations", o.solver.max_iterations, 1, 1000),
      Range("solver.function_tolerance", o.solver.function_tolerance, 1e-16, 0.1),
      Range("solver.gradient_tolerance", o.solver.gradient_tolerance, 1e-20, 0.1),
      Range("solver.max_time", o.solver.max_time_s, 1e-4, 10),
      Range("protrusion_search_steps", o.protrusion_search_steps, 1, 60),
      Range("row_rotation_samples", o.row_rotation_samples, 1, 4096),
      Range("min_face_confidence", o.min_face_confidence, 0, 1),
      Range("intentional_window", o.intentional_window_s, 0, 5),
      Range("subject_reach", o.subject_reach, 0, 10),
      Range("subject_reach_lowpass", o.subject_reach_lowpass_hz, 0, 10),
      Range("subject_reach_hold", o.subject_reach_hold, 0, 1),
  });
  return s;
}

}  // namespace steadiface
