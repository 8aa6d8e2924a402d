// RunEvaluation (steadiface_evaluate's library): its table row is the
// scorecard of the same run made directly, its files are there with a row
// per frame, and a request it cannot serve is refused with exit status 2.
#include "steadiface_core/eval/evaluation.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "sim_util.h"
#include "steadiface_core/eval/calibration_sweep.h"
#include "steadiface_core/eval/run_methods.h"

namespace steadiface {
namespace {

std::string TempDir() {
  char tmpl[] = "/tmp/steadiface_evaluation_test_XXXXXX";
  EXPECT_NE(mkdtemp(tmpl), nullptr);
  return tmpl;
}

int Lines(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) ++n;
  return n;
}

eval::EvaluationOptions ShortStill(const std::string& out_dir) {
  eval::EvaluationOptions o;
  o.data_dir = STEADIFACE_TEST_DATA_DIR;
  o.out_dir = out_dir;
  o.presets = {"still"};
  o.methods = {"none", "gyro-only"};
  o.duration_s = 0.5;
  return o;
}

TEST(EvaluationTest, RowsAreTheScorecardsOfTheSameRuns) {
  const std::string dir = TempDir();
  std::ostringstream out, err;
  ASSERT_EQ(eval::RunEvaluation(ShortStill(dir), out, err), 0) << err.str();
  // The same run made directly: the simulator, the method's options, the scorecard.
  const std::unique_ptr<sim::Simulator> sim = testing_util::MakeSimulator(
      "still", [](sim::SimulatorOptions* so) { so->duration_s = 0.5; });
  ASSERT_NE(sim, nullptr);
  const PipelineOptions po = eval::OptionsFor(*sim, eval::Method::kGyroOnly);
  std::unique_ptr<eval::Scorecard> card;
  ASSERT_TRUE(eval::MakeScorecard(*sim, po, &card).ok());
  ASSERT_TRUE(eval::RunMethod(*sim, eval::Method::kGyroOnly, po, card.get()).ok());
  const eval::Score sc = card->Compute();
  char expected[160];
  std::snprintf(expected, sizeof(expected), "| still | gyro-only | %.2f | %.3f |",
                sc.head_jitter_px, 100 * sc.head_jitter_frac);
  ASSERT_TRUE(std::isfinite(sc.head_jitter_px));
  EXPECT_NE(out.str().find(expected), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("| still | none | "), std::string::npos);
  // A trajectory per method with a row per frame, and both runs in the report.
  const int frames = sim->num_frames();
  EXPECT_EQ(Lines(dir + "/traj_still_none.csv"), frames + 1);
  EXPECT_EQ(Lines(dir + "/traj_still_gyro-only.csv"), frames + 1);
  std::ifstream json(dir + "/report.json");
  const std::string report((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("\"method\": \"gyro-only\", \"scoring\": \"exact\", \"frames\": " +
                        std::to_string(sc.frames)),
            std::string::npos)
      << report;
  std::remove((dir + "/traj_still_none.csv").c_str());
  std::remove((dir + "/traj_still_gyro-only.csv").c_str());
  std::remove((dir + "/report.json").c_str());
  rmdir(dir.c_str());
}

TEST(EvaluationTest, UnknownMethodsAndPresetsAreRefused) {
  const std::string dir = TempDir();
  eval::EvaluationOptions o = ShortStill(dir);
  o.methods = {"gyro-only", "sideways"};
  std::ostringstream out, err;
  EXPECT_EQ(eval::RunEvaluation(o, out, err), 2);
  EXPECT_NE(err.str().find("unknown method sideways"), std::string::npos);
  o.methods = {"none"};
  o.peer.vidstab_zoom_percent = 100.0;  // would show nothing
  std::ostringstream out1, err1;
  EXPECT_EQ(eval::RunEvaluation(o, out1, err1), 2);
  EXPECT_NE(err1.str().find("--vidstab-zoom must be in"), std::string::npos) << err1.str();
  o.peer.vidstab_zoom_percent = NAN;
  o.presets = {"no_such_preset"};
  std::ostringstream out2, err2;
  EXPECT_EQ(eval::RunEvaluation(o, out2, err2), 1);  // ran, and that preset failed
  EXPECT_NE(err2.str().find("preset no_such_preset: unknown preset"), std::string::npos)
      << err2.str();
  std::remove((dir + "/report.json").c_str());
  rmdir(dir.c_str());
}

// A method run with options that conflict (the composite with the dynamic
// crop) runs, and is said once on err; a negative stress is refused.
TEST(EvaluationTest, ConflictingOptionsAreSaidAndNegativeStressesRefused) {
  const std::string dir = TempDir();
  eval::EvaluationOptions o = ShortStill(dir);
  o.presets = {"still", "vlog"};
  o.methods = {"gyro-only", "steadiface-composite"};
  o.view.crop_mode = 1;  // dynamic
  std::ostringstream out, err;
  EXPECT_EQ(eval::RunEvaluation(o, out, err), 0) << err.str();
  const std::string said = "steadiface-composite: warning: the composite's matte";
  const size_t at = err.str().find(said);
  EXPECT_NE(at, std::string::npos) << err.str();
  EXPECT_EQ(err.str().find(said, at + 1), std::string::npos) << err.str();  // once
  EXPECT_EQ(err.str().find("gyro-only: warning"), std::string::npos) << err.str();
  o.view.crop_mode = 0;  // fixed: no conflict
  std::ostringstream out2, err2;
  EXPECT_EQ(eval::RunEvaluation(o, out2, err2), 0) << err2.str();
  EXPECT_EQ(err2.str().find("warning"), std::string::npos) << err2.str();
  o.head_jitter_scale = -1.0;
  std::ostringstream out3, err3;
  EXPECT_EQ(eval::RunEvaluation(o, out3, err3), 1);
  EXPECT_NE(err3.str().find("--head-jitter must be >= 0"), std::string::npos) << err3.str();
  o.head_jitter_scale = NAN;
  o.head_turn_speed = 0.0;
  std::ostringstream out4, err4;
  EXPECT_EQ(eval::RunEvaluation(o, out4, err4), 1);
  EXPECT_NE(err4.str().find("--head-turn-speed must be in"), std::string::npos) << err4.str();
  std::filesystem::remove_all(dir);
}

TEST(EvaluationTest, ViewOverridesChangeOnlyWhatTheyName) {
  PipelineOptions po, before;
  eval::ViewOverrides v;
  ASSERT_TRUE(eval::ApplyViewOverrides(v, &po).ok());  // nothing set: nothing changes
  EXPECT_EQ(po.crop.mode, before.crop.mode);
  EXPECT_EQ(po.horizon.mode, before.horizon.mode);
  EXPECT_EQ(po.crop.widest_crop_ratio, before.crop.widest_crop_ratio);
  v.crop_mode = 1;
  v.horizon = "lock";
  v.widest = 0.05;
  v.start_tight = true;
  ASSERT_TRUE(eval::ApplyViewOverrides(v, &po).ok());
  EXPECT_EQ(po.crop.mode, CropMode::kDynamic);
  EXPECT_EQ(po.horizon.mode, HorizonMode::kLock);
  EXPECT_EQ(po.crop.widest_crop_ratio, 0.05);
  EXPECT_FALSE(po.crop.start_wide);
  EXPECT_EQ(po.crop.headroom, before.crop.headroom);
  v.horizon = "sideways";
  EXPECT_FALSE(eval::ApplyViewOverrides(v, &po).ok());
}

// The sweep's default grid pairs each permutation with one offset x
// readout cell in turn, so every permutation, offset and readout appears.
TEST(CalibrationSweepTest, TheCyclingGridCoversEveryValue) {
  eval::CalibrationSweepOptions o;
  o.formats = {"640x360"};
  o.seeds = {1};
  const std::vector<eval::SweepJob> jobs = eval::SweepJobs(o);
  ASSERT_EQ(jobs.size(), 24u);
  std::set<int> perms;
  std::set<double> offsets, readouts;
  for (const auto& j : jobs) {
    perms.insert(j.permutation);
    offsets.insert(j.offset_s);
    readouts.insert(j.readout_s);
  }
  EXPECT_EQ(perms.size(), 24u);
  EXPECT_EQ(offsets.size(), o.offsets.size());
  EXPECT_EQ(readouts.size(), o.readouts.size());
  o.full = true;
  EXPECT_EQ(eval::SweepJobs(o).size(), 24u * o.offsets.size() * o.readouts.size());
}

// One recording of the sweep: a permuted, tilted IMU 12 ms late and a 10 ms
// readout, calibrated from nothing configured.
TEST(CalibrationSweepTest, OneRecordingIsCalibrated) {
  eval::CalibrationSweepOptions o;
  o.data_dir = STEADIFACE_TEST_DATA_DIR;
  const eval::SweepJob job{"640x360", 1, 5, 0.012, 0.010};
  CalibrationResult r;
  Eigen::Quaterniond mounting;
  const Status st = eval::RunSweepJob(o, job, &r, &mounting);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_NEAR(r.time_offset_s, 0.012, 0.001);
  EXPECT_NEAR(r.readout_s, 0.010, 0.002);
  EXPECT_LT(r.R_cam_imu.angularDistance(mounting) * 180.0 / M_PI, 0.3);
  EXPECT_GT(mounting.angularDistance(Eigen::Quaterniond::Identity()), 0.5);  // not trivial
}

}  // namespace
}  // namespace steadiface
