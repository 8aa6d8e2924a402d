// The approximate scoring path (issue: simulator/scorecard): measured on
// output frames alone, checked against closed-form motion and against the
// exact scorecard on a rendered preset; the ffmpeg peers run through it.
#include <cmath>
#include <cstdlib>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/common/percentile.h"
#include "steadiface_core/eval/ffmpeg_baseline.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/video_scorer.h"
#include "test_util.h"

namespace steadiface {
namespace {

CameraIntrinsics Intrinsics(int w, int h) {
  CameraIntrinsics in;
  in.width = w;
  in.height = h;
  in.fx = in.fy = 0.8 * w;
  in.cx = 0.5 * w;
  in.cy = 0.5 * h;
  return in;
}

// A real photo translated by `shift(i)` px per frame (no face).
cv::Mat Shifted(const cv::Mat& src, int w, int h, const cv::Point2d& d) {
  cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, d.x - 0.25 * src.cols + 0.5 * w, 0, 1,
               d.y - 0.25 * src.rows + 0.5 * h);
  cv::Mat out;
  cv::warpAffine(src, out, m, cv::Size(w, h), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

TEST(VideoScorerTest, StillVideoScoresZeroAndAKnownShakeScoresItsRms) {
  const cv::Mat photo = testing_util::LoadImage("building.jpg");
  ASSERT_FALSE(photo.empty());
  const int w = 480, h = 270;
  std::unique_ptr<eval::VideoScorer> still, shaky;
  eval::VideoScorerOptions o;
  ASSERT_TRUE(eval::VideoScorer::Create(Intrinsics(w, h), o, &still).ok());
  ASSERT_TRUE(eval::VideoScorer::Create(Intrinsics(w, h), o, &shaky).ok());
  // 3 s at 30 fps; 6 Hz shake of amplitude 4 px horizontally and 3 px
  // vertically: RMS sqrt((16 + 9) / 2) = 3.54 px (a whole number of periods).
  const double ax = 4.0, ay = 3.0, f = 6.0;
  for (int i = 0; i < 90; ++i) {
    const double t = i / 30.0;
    ASSERT_TRUE(still->Add(Shifted(photo, w, h, {0, 0})).ok());
    ASSERT_TRUE(shaky->Add(Shifted(photo, w, h, {ax * std::sin(2 * M_PI * f * t),
                                                  ay * std::cos(2 * M_PI * f * t)})).ok());
  }
  const eval::Score s0 = still->Compute(), s1 = shaky->Compute();
  EXPECT_EQ(s0.frames, 90);
  EXPECT_LT(s0.background_jitter_px, 0.02);
  const double expected = std::sqrt((ax * ax + ay * ay) / 2.0);
  EXPECT_NEAR(s1.background_jitter_px, expected, 0.05 * expected);
  // No face anywhere: head metrics are not measured, never made up.
  EXPECT_TRUE(std::isnan(s1.head_jitter_px));
  EXPECT_EQ(shaky->face_fraction(), 0.0);
  // What the path cannot see is reported as unknown.
  EXPECT_TRUE(std::isnan(s1.cropping));
  EXPECT_TRUE(std::isnan(s1.undefined_fraction));
}

TEST(PercentileTest, NearestRank) {
  EXPECT_EQ(Percentile({}, 0.5), 0.0);
  EXPECT_EQ(Percentile({3.0}, 0.99), 3.0);
  EXPECT_EQ(Percentile({5, 1, 4, 2, 3}, 0.5), 3.0);
  EXPECT_EQ(Percentile({5, 1, 4, 2, 3}, 0.0), 1.0);
  EXPECT_EQ(Percentile({5, 1, 4, 2, 3}, 1.0), 5.0);
  std::vector<double> v;
  for (int i = 1; i <= 100; ++i) v.push_back(101 - i);
  EXPECT_EQ(Percentile(v, 0.99), 99.0);  // rank round(0.99 * 99) = 98 -> 99
}

TEST(VideoScorerTest, RejectsBadOptionsAndFrames) {
  std::unique_ptr<eval::VideoScorer> v;
  eval::VideoScorerOptions o;
  o.fps = 0.0;
  EXPECT_FALSE(eval::VideoScorer::Create(Intrinsics(320, 240), o, &v).ok());
  ASSERT_TRUE(eval::VideoScorer::Create(Intrinsics(320, 240), eval::VideoScorerOptions(), &v).ok());
  EXPECT_FALSE(v->Add(cv::Mat()).ok());
  EXPECT_FALSE(v->Add(cv::Mat(240, 320, CV_32FC1, cv::Scalar(0))).ok());
}

std::unique_ptr<sim::Simulator> Walk(int w, int h, double seconds) {
  sim::SimulatorOptions o;
  o.data_dir = STEADIFACE_TEST_DATA_DIR;
  EXPECT_TRUE(sim::ApplyPreset("walk", &o).ok());
  o.width = w;
  o.height = h;
  o.duration_s = seconds;
  // The flat face: the approximate scorer follows the landmarks' centre,
  // the exact one the pose-invariant head, and on a turning relief head the
  // two differ by the turn's own motion (about 1 cm at the default yaw).
  o.head_model = "flat";
  std::unique_ptr<sim::Simulator> s;
  EXPECT_TRUE(sim::Simulator::Create(o, &s).ok());
  return s;
}

// The approximate path on rendered frames against the exact scorecard on the
// same frames' ground truth: the input and steadiface's output.
TEST(VideoScorerTest, AgreesWithTheExactScorecardOnARenderedPreset) {
  auto s = Walk(640, 360, 3.0);
  for (eval::Method m : {eval::Method::kNone, eval::Method::kSteadiface}) {
    const PipelineOptions po = eval::OptionsFor(*s, m);
    std::unique_ptr<eval::Scorecard> card;
    ASSERT_TRUE(eval::MakeScorecard(*s, po, &card).ok());
    std::unique_ptr<eval::VideoScorer> v;
    ASSERT_TRUE(eval::VideoScorer::Create(s->intrinsics(), eval::VideoScorerOptions(), &v).ok());
    eval::RunMethodOptions run;
    run.render = true;
    run.on_output = [&v](const cv::Mat& f) { return v->Add(f); };
    const Status st = eval::RunMethod(*s, m, po, card.get(), run);
    ASSERT_TRUE(st.ok()) << st.message();
    const eval::Score exact = card->Compute(), approx = v->Compute();
    std::cout << "[ " << eval::MethodName(m) << " ] head exact " << exact.head_jitter_px
              << " approx " << approx.head_jitter_px << " px; background exact "
              << exact.background_jitter_px << " approx " << approx.background_jitter_px
              << " px; face in " << 100 * v->face_fraction() << " % of frames\n";
    EXPECT_GT(v->face_fraction(), 0.95);
    // Stated agreement: head within 10 % + 0.3 px (landmark noise), background
    // within 25 % (one median track for the mean of the true points).
    EXPECT_NEAR(approx.head_jitter_px, exact.head_jitter_px, 0.1 * exact.head_jitter_px + 0.3);
    EXPECT_NEAR(approx.background_jitter_px, exact.background_jitter_px,
                0.25 * exact.background_jitter_px);
  }
}

TEST(FfmpegBaselineTest, VidstabAndDeshakeRunAndAreScored) {
  if (!eval::FfmpegAvailable(nullptr)) {
    GTEST_SKIP() << "ffmpeg with vidstab/deshake not installed (scripts/install_deps installs it)";
  }
  auto s = Walk(480, 270, 2.0);
  char dir[] = "/tmp/sf_ffmpeg_test_XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string input = std::string(dir) + "/in.mkv";
  eval::LosslessVideoWriter writer;
  ASSERT_TRUE(writer.Open(input, 480, 270, s->options().fps).ok());
  cv::Mat frame;
  sim::SimTruth truth;
  std::vector<cv::Mat> rendered;
  for (int i = 0; i < s->num_frames(); ++i) {
    ASSERT_TRUE(s->Render(i, &frame, &truth).ok());
    rendered.push_back(frame.clone());
    ASSERT_TRUE(writer.Write(frame).ok());
  }
  ASSERT_TRUE(writer.Close().ok());
  std::unique_ptr<eval::VideoScorer> in;
  ASSERT_TRUE(eval::VideoScorer::Create(s->intrinsics(), eval::VideoScorerOptions(), &in).ok());
  for (const cv::Mat& f : rendered) ASSERT_TRUE(in->Add(f).ok());
  const double input_bg = in->Compute().background_jitter_px;
  // The same frames read back from the file (ScoreVideoFile, as
  // steadiface_score_video scores a clip): every frame, the size, and the
  // background's jitter, which the guessed camera does not change.
  eval::VideoFileScore file;
  ASSERT_TRUE(eval::ScoreVideoFile(input, eval::VideoScorerOptions(), &file).ok());
  EXPECT_EQ(file.score.frames, s->num_frames());
  EXPECT_EQ(file.width, 480);
  EXPECT_EQ(file.height, 270);
  EXPECT_NEAR(file.score.background_jitter_px, input_bg, 0.05 * input_bg);
  EXPECT_FALSE(eval::ScoreVideoFile(std::string(dir) + "/missing.mkv",
                                    eval::VideoScorerOptions(), &file).ok());
  for (auto method : {eval::FfmpegMethod::kVidstab, eval::FfmpegMethod::kDeshake}) {
    int n = 0;
    double seconds = 0.0;
    std::unique_ptr<eval::VideoScorer> v;
    ASSERT_TRUE(eval::VideoScorer::Create(s->intrinsics(), eval::VideoScorerOptions(), &v).ok());
    const Status st = eval::RunFfmpegStabilizer(
        method, input, 480, 270, dir,
        [&](const cv::Mat& f) {
          ++n;
          return v->Add(f);
        },
        &seconds);
    ASSERT_TRUE(st.ok()) << st.message();
    EXPECT_EQ(n, s->num_frames()) << eval::FfmpegMethodName(method);
    EXPECT_GT(seconds, 0.0);
    const eval::Score sc = v->Compute();
    EXPECT_TRUE(std::isfinite(sc.background_jitter_px)) << eval::FfmpegMethodName(method);
    EXPECT_TRUE(std::isfinite(sc.head_jitter_px)) << eval::FfmpegMethodName(method);
    // What comes back is the peer's stabilized video, not the input.
    std::cout << "[ " << eval::FfmpegMethodName(method) << " ] background " << sc.background_jitter_px
              << " px (input " << input_bg << "), head " << sc.head_jitter_px << " px, "
              << 1000.0 * seconds / n << " ms/frame\n";
    EXPECT_LT(sc.background_jitter_px, 0.9 * input_bg) << eval::FfmpegMethodName(method);
  }
  std::remove(input.c_str());
  EXPECT_NE(access((std::string(dir) + "/vidstab.trf").c_str(), F_OK), 0)
      << "RunFfmpegStabilizer leaves no transforms file behind";
  rmdir(dir);
}

}  // namespace
}  // namespace steadiface
