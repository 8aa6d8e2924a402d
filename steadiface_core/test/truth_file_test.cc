#include "steadiface_core/sim/truth_file.h"

#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_util.h"

namespace steadiface {
namespace sim {
namespace {

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "/steadiface_truth_" + name;
}

SimulationSettings Settings() {
  SimulationSettings s;
  s.preset = "shake";
  s.data_dir = "/some dir/with spaces";
  s.base.width = 320;
  s.base.height = 180;
  s.base.fps = 25.0;
  s.base.duration_s = 1.5;
  s.base.hfov_rad = 0.9;
  s.base.imu_rate_hz = 400.0;
  s.base.imu_clock_offset_s = 0.012;
  s.base.seed = 7;
  s.base.background_photo = "leuvenA.jpg";
  s.base.render_face = false;
  s.readout_s = 0.031;
  s.epoch_s = 1.7e9;
  return s;
}

TEST(TruthFileTest, WhatTheWriterWritesTheReaderReadsBack) {
  const std::string path = TempPath("roundtrip.csv");
  SimTruth t;
  t.head_px = Eigen::Vector2d(123.456789012345, -7.25);
  t.head_in_view = true;
  t.face_scale_px = 88.5;
  t.second_face = true;
  for (int r = 0; r < 16; ++r) {
    t.R_r.push_back(Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * r, Eigen::Vector3d(1, 2, 3).normalized())));
  }
  {
    std::ofstream f(path);
    TruthFileWriter w(&f, Settings());
    w.Add(0, 1700000000.0, t);
    w.Add(1, 1700000000.04, t);
  }
  SimulationSettings s;
  bool has = false;
  std::vector<TruthRow> rows;
  ASSERT_TRUE(ReadTruthFile(path, &s, &has, &rows).ok());
  ASSERT_TRUE(has);
  const SimulationSettings e = Settings();
  EXPECT_EQ(s.preset, e.preset);
  EXPECT_EQ(s.data_dir, e.data_dir);
  EXPECT_EQ(s.base.width, 320);
  EXPECT_EQ(s.base.height, 180);
  EXPECT_EQ(s.base.fps, 25.0);
  EXPECT_EQ(s.base.duration_s, 1.5);
  EXPECT_EQ(s.base.hfov_rad, 0.9);
  EXPECT_EQ(s.base.imu_rate_hz, 400.0);
  EXPECT_EQ(s.base.imu_clock_offset_s, 0.012);
  EXPECT_EQ(s.base.seed, 7u);
  EXPECT_EQ(s.base.background_photo, "leuvenA.jpg");
  EXPECT_FALSE(s.base.render_face);
  EXPECT_EQ(s.readout_s, 0.031);
  EXPECT_EQ(s.epoch_s, 1.7e9);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].frame, 1);
  EXPECT_EQ(rows[1].stamp_s, 1700000000.04);
  EXPECT_EQ(rows[0].truth.head_px, t.head_px);  // full precision
  EXPECT_TRUE(rows[0].truth.head_in_view);
  EXPECT_EQ(rows[0].truth.face_scale_px, 88.5);
  EXPECT_FALSE(rows[0].truth.occluded);
  EXPECT_TRUE(rows[0].truth.second_face);
  ASSERT_EQ(rows[0].truth.R_r.size(), 16u);
  EXPECT_TRUE(rows[0].truth.R_r[15].coeffs() == t.R_r[15].coeffs());
  const auto by_ms = FramesByStampMs(rows);
  EXPECT_EQ(by_ms.at(1700000000040), 1);
  std::remove(path.c_str());
}

TEST(TruthFileTest, TheSettingsRebuildThePresetWithTheirOverrides) {
  SimulatorOptions preset;
  ASSERT_TRUE(ApplyPreset("shake", &preset).ok());
  SimulatorOptions o;
  ASSERT_TRUE(MakeSimulatorOptions(Settings(), &o).ok());
  EXPECT_EQ(o.duration_s, 1.5);   // restored after the preset
  EXPECT_EQ(o.readout_s, 0.031);  // set after it
  EXPECT_EQ(o.seed, 7u);
  EXPECT_EQ(o.data_dir, "/some dir/with spaces");
  SimulationSettings keep = Settings();
  keep.readout_s = -1.0;
  ASSERT_TRUE(MakeSimulatorOptions(keep, &o).ok());
  EXPECT_EQ(o.readout_s, preset.readout_s);  // the preset's
  keep.preset = "no_such_preset";
  EXPECT_FALSE(MakeSimulatorOptions(keep, &o).ok());
}

TEST(TruthFileTest, ARebuiltSimulationReproducesTheRecordedTruth) {
  SimulationSettings s;
  s.preset = "walk";
  s.data_dir = STEADIFACE_TEST_DATA_DIR;
  s.base.duration_s = 0.5;
  s.base.width = 320;
  s.base.height = 180;
  SimulatorOptions o;
  ASSERT_TRUE(MakeSimulatorOptions(s, &o).ok());
  std::unique_ptr<Simulator> a, b;
  ASSERT_TRUE(Simulator::Create(o, &a).ok());
  const std::string path = TempPath("rebuild.csv");
  {
    std::ofstream f(path);
    TruthFileWriter w(&f, s);
    for (int i = 0; i < a->num_frames(); ++i) w.Add(i, ToSeconds(a->Truth(i).stamp), a->Truth(i));
  }
  SimulationSettings read;
  bool has = false;
  std::vector<TruthRow> rows;
  ASSERT_TRUE(ReadTruthFile(path, &read, &has, &rows).ok());
  ASSERT_TRUE(MakeSimulatorOptions(read, &o).ok());
  ASSERT_TRUE(Simulator::Create(o, &b).ok());
  ASSERT_EQ(b->num_frames(), static_cast<int>(rows.size()));
  for (const TruthRow& r : rows) {
    const SimTruth t = b->Truth(r.frame);
    EXPECT_EQ(t.head_in_view, r.truth.head_in_view);
    EXPECT_NEAR((t.head_px - r.truth.head_px).norm(), 0.0, 1e-9) << r.frame;
    EXPECT_NEAR(t.R_r[7].angularDistance(r.truth.R_r[7]), 0.0, 1e-12) << r.frame;
  }
  std::remove(path.c_str());
}

TEST(TruthFileTest, FilesThatAreNotTruthAreRefusedWithAReason) {
  SimulationSettings s;
  bool has = true;
  std::vector<TruthRow> rows;
  EXPECT_FALSE(ReadTruthFile(TempPath("missing.csv"), &s, &has, &rows).ok());
  const std::string path = TempPath("bad.csv");
  std::ofstream(path) << "stamp,qx\n1,2\n";
  Status st = ReadTruthFile(path, &s, &has, &rows);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("not a steadiface truth file"), std::string::npos) << st.message();
  std::ofstream(path) << "frame,stamp,head_x\n0,1.0,2\n";
  st = ReadTruthFile(path, &s, &has, &rows);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("line 2"), std::string::npos) << st.message();
  // An older file without the settings line: rows, and no settings.
  {
    std::ostringstream full;
    SimTruth t;
    t.R_r.assign(16, Eigen::Quaterniond::Identity());
    TruthFileWriter w(&full, SimulationSettings());
    w.Add(3, 2.5, t);
    const std::string text = full.str();
    std::ofstream(path) << text.substr(text.find('\n') + 1);  // no settings line
  }
  ASSERT_TRUE(ReadTruthFile(path, &s, &has, &rows).ok());
  EXPECT_FALSE(has);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].frame, 3);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace sim
}  // namespace steadiface
