#pragma once

#include <Eigen/Core>

#include "steadiface_core/face/head_region_motion.h"

namespace steadiface {

/// The gain of the first-order filter on the yaw's rate per frame. The
/// flow is taken beyond the camera's rotation (the gyro, each row at its
/// time), so one frame's measured turn is nearly clean; a light filter
/// still steadies it on real footage. The rate's lag after a reversal by D
/// leaves the yaw behind by D (1 - gain) / gain, and a wrong axis feeds
/// back through the tracks' depths, so the gain is high: on turn_away
/// (seeds 1-3) 0.35 / 0.5 / 0.7 / 1.0 give the head 5.2-6.3 / 4.8-5.7 /
/// 4.6-5.6 / 4.6-5.6 px [-].
constexpr double kHeadTurnRateGain = 0.7;

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
/// tracks). When the tracks' depths do not spread (they all face the
/// camera, or all sit at the silhouette) the turn is not observable and
/// only the translation is taken. The yaw stays within +-kHeadTurnMaxYaw
/// (past_profile once it reaches it) and
/// changes at most 0.15 rad per frame; its rate is filtered (kHeadTurnRateGain). False (state kept) with fewer than 3
/// tracks or a radius <= 0.
bool UpdateHeadTurn(const RegionFlow& flow, HeadTurn* head);

}  // namespace steadiface
