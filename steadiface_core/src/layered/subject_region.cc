#include "steadiface_core/layered/subject_region.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "steadiface_core/face/landmarks68.h"

namespace steadiface {
namespace {

// Signed distance to an axis-aligned ellipse, approximated by the radial
// distance in the unit circle scaled by the smaller half-axis.
double EllipseDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& c,
                       const Eigen::Vector2d& axes) {
  const Eigen::Vector2d q((p.x() - c.x()) / axes.x(),
                          (p.y() - c.y()) / axes.y());
  return (q.norm() - 1.0) * std::min(axes.x(), axes.y());
}

// Signed distance to an axis-aligned box [x0, x1] x [y0, y1].
double BoxDistance(const Eigen::Vector2d& p, double x0, double x1, double y0,
                   double y1) {
  const double dx = std::max(x0 - p.x(), p.x() - x1);
  const double dy = std::max(y0 - p.y(), p.y() - y1);
  const double outside = std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
  return outside + std::min(std::max(dx, dy), 0.0);
}

using landmarks68::kBrowFirst;
using landmarks68::kBrowLast;
using landmarks68::kChin;
using landmarks68::kJawFirst;
using landmarks68::kJawLast;

}  // namespace

Status ValidateSubjectRegionOptions(const SubjectRegionOptions& o) {
  std::ostringstream err;
  auto in = [](double v, double lo, double hi) {
    return std::isfinite(v) && v >= lo && v <= hi;
  };
  if (!in(o.head_width_scale, 0.2, 5.0) || !in(o.head_top_scale, 0.0, 3.0)) {
    err << "warp.layered: head_width_scale must be in [0.2, 5] and "
           "head_top_scale in [0, 3]";
  } else if (!in(o.shoulder_width_scale, 0.2, 10.0) ||
             !in(o.neck_width_scale, 0.05, 5.0)) {
    err << "warp.layered: shoulder_width_scale must be in [0.2, 10] and "
           "neck_width_scale in "
           "[0.05, 5]";
  } else if (!in(o.smoothing_s, 0.0, 10.0) || !in(o.ramp_s, 0.01, 60.0)) {
    err << "warp.layered: region smoothing_s must be in [0, 10] s and ramp_s "
           "in [0.01, 60] s";
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

double SubjectRegion::SignedDistance(const Eigen::Vector2d& p) const {
  double d = EllipseDistance(p, head_centre, head_axes);
  if (torso) {
    d = std::min(
        d, BoxDistance(p, chin.x() - neck_half_width,
                       chin.x() + neck_half_width, chin.y() - 0.3 * face_height,
                       chin.y() + 1.0 * face_height));
    d = std::min(d, EllipseDistance(p, shoulder_centre, shoulder_axes));
  }
  return d;
}

void SubjectRegion::GridDistances(const std::vector<double>& u, const std::vector<double>& v,
                                  std::vector<double>* sd) const {
  sd->assign(u.size() * v.size(), 0.0);
  if (u.size() < 2 || v.size() < 2) return;
  const double cell = std::min((u.back() - u.front()) / (u.size() - 1),
                               (v.back() - v.front()) / (v.size() - 1));
  const double res = std::max(0.25, 0.25 * cell), pad = cell;
  const double x0 = u.front() - pad, y0 = v.front() - pad;
  const int w = static_cast<int>(std::ceil((u.back() - u.front() + 2 * pad) / res)) + 2;
  const int h = static_cast<int>(std::ceil((v.back() - v.front() + 2 * pad) / res)) + 2;
  // The region's union on the raster (sub-pixel placement: 4 fractional
  // bits), raster pixel (i, j) centred at output (x0 + i res, y0 + j res).
  constexpr int kShift = 4;
  auto fx = [&](double x) { return static_cast<int>(std::lround((x - x0) / res * (1 << kShift))); };
  auto fy = [&](double y) { return static_cast<int>(std::lround((y - y0) / res * (1 << kShift))); };
  auto fl = [&](double l) { return static_cast<int>(std::lround(l / res * (1 << kShift))); };
  cv::Mat mask(h, w, CV_8U, cv::Scalar(0)), depth;
  auto ellipse = [&](const Eigen::Vector2d& c, const Eigen::Vector2d& a) {
    cv::ellipse(mask, cv::Point(fx(c.x()), fy(c.y())), cv::Size(fl(a.x()), fl(a.y())), 0.0, 0.0,
                360.0, cv::Scalar(255), cv::FILLED, cv::LINE_8, kShift);
  };
  ellipse(head_centre, head_axes);
  if (torso) {
    cv::rectangle(mask, cv::Point(fx(chin.x() - neck_half_width), fy(chin.y() - 0.3 * face_height)),
                  cv::Point(fx(chin.x() + neck_half_width), fy(chin.y() + 1.0 * face_height)),
                  cv::Scalar(255), cv::FILLED, cv::LINE_8, kShift);
    ellipse(shoulder_centre, shoulder_axes);
  }
  // Depth inside (5x5 chamfer: within 2 % of the Euclidean distance); a
  // pixel next to the outline is half a pixel from it.
  cv::distanceTransform(mask, depth, cv::DIST_L2, cv::DIST_MASK_5);
  auto at = [&](int i, int j) {
    const float d = depth.at<float>(std::min(std::max(j, 0), h - 1), std::min(std::max(i, 0), w - 1));
    return d > 0.0f ? d - 0.5 : 0.0;
  };
  for (size_t j = 0; j < v.size(); ++j) {
    for (size_t i = 0; i < u.size(); ++i) {
      const Eigen::Vector2d p(u[i], v[j]);
      // Outside, SignedDistance is right (the nearest shape's distance);
      // inside it is a lower bound on the depth.
      const double analytic = SignedDistance(p);
      double& out = (*sd)[j * u.size() + i];
      out = analytic;
      if (analytic > 0.0) continue;
      const double px = (u[i] - x0) / res, py = (v[j] - y0) / res;
      const int ix = static_cast<int>(std::floor(px)), iy = static_cast<int>(std::floor(py));
      const double a = px - ix, b = py - iy;
      const double d = ((1 - a) * (1 - b) * at(ix, iy) + a * (1 - b) * at(ix + 1, iy) +
                        (1 - a) * b * at(ix, iy + 1) + a * b * at(ix + 1, iy + 1)) * res;
      // Less the raster's half diagonal and the chamfer's 2 % (the filled
      // outline's covered pixels can still leave it up to ~1 px deep).
      out = -std::max(-analytic, 0.98 * d - 0.5 * std::sqrt(2.0) * res);
    }
  }
}

SubjectRegion SubjectRegionTracker::Measure(const CameraModel& model,
                                            const OutputGeometry& output,
                                            const Eigen::Quaterniond& R_v,
                                            const Eigen::Vector2d& t, const RowRotations& rows,
                                            const FaceObservation* face) const {
  // This frame's head ellipse from the landmarks (invalid without them).
  const SubjectRegionOptions& o = options_;
  SubjectRegion measured;
  if (face != nullptr && face->valid && face->landmarks.size() == landmarks68::kCount &&
      !rows.empty()) {
    // Landmarks into the output through the subject layer's pose, each at
    // its own row's real rotation.
    std::vector<Eigen::Vector2d> out(landmarks68::kCount);
    bool ok = true;
    for (int i = 0; i < landmarks68::kCount && ok; ++i) {
      const double row = face->landmark_rows.size() == landmarks68::kCount
                             ? face->landmark_rows[i]
                             : 0.5 * (rows.height() - 1);
      Eigen::Vector2d V;
      ok = model.Project(face->landmarks[i], R_v, t, rows.At(row), &V) &&
           V.allFinite();
      out[i] = output.VirtualToOutputPixel(V);
    }
    if (ok) {
      double x0 = out[kJawFirst].x(), x1 = x0, brow = out[kBrowFirst].y();
      for (int i = kJawFirst; i <= kJawLast; ++i) {
        x0 = std::min(x0, out[i].x());
        x1 = std::max(x1, out[i].x());
      }
      for (int i = kBrowFirst; i <= kBrowLast; ++i)
        brow = std::min(brow, out[i].y());
      const Eigen::Vector2d chin = out[kChin];
      const double w = x1 - x0, h = chin.y() - brow;
      if (w > 1.0 && h > 1.0) {
        measured.valid = true;
        measured.jaw_width = w;
        measured.face_height = h;
        measured.chin = chin;
        const double top = brow - o.head_top_scale * h,
                     bottom = chin.y() + 0.05 * h;
        measured.head_centre =
            Eigen::Vector2d(0.5 * (x0 + x1), 0.5 * (top + bottom));
        measured.head_axes =
            Eigen::Vector2d(o.head_width_scale * w, 0.5 * (bottom - top));
        Eigen::Vector2d c = Eigen::Vector2d::Zero();
        for (const auto& q : out) c += q;
        measured.face_centre = c / static_cast<double>(landmarks68::kCount);
      }
    }
  }
  return measured;
}

const SubjectRegion& SubjectRegionTracker::Update(
    const CameraModel& model, const OutputGeometry& output,
    const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
    const RowRotations& rows, const FaceObservation* face, double blend_target,
    double dt) {
  const SubjectRegionOptions& o = options_;
  const SubjectRegion measured = Measure(model, output, R_v, t, rows, face);
  SubjectRegion& r = region_;
  if (measured.valid) {
    if (!r.valid) {
      const double blend = r.blend;
      r = measured;
      r.blend = blend;
    } else {
      // First-order smoothing of the shape (exact for dt). The position is
      // this frame's: smoothing it would lag a subject that moves in the
      // output (one walking across the view: 180 px/s x 0.15 s), putting
      // its head into the band.
      const double a = o.smoothing_s > 0 && dt > 0
                           ? 1.0 - std::exp(-dt / o.smoothing_s)
                           : 1.0;
      const Eigen::Vector2d chin_offset = r.chin - r.head_centre;
      r.head_centre = measured.head_centre;
      r.face_centre = measured.face_centre;
      r.head_axes += a * (measured.head_axes - r.head_axes);
      r.chin = r.head_centre + chin_offset +
               a * ((measured.chin - measured.head_centre) - chin_offset);
      r.jaw_width += a * (measured.jaw_width - r.jaw_width);
      r.face_height += a * (measured.face_height - r.face_height);
    }
  }
  // Neck and shoulders from the smoothed face.
  r.torso = o.torso;
  r.neck_half_width = o.neck_width_scale * r.jaw_width;
  r.shoulder_axes = Eigen::Vector2d(o.shoulder_width_scale * r.jaw_width,
                                    2.0 * r.face_height);
  r.shoulder_centre =
      r.chin + Eigen::Vector2d(0.0, 0.6 * r.face_height + r.shoulder_axes.y());
  // Blend: towards the target (0 without a region), rate-limited.
  const double target =
      r.valid ? std::min(1.0, std::max(0.0, blend_target)) : 0.0;
  // The stream's first frame starts at its target (as w_f does: there is
  // no previous output to jump from); later frames ramp.
  const double step_max = dt > 0 ? dt / o.ramp_s : 1.0;
  const double previous = r.blend;
  r.blend =
      previous + std::min(step_max, std::max(-step_max, target - previous));
  // The first frame's start is not a step (nothing was shown before it).
  r.blend_step = dt > 0 ? std::abs(r.blend - previous) : 0.0;
  return r;
}

}  // namespace steadiface
