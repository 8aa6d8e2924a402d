#include "steadiface_core/pipeline/debug_overlay.h"

#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "steadiface_core/composite/compositor.h"
#include "steadiface_core/warp/warp_geometry.h"

namespace steadiface {
namespace {

cv::Point2f P(const Eigen::Vector2d& p) {
  return cv::Point2f(static_cast<float>(p.x()), static_cast<float>(p.y()));
}

// The landmarks (green dots; orange when a head turned past them is
// followed: FaceInfo::followed) and their centre C (yellow cross).
void DrawFace(const FaceInfo& face, double s, int th, cv::Mat* out) {
  const cv::Scalar green(0, 220, 0), orange(0, 140, 255), yellow(0, 230, 255);
  const cv::Scalar& dots = face.valid ? green : orange;
  for (const auto& p : face.landmarks_px) {
    cv::circle(*out, P(p), static_cast<int>(2 * s), dots, cv::FILLED, cv::LINE_AA);
  }
  const cv::Point2f c = P(face.centre_px);
  const float r = static_cast<float>(8 * s);
  cv::line(*out, c - cv::Point2f(r, 0), c + cv::Point2f(r, 0), yellow, th, cv::LINE_AA);
  cv::line(*out, c - cv::Point2f(0, r), c + cv::Point2f(0, r), yellow, th, cv::LINE_AA);
}

// The crop footprint (the output boundary mapped into the input: cyan, red
// where it leaves the frame) and H where it falls in the input (magenta).
void DrawFootprint(const CameraModel& model, const ProtrusionGeometry& protrusion,
                   const StabilizerFrame& frame, double s, int th, cv::Mat* out) {
  const cv::Scalar magenta(255, 0, 255), cyan(255, 220, 0), red(0, 0, 255);
  const CameraIntrinsics& k = model.intrinsics();
  std::vector<cv::Point2f> poly;
  std::vector<bool> inside;
  double row = 0.5 * (k.height - 1);
  for (const auto& V : protrusion.boundary()) {
    Eigen::Vector2d p;
    if (!VirtualToRealPixelRS(model, frame.R_v, frame.t, frame.rows, V, 5, 1e-2, &p, &row)) {
      continue;
    }
    poly.push_back(P(p));
    inside.push_back(p.x() >= 0 && p.y() >= 0 && p.x() <= k.width - 1 && p.y() <= k.height - 1);
  }
  for (size_t i = 0; i < poly.size(); ++i) {
    const size_t j = (i + 1) % poly.size();
    cv::line(*out, poly[i], poly[j], inside[i] && inside[j] ? cyan : red, th, cv::LINE_AA);
  }
  if (frame.has_target) {
    // H lives in the virtual view; show where it falls in the input.
    Eigen::Vector2d h;
    if (model.Unproject(frame.H, frame.R_v, frame.t, frame.R_r, &h)) {
      cv::circle(*out, P(model.NormalizedToPixel(h)), static_cast<int>(10 * s), magenta, th,
                 cv::LINE_AA);
    }
  }
}

// The state as text: face tracking, head pose, w_f, the solver and flags.
std::vector<std::string> StateLines(const FaceInfo* face, const StabilizerFrame* frame) {
  std::vector<std::string> lines;
  char buf[160];
  if (face != nullptr) {
    std::snprintf(buf, sizeof(buf), "face: %s%s%s%s conf %.2f", TrackingStateName(face->state),
                  face->failure != FaceFailure::kNone ? " / " : "",
                  face->failure != FaceFailure::kNone ? FaceFailureName(face->failure) : "",
                  face->followed ? ", head followed" : "", face->confidence);
    lines.emplace_back(buf);
    if (face->has_pose) {
      std::snprintf(buf, sizeof(buf), "pose yaw %.0f pitch %.0f roll %.0f deg",
                    face->yaw * 57.2958, face->pitch * 57.2958, face->roll * 57.2958);
      lines.emplace_back(buf);
    }
  }
  if (frame != nullptr) {
    std::snprintf(buf, sizeof(buf), "w_f %.3g  solver %s %d it %.2f ms", frame->weights.fit,
                  frame->solver.termination.c_str(), frame->solver.iterations,
                  frame->solver.time_ms);
    lines.emplace_back(buf);
    std::string flags;
    if (frame->flags.held_face) flags += " held_face";
    if (frame->flags.protrusion_search) flags += " protrusion_search";
    if (frame->flags.previous_warp) flags += " previous_warp";
    if (frame->flags.solver_failed) flags += " solver_failed";
    if (frame->flags.undefined_pixels) flags += " UNDEFINED";
    if (!flags.empty()) lines.push_back("flags:" + flags);
  }
  return lines;
}

}  // namespace

void DrawDebugOverlay(const cv::Mat& input, const CameraModel& model,
                      const ProtrusionGeometry& protrusion,
                      const FaceInfo* face, const StabilizerFrame* frame,
                      cv::Mat* out) {
  if (input.channels() == 1) {
    cv::cvtColor(input, *out, cv::COLOR_GRAY2BGR);
  } else if (input.channels() == 4) {
    cv::cvtColor(input, *out, cv::COLOR_BGRA2BGR);
  } else {
    input.copyTo(*out);
  }
  const double s = std::max(1.0, out->cols / 640.0);  // line scale
  const int th = static_cast<int>(std::lround(s));
  if (face != nullptr && face->located()) DrawFace(*face, s, th, out);
  if (frame != nullptr && !frame->rows.empty()) DrawFootprint(model, protrusion, *frame, s, th, out);
  // Text block.
  const double fs = 0.5 * s;
  int y = static_cast<int>(20 * s);
  for (const auto& l : StateLines(face, frame)) {
    cv::putText(*out, l, cv::Point(static_cast<int>(8 * s), y), cv::FONT_HERSHEY_SIMPLEX,
                fs, cv::Scalar(0, 0, 0), th + 2, cv::LINE_AA);
    cv::putText(*out, l, cv::Point(static_cast<int>(8 * s), y), cv::FONT_HERSHEY_SIMPLEX,
                fs, cv::Scalar(255, 255, 255), th, cv::LINE_AA);
    y += static_cast<int>(18 * s);
  }
}

namespace {

// The mesh's source (input px) of an output point (bilinear in its cell).
cv::Point2f MeshSource(const WarpMesh& mesh, double u, double v) {
  int i = 0, j = 0;
  while (i + 2 < mesh.cols && mesh.u[i + 1] < u) ++i;
  while (j + 2 < mesh.rows && mesh.v[j + 1] < v) ++j;
  const double a = std::min(1.0, std::max(0.0, (u - mesh.u[i]) / (mesh.u[i + 1] - mesh.u[i])));
  const double b = std::min(1.0, std::max(0.0, (v - mesh.v[j]) / (mesh.v[j + 1] - mesh.v[j])));
  auto q = [&](int ii, int jj) { return mesh.source[jj * mesh.cols + ii].cast<double>(); };
  const Eigen::Vector2d p = (1 - a) * (1 - b) * q(i, j) + a * (1 - b) * q(i + 1, j) +
                            (1 - a) * b * q(i, j + 1) + a * b * q(i + 1, j + 1);
  return cv::Point2f(static_cast<float>(p.x()), static_cast<float>(p.y()));
}

void TextLine(const std::string& text, int line_from_bottom, cv::Mat* out) {
  const double s = std::max(1.0, out->cols / 640.0);
  const int th = static_cast<int>(std::lround(s));
  const cv::Point at(static_cast<int>(8 * s),
                     out->rows - static_cast<int>((10 + 18 * line_from_bottom) * s));
  cv::putText(*out, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.5 * s, cv::Scalar(0, 0, 0), th + 2,
              cv::LINE_AA);
  cv::putText(*out, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.5 * s, cv::Scalar(255, 255, 255), th,
              cv::LINE_AA);
}

}  // namespace

void DrawCompositeOverlay(const WarpMesh& background_mesh, const Compositor& compositor,
                          cv::Mat* out) {
  const CompositeReport& r = compositor.report();
  const double s = std::max(1.0, out->cols / 640.0);
  const int th = static_cast<int>(std::lround(s));
  if (r.active && !compositor.background_matte().empty() && background_mesh.cols >= 2) {
    // The matte's outline (magenta), traced in the background layer's
    // output and mapped into the input through its mesh.
    const cv::Mat inside = compositor.background_matte() >= 0.5;
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(inside, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    for (const auto& c : contours) {
      std::vector<cv::Point> poly;
      for (const auto& p : c) {
        const cv::Point2f q = MeshSource(background_mesh, p.x + r.background_roi.x,
                                         p.y + r.background_roi.y);
        poly.emplace_back(cvRound(q.x), cvRound(q.y));
      }
      cv::polylines(*out, poly, true, cv::Scalar(255, 0, 255), th, cv::LINE_AA);
    }
  }
  // The plate's age, top right: green where fresh, fading to black as it
  // ages, black where never seen.
  const cv::Mat& seen = compositor.plate().seen();
  const double now = compositor.plate().now();
  const double max_age = compositor.plate().options().max_age_s;
  const int w = std::max(16, out->cols / 4), h = std::max(9, w * seen.rows / std::max(1, seen.cols));
  cv::Mat age(seen.size(), CV_8UC3, cv::Scalar::all(0));
  for (int y = 0; y < seen.rows; ++y) {
    const float* a = seen.ptr<float>(y);
    cv::Vec3b* o = age.ptr<cv::Vec3b>(y);
    for (int x = 0; x < seen.cols; ++x) {
      const double f = 1.0 - (now - a[x]) / max_age;
      if (f > 0.0) o[x] = cv::Vec3b(0, static_cast<uchar>(255 * std::min(1.0, f)), 0);
    }
  }
  const cv::Rect inset(out->cols - w - 4, 4, w, h);
  if ((inset & cv::Rect(0, 0, out->cols, out->rows)) == inset) {
    cv::resize(age, (*out)(inset), inset.size(), 0, 0, cv::INTER_AREA);
    cv::rectangle(*out, inset, cv::Scalar(255, 255, 255), 1);
  }
  char buf[200];
  std::snprintf(buf, sizeof(buf),
                "composite matte %.2f  uncovered %.0f px: plate %.0f%% fallback %.0f%%  plate "
                "fresh %.0f%%  restarts %d",
                r.matte_mean, r.uncovered_px, 100 * r.plate_share, 100 * r.fallback_share,
                100 * r.plate_coverage, r.plate_restarts);
  TextLine(buf, 0, out);
}

void DrawLayeredOverlay(const WarpMesh& mesh, const SubjectRegion& region,
                        const LayerBlendReport& blend, int output_width, int output_height,
                        cv::Mat* out) {
  if (mesh.cols < 2 || mesh.rows < 2 || output_width < 2 || output_height < 2) return;
  const double s = std::max(1.0, out->cols / 640.0);
  const int th = static_cast<int>(std::lround(s));
  auto source = [&mesh](double u, double v) { return MeshSource(mesh, u, v); };
  if (region.valid && region.blend > 0.0) {
    // Level sets of the region's signed distance on a coarse output grid.
    const int step = std::max(2, output_width / 160);
    const int gw = output_width / step + 1, gh = output_height / step + 1;
    const cv::Scalar orange(0, 140, 255), blue(255, 120, 0);
    const double inner = blend.band_outer_px - blend.band_px;
    for (const auto& level : {std::make_pair(0.0, orange), std::make_pair(inner, blue),
                              std::make_pair(blend.band_outer_px, blue)}) {
      cv::Mat mask(gh, gw, CV_8UC1);
      for (int y = 0; y < gh; ++y) {
        for (int x = 0; x < gw; ++x) {
          mask.at<uchar>(y, x) =
              region.SignedDistance(Eigen::Vector2d(x * step, y * step)) <= level.first ? 255 : 0;
        }
      }
      std::vector<std::vector<cv::Point>> contours;
      cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
      for (const auto& c : contours) {
        std::vector<cv::Point2f> poly;
        for (const auto& p : c) poly.push_back(source(p.x * step, p.y * step));
        std::vector<cv::Point> ipoly;
        for (const auto& p : poly) ipoly.emplace_back(cvRound(p.x), cvRound(p.y));
        cv::polylines(*out, ipoly, true, level.second, th, cv::LINE_AA);
      }
    }
  }
  char buf[200];
  std::snprintf(buf, sizeof(buf), "layered g %.2f  offset %.1f->%.1f px  shift %.1f px  cell %.2f%s",
                region.blend, blend.offset_px, blend.capped_offset_px, blend.shift_px,
                blend.min_cell_ratio, blend.protrusion_keep * blend.distortion_keep < 1.0 ? "  pulled" : "");
  const cv::Point at(static_cast<int>(8 * s), out->rows - static_cast<int>(10 * s));
  cv::putText(*out, buf, at, cv::FONT_HERSHEY_SIMPLEX, 0.5 * s, cv::Scalar(0, 0, 0), th + 2,
              cv::LINE_AA);
  cv::putText(*out, buf, at, cv::FONT_HERSHEY_SIMPLEX, 0.5 * s, cv::Scalar(255, 255, 255), th,
              cv::LINE_AA);
}

}  // namespace steadiface
