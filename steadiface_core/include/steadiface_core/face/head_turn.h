#pragma once

#include <algorithm>

#include <Eigen/Core>

#include "steadiface_core/face/head_region_motion.h"

namespace steadiface {

/// The yaw's rate per frame is filtered as a constant rate (Kalman, one
/// state): each frame's measured turn enters with its own standard error,
/// from the fit's residuals and the spread of the tracks' depths. One
/// frame's flow pins the turn only when the depths spread: over a face
/// seen nearly frontally a 0.035 rad turn moves the tracks relative to one
/// another by about 0.4 px, near their noise. A fixed gain took such frames
/// at face value, and a frame with no spread of depths (or a wrong turn)
/// handed the whole turning flow to the axis: turned 3.6 rad at 3x the
/// preset's head motion, turn_away's axis slid 90 px off the head in ten
/// frames. The rate itself may change from one frame to the next by about
/// this much (a standard deviation: a head's turn speeding up or slowing
/// down) [rad/frame per frame].
constexpr double kHeadTurnRateProcessSd = 0.01;
/// The rate's standard deviation when a follow takes the rate of the last
/// fits (PnP's, filtered) [rad/frame].
constexpr double kHeadTurnRateStartSd = 0.06;
/// The largest turn per frame a head is taken to make: one frame's
/// measured turn and a follow's starting rate are clipped to it [rad/frame].
constexpr double kHeadTurnMaxRate = 0.15;
/// `rate` within +-kHeadTurnMaxRate [rad/frame].
inline double ClipTurnRate(double rate) {
  return std::clamp(rate, -kHeadTurnMaxRate, kHeadTurnMaxRate);
}
/// A track's flow is taken as no more precise than this, whatever the
/// residuals of one frame's fit (a cylinder's flow fits exactly only in
/// the simulator) [px].
constexpr double kHeadTurnFlowSdFloor = 0.3;

/// The largest |yaw| the cylinder follows [rad]. A head turned further
/// shows the far side of its skull, and the flow no longer tells the turn
/// from the axis' motion: the turn back from a profile was measured two
/// to three times too fast (turn_away at 1.3x the head's motion), its axis
/// 50 px off. A follow that reaches it ends (HeadTurn::past_profile).
constexpr double kHeadTurnMaxYaw = 1.5;

/// A head followed through a turn past what the landmark model fits, as a
/// vertical cylinder about its turning axis: the cylinder head model
/// (La Cascia, Sclaroff and Athitsos 2000; Xiao, Kanade and Cohn 2002)
/// reduced to the motions that matter to the stabilizer, the axis' image
/// translation and the yaw about it. A surface point at angle beta from the
/// line of sight sits at x = axis.x + r sin(beta), depth z = r cos(beta)
/// towards the camera; a turn by d_yaw moves it by dx = -z d_yaw. So points
/// near the silhouette (z ~ 0) move with the axis and points facing the
/// camera with the turn, and one frame's flow gives both.
struct HeadTurn {
  /// x: the turning axis in the image; y: the face centre's row [px].
  Eigen::Vector2d axis_px = Eigen::Vector2d::Zero();
  /// The yaw, in the landmarks' convention: the face centre sits at
  /// axis.x - radius sin(yaw) [rad].
  double yaw = 0.0;
  /// The yaw's change per frame, filtered [rad/frame].
  double yaw_rate = 0.0;
  /// The filtered rate's variance [(rad/frame)^2].
  double yaw_rate_var = kHeadTurnRateStartSd * kHeadTurnRateStartSd;
  /// The face's distance from the axis in the image [px].
  double radius_px = 0.0;
  /// The yaw reached kHeadTurnMaxYaw: the head is past what the cylinder
  /// follows.
  bool past_profile = false;

  /// Where the landmark centre is while the head is turned so [px].
  Eigen::Vector2d FaceCentre() const;
};

/// One frame: the axis moves by the flow's part common to all depths and
/// the yaw by its part proportional to depth (least squares over the
/// tracks). The measured turn updates the filtered rate by its standard
/// error (kHeadTurnRateProcessSd above); when the tracks' depths do not
/// spread (they all face the camera, or all sit at the silhouette) the turn
/// is not observable and the rate is kept. The axis then moves by the flow
/// beyond that turn. The yaw stays within +-kHeadTurnMaxYaw (past_profile
/// once it reaches it) and changes at most kHeadTurnMaxRate per frame. False
/// (state kept) with fewer than 3 tracks or a radius <= 0.
bool UpdateHeadTurn(const RegionFlow& flow, HeadTurn* head);

}  // namespace steadiface
