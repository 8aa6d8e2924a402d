#include "steadiface_ros/frusta_markers.h"

#include <array>
#include <string>

namespace steadiface_ros {
namespace {

geometry_msgs::Point P(const Eigen::Vector3d& v) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}

std_msgs::ColorRGBA Colour(float r, float g, float b, float a) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

visualization_msgs::Marker Base(const std_msgs::Header& h, int id, int type,
                                const std_msgs::ColorRGBA& c) {
  visualization_msgs::Marker m;
  m.header = h;
  m.ns = "steadiface_frusta";
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.color = c;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.frame_locked = false;
  return m;
}

// The image plane's corners at `depth` in camera coordinates (top-left,
// top-right, bottom-right, bottom-left).
std::array<Eigen::Vector3d, 4> Corners(const steadiface::CameraIntrinsics& k,
                                       double depth) {
  const double w = k.width, h = k.height;
  auto ray = [&](double u, double v) {
    return Eigen::Vector3d((u - k.cx) / k.fx * depth, (v - k.cy) / k.fy * depth,
                           depth);
  };
  return {ray(0, 0), ray(w, 0), ray(w, h), ray(0, h)};
}

}  // namespace

void FrustaMarkers::Add(const Eigen::Quaterniond& world_from_real,
                        const Eigen::Quaterniond& world_from_virtual) {
  if (!world_from_real.coeffs().allFinite() ||
      !world_from_virtual.coeffs().allFinite())
    return;
  real_trail_.push_back(world_from_real.normalized());
  virtual_trail_.push_back(world_from_virtual.normalized());
  while (real_trail_.size() > trail_length_) real_trail_.pop_front();
  while (virtual_trail_.size() > trail_length_) virtual_trail_.pop_front();
}

void FrustaMarkers::Clear() {
  real_trail_.clear();
  virtual_trail_.clear();
}

visualization_msgs::MarkerArray FrustaMarkers::Make(
    const std_msgs::Header& h, const steadiface::CameraIntrinsics& real,
    const steadiface::CameraIntrinsics& virtual_camera) const {
  visualization_msgs::MarkerArray out;
  if (real_trail_.empty() || !steadiface::ValidateIntrinsics(real).ok() ||
      !steadiface::ValidateIntrinsics(virtual_camera).ok()) {
    return out;
  }
  struct Cam {
    const std::deque<Eigen::Quaterniond>* trail;
    const steadiface::CameraIntrinsics* k;
    std_msgs::ColorRGBA colour;
    std::string label;
  };
  const std::array<Cam, 2> cams = {
      Cam{&real_trail_, &real, Colour(1.0f, 0.45f, 0.0f, 1.0f), "real camera"},
      Cam{&virtual_trail_, &virtual_camera, Colour(0.1f, 0.85f, 0.2f, 1.0f),
          "virtual camera"}};
  int id = 0;
  for (const Cam& c : cams) {
    const Eigen::Quaterniond& q = c.trail->back();
    std::array<Eigen::Vector3d, 4> corners = Corners(*c.k, depth_);
    for (auto& p : corners) p = q * p;
    // Frustum: apex to each corner, and the image plane's outline.
    visualization_msgs::Marker lines =
        Base(h, id++, visualization_msgs::Marker::LINE_LIST, c.colour);
    lines.scale.x = 0.006 * depth_;
    for (int i = 0; i < 4; ++i) {
      lines.points.push_back(P(Eigen::Vector3d::Zero()));
      lines.points.push_back(P(corners[i]));
      lines.points.push_back(P(corners[i]));
      lines.points.push_back(P(corners[(i + 1) % 4]));
    }
    out.markers.push_back(lines);
    // The image plane, lightly filled.
    std_msgs::ColorRGBA fill_colour = c.colour;
    fill_colour.a = 0.18f;
    visualization_msgs::Marker fill =
        Base(h, id++, visualization_msgs::Marker::TRIANGLE_LIST, fill_colour);
    for (int i : {0, 1, 2, 0, 2, 3}) fill.points.push_back(P(corners[i]));
    out.markers.push_back(fill);
    // Where the optical axis met the plane over the last frames.
    visualization_msgs::Marker trail =
        Base(h, id++, visualization_msgs::Marker::LINE_STRIP, c.colour);
    trail.scale.x = 0.004 * depth_;
    for (const auto& t : *c.trail)
      trail.points.push_back(P(t * Eigen::Vector3d(0, 0, depth_)));
    if (trail.points.size() < 2) trail.points.push_back(trail.points.back());
    out.markers.push_back(trail);
    // A label: the real camera's above its plane's top edge, the virtual
    // camera's (a narrower plane, inside the real one) below its bottom
    // edge, so that the two never overlap (-y is up in an optical frame).
    visualization_msgs::Marker text =
        Base(h, id++, visualization_msgs::Marker::TEXT_VIEW_FACING, c.colour);
    text.scale.z = 0.06 * depth_;
    text.text = c.label;
    const bool real_camera = c.trail == &real_trail_;
    const Eigen::Vector3d anchor = real_camera
                                       ? 0.5 * (corners[0] + corners[1])
                                       : 0.5 * (corners[2] + corners[3]);
    text.pose.position =
        P(anchor +
          q * Eigen::Vector3d(0, real_camera ? -0.05 : 0.05, 0) * depth_);
    out.markers.push_back(text);
  }
  return out;
}

}  // namespace steadiface_ros
