#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "steadiface_core/eval/composite_quality.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace eval {

/// A stabilization method to score on simulated sequences.
enum class Method {
  kNone,        ///< input as is
  kGyroOnly,    ///< steadiface with w_f = 0 (no face)
  kSteadiface,  ///< the full method, dlib landmarks from the rendered frames
  kSteadifaceLayered,  ///< the full method with the layered warp
  kSteadifaceComposite,  ///< the full method with the composite warp
};
const char* MethodName(Method m);

/// Pipeline options matching a simulator (intrinsics, readout, IMU clock
/// offset) with the package defaults otherwise, except that the solver's
/// wall-time cap (a real-time guard) is lifted to its largest allowed value:
/// scores must not depend on how loaded the machine is. The iteration cap
/// still ends every solve; on an idle machine the default cap never binds,
/// so the figures are the live configuration's.
PipelineOptions OptionsFor(const sim::Simulator& sim, Method method);

/// The scorecard for warps a pipeline with `options` produces on `sim` (its
/// camera model and output geometry), with default scorecard options; its
/// window is `window_s` (start, end) when finite, else the simulated IMU's
/// dropout, if any.
Status MakeScorecard(const sim::Simulator& sim, const PipelineOptions& options,
                     std::unique_ptr<Scorecard>* card,
                     const Eigen::Vector2d& window_s = Eigen::Vector2d::Constant(NAN));

/// The warp `pipeline` applied to the frame it just processed (`out`), for
/// the scorecard: the pose, or in layered mode the joined mesh and the
/// background layer's, read from the pipeline's warper (so ask before the
/// next frame). `rendered`: the output was rendered (adds the warp's time).
FrameWarp MakeFrameWarp(const PipelineFrame& out, const Pipeline& pipeline, bool rendered);

/// How long past a frame's last row the gyro is waited for [s].
constexpr double kGyroWaitS = 0.1;

/// Feeds the simulator's gyro samples from index `*next` on into `pipeline`
/// until they cover the frame stamped `stamp` up to just past its last row,
/// as a live node would have them (`imu_time_offset_s` as in the pipeline's
/// options), but none stamped more than kGyroWaitS after that row: across
/// an IMU dropout the frame is left uncovered. Advances `*next`.
void FeedGyroForFrame(const sim::Simulator& sim, Time stamp, double imu_time_offset_s,
                      Pipeline* pipeline, size_t* next);

/// True when the simulated IMU drops out (SimulatorOptions::imu_dropout_*).
inline bool ImuHasGap(const sim::SimulatorOptions& o) {
  return o.imu_dropout_start_s >= 0.0 && o.imu_dropout_end_s > o.imu_dropout_start_s;
}

/// What RunMethod renders and hands back besides the scorecard.
struct RunMethodOptions {
  /// Render every output image (Pipeline's render_output; the composite
  /// always renders, as its matte and plate are made from the pictures).
  bool render = false;
  /// Receives the stabilizer frames, if set.
  std::vector<StabilizerFrame>* frames = nullptr;
  /// Receives each output image (for kNone: the input frame), if set; needs
  /// `render`.
  std::function<Status(const cv::Mat&)> on_output;
  /// The composite's matte and plate scored against the truth
  /// (CompositeQuality), if set.
  CompositeQualityScore* composite_quality = nullptr;
  /// A path prefix: with composite_quality, also writes every 15th frame's
  /// picture (CompositeQuality::DumpFrames). Empty: none.
  std::string composite_frames;
  /// The stabilizer is handed the true head centre
  /// (Pipeline::SetTrueHeadCentre) on every frame the head is in view.
  bool true_head = false;
};

/// Renders every frame, feeds the IMU and the frames through a Pipeline,
/// and scores the warps into `card` (also kept for trajectories); `run`
/// says what else is rendered and handed back.
Status RunMethod(const sim::Simulator& sim, Method method, const PipelineOptions& options,
                 Scorecard* card, const RunMethodOptions& run = RunMethodOptions());

}  // namespace eval
}  // namespace steadiface
