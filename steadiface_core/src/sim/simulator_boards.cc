// The simulator's billboards: the face's pose and relief, and the
// billboards besides the face: the torso, the hair edge, the passer-by, the
// second face and the occluding hand.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "sim/ramp.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace sim {

Pose Simulator::FacePose(double t, bool turned) const {
  Pose P;
  if (turned) P.R = head_.Orientation(t);
  // Turned about the turning centre: it stays where it is unturned.
  P.p = head_.Position(t) + Body(t) + turning_centre_ - P.R * turning_centre_;
  P = Orbit(P, t);
  const SimulatorOptions& so = options_;
  if (so.face_out_start_s >= 0) {
    // Sideways out of view and back.
    const double out = Ramp(t, so.face_out_start_s, so.face_out_start_s + 0.4) -
                       Ramp(t, so.face_out_end_s, so.face_out_end_s + 0.4);
    P.p.x() += 0.6 * out;
  }
  return P;
}

Status Simulator::MakeRelief(double m_per_px) {
  const SimulatorOptions& o = options_;
  HeadReliefOptions ro = o.relief;
  if (ro.mean_face) ro.nose_height_m = 0.0;  // the mean face has its own nose
  face_.depth_m = MakeHeadRelief(face_.bgra.size(), face_centre_uv_, o.face_width_px, ro);
  if (!ro.mean_face) return Status::Ok();
  const std::string path = o.data_dir + "/" + o.face_landmarks;
  std::vector<Eigen::Vector2d> uv;
  if (!ReadPhotoLandmarks(path, &uv)) {
    return Status::Error("sim: cannot read 68 landmarks (\"x y\" per line) from " + path);
  }
  const Eigen::Vector2d origin(o.face_region.x, o.face_region.y);
  for (Eigen::Vector2d& p : uv) p -= origin;
  if (!AddMeanFaceDepths(uv, m_per_px, ro.mean_face_sigma, &face_.depth_m)) {
    return Status::Error("sim: the landmarks in " + path + " do not fit the face photo");
  }
  return Status::Ok();
}

void Simulator::MakeTorso() {
  const SimulatorOptions& o = options_;
  // Neck and shoulders: a striped shirt, its top edge at the neck, 8 cm
  // below the face's landmark centre; 2 mm per texel.
  const double m = 0.002, width = o.torso_width_m, height = 0.5;
  const int tw = static_cast<int>(width / m), th = static_cast<int>(height / m);
  torso_.bgra = cv::Mat(th, tw, CV_8UC4);
  for (int y = 0; y < th; ++y) {
    cv::Vec4b* row = torso_.bgra.ptr<cv::Vec4b>(y);
    for (int x = 0; x < tw; ++x) {
      const double X = (x - 0.5 * (tw - 1)) * m, Y = y * m;
      // Neck 12 cm wide, widening to the shoulders from 7 to 15 cm down.
      const double s = std::min(1.0, std::max(0.0, (Y - 0.07) / 0.08));
      const double half = 0.06 + (0.5 * width - 0.06) * s * s * (3 - 2 * s);
      const double edge = (half - std::abs(X)) / m;  // texels inside
      const double a = std::min(1.0, std::max(0.0, 0.5 + 0.5 * edge));
      const bool neck = Y < 0.09;
      const bool stripe = (x / 12) % 2 == 0;
      row[x] = neck ? cv::Vec4b(120, 150, 200, 0) : stripe ? cv::Vec4b(150, 70, 40, 0)
                                                          : cv::Vec4b(200, 190, 180, 0);
      row[x][3] = static_cast<uchar>(std::lround(255.0 * a));
    }
  }
  torso_.metres_per_px = m;
  torso_.anchor_px = Eigen::Vector2d(0.5 * (tw - 1), 0.0);
  torso_.pose = [this](double t) {
    // The face billboard's position without its turning and nodding.
    const Pose P = FacePose(t, false);
    const Eigen::Vector3d centre = P.p + P.R * face_front_;
    Pose T;
    T.R = Orbit(Pose(), t).R;
    T.p = centre + T.R * Eigen::Vector3d(0.0, 0.08, options_.torso_depth_m);
    return T;
  };
}

void Simulator::MakeHair() {
  // In the upper half, the outline (unit ellipse distance d) becomes strands:
  // each column's hair reaches d_max in [0.86, 1], with a soft tip, the
  // strands semi-transparent between them, in a hair colour.
  cv::Mat& t = face_.bgra;
  const double cx = 0.5 * (t.cols - 1), cy = 0.5 * (t.rows - 1);
  const double ax = 0.5 * t.cols, ay = 0.5 * t.rows;
  for (int y = 0; y < t.rows && y < cy; ++y) {
    cv::Vec4b* row = t.ptr<cv::Vec4b>(y);
    for (int x = 0; x < t.cols; ++x) {
      const double d = std::hypot((x - cx) / ax, (y - cy) / ay);
      if (d < 0.8 || d > 1.0) continue;
      const double reach = 0.95 + 0.03 * std::sin(1.3 * x + 2.0 * std::sin(0.21 * x)) +
                           0.02 * std::sin(3.1 * x);
      const double strand = 0.6 + 0.4 * std::abs(std::sin(2.3 * x + std::sin(0.5 * y)));
      const double a = std::min(1.0, std::max(0.0, (reach - d) / 0.03)) * (d > 0.86 ? strand : 1.0);
      const double hair = std::min(1.0, (d - 0.8) / 0.06);
      for (int c = 0; c < 3; ++c) {
        const double h = c == 0 ? 40 : c == 1 ? 70 : 105;  // BGR, brown
        row[x][c] = static_cast<uchar>(std::lround(row[x][c] + hair * (h - row[x][c])));
      }
      row[x][3] = static_cast<uchar>(std::lround(255.0 * a));
    }
  }
}

void Simulator::MakePasserBy() {
  // A person 1.7 m tall, 0.5 m wide (a head on a coat), 2.5 m from the
  // camera's start, walking 2.4 m across behind the subject.
  const double m = 0.01;
  const int w = 50, h = 170;
  passer_by_.bgra = cv::Mat(h, w, CV_8UC4, cv::Scalar::all(0));
  cv::ellipse(passer_by_.bgra, cv::Point(25, 12), cv::Size(10, 12), 0, 0, 360,
              cv::Scalar(90, 120, 170, 255), -1, cv::LINE_AA);
  cv::rectangle(passer_by_.bgra, cv::Rect(3, 26, 44, 144), cv::Scalar(40, 40, 160, 255), -1);
  for (int y = 40; y < h; y += 12) {
    cv::line(passer_by_.bgra, cv::Point(3, y), cv::Point(46, y), cv::Scalar(60, 150, 220, 255), 2);
  }
  passer_by_.metres_per_px = m;
  passer_by_.anchor_px = Eigen::Vector2d(25, 60);
  passer_by_.pose = [this](double t) {
    const SimulatorOptions& so = options_;
    const double s = Ramp(t, so.passer_by_start_s, so.passer_by_end_s);
    Pose P;
    P.p = Eigen::Vector3d(-1.2 + 2.4 * s, 0.1, 2.5);
    return P;
  };
}

void Simulator::MakeSecondFaceAndOccluder(const cv::Mat& photo, double m_per_px) {
  // The second face (the mirrored photo, approaching) and the occluding hand.
  const SimulatorOptions& o = options_;
  cv::Mat mirrored;
  cv::flip(photo, mirrored, 1);
  cv::Rect mr = o.face_region;
  mr.x = photo.cols - o.face_region.x - o.face_region.width;
  second_face_ = MakeFaceBillboard(mirrored, mr, o.face_region.width * m_per_px);
  second_face_.pose = [this](double t) {
    const SimulatorOptions& so = options_;
    const double s = Ramp(t, so.second_face_start_s, so.second_face_start_s + 0.6 * so.duration_s);
    const double d = 1.2 + (so.second_face_final_distance_m - 1.2) * s;
    Pose P;
    P.p = Eigen::Vector3d(0.28 * d, 0.02, d) + Body(t);
    return P;
  };
  occluder_.bgra = cv::Mat(30, 12, CV_8UC4, cv::Scalar(70, 110, 170, 255));  // a hand
  occluder_.metres_per_px = 0.01;
  occluder_.anchor_px = Eigen::Vector2d(5.5, 14.5);
  occluder_.pose = [this](double t) {
    const SimulatorOptions& so = options_;
    const double s = Ramp(t, so.occlusion_start_s, so.occlusion_end_s);
    Pose P = FacePose(t, false);
    P.R = Eigen::Quaterniond::Identity();
    P.p.z() -= 0.15;
    P.p.x() += -0.25 + 0.5 * s;
    return P;
  };
}

}  // namespace sim
}  // namespace steadiface
