// config/default.yaml and config/Steadiface.cfg restate the core's option
// defaults for users; these tests keep the three in step, and check that
// LoadOptions rejects bad values with a message naming the key.
#include "steadiface_ros/params.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>

#include <dynamic_reconfigure/Config.h>
#include <gtest/gtest.h>

namespace steadiface_ros {
namespace {

const std::string kDefaultYaml = std::string(STEADIFACE_CONFIG_DIR) + "/default.yaml";
const std::string kPackageCascade =
    "package://steadiface/data/haarcascade_frontalface_default.xml";

// Reads through another source and records every key whose value differs
// from the one the caller passed in (LoadOptions passes the default).
class DefaultChecker : public ParamSource {
 public:
  explicit DefaultChecker(const ParamSource& inner) : inner_(inner) {}
  bool Get(const std::string& key, double* v) const override { return Check(key, v); }
  bool Get(const std::string& key, int* v) const override { return Check(key, v); }
  bool Get(const std::string& key, bool* v) const override { return Check(key, v); }
  bool Get(const std::string& key, std::string* v) const override { return Check(key, v); }
  bool Get(const std::string& key, std::vector<double>* v) const override {
    const std::vector<double> before = *v;
    const bool found = inner_.Get(key, v);
    if (found && *v != before) differs_.push_back(key);
    if (found) ++found_;
    return found;
  }
  const std::vector<std::string>& differs() const { return differs_; }
  int found() const { return found_; }

 private:
  template <typename T>
  bool Check(const std::string& key, T* v) const {
    const T before = *v;
    const bool found = inner_.Get(key, v);
    if (found) ++found_;
    if (found && !(*v == before)) {
      std::ostringstream s;
      s << key << ": default.yaml " << *v << ", core " << before;
      differs_.push_back(s.str());
    }
    return found;
  }
  const ParamSource& inner_;
  mutable std::vector<std::string> differs_;
  mutable int found_ = 0;
};

TEST(ParamsTest, DefaultYamlStatesTheCoreDefaults) {
  std::unique_ptr<ParamSource> yaml;
  ASSERT_TRUE(YamlParams({kDefaultYaml}, &yaml).ok());
  DefaultChecker checker(*yaml);
  steadiface::PipelineOptions po;
  WrapperOptions wo;
  const steadiface::Status s = LoadOptions(checker, &po, &wo);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_GT(checker.found(), 50);  // the file states (nearly) every key
  // One deliberate difference: the cascade is named by the package's own copy
  // (data/README.md), the same file as the core's default (next test).
  const std::string cascade = "face/cascade_path: default.yaml " + kPackageCascade +
                              ", core " + steadiface::FaceDetectorOptions().cascade_path;
  std::string all;
  for (const auto& d : checker.differs()) all += "\n  " + d;
  EXPECT_EQ(checker.differs(), std::vector<std::string>{cascade})
      << "default.yaml differs from the core:" << all;
}

std::string ReadFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// LoadOptions over config/default.yaml and an overlay with `yaml` (written
// to a temporary file and removed).
steadiface::Status LoadWithOverlay(const std::string& yaml, steadiface::PipelineOptions* po,
                                   WrapperOptions* wo) {
  const std::string path = ::testing::TempDir() + "steadiface_params_overlay.yaml";
  std::ofstream(path) << yaml;
  std::unique_ptr<ParamSource> source;
  steadiface::Status s = YamlParams({kDefaultYaml, path}, &source);
  if (s.ok()) s = LoadOptions(*source, po, wo);
  std::remove(path.c_str());
  return s;
}

TEST(ParamsTest, FileParametersResolvePackageUrls) {
  steadiface::PipelineOptions po;
  WrapperOptions wo;
  ASSERT_TRUE(LoadWithOverlay("face:\n  detector: opencv_cascade\n", &po, &wo).ok());
  // package:// needs ROS_PACKAGE_PATH; the catkin test environment has it.
  const std::string& path = po.face.detector.cascade_path;
  EXPECT_EQ(path.find("://"), std::string::npos) << path;
  EXPECT_NE(path.find("/data/haarcascade_frontalface_default.xml"), std::string::npos) << path;
  const std::string shipped = ReadFile(path);
  EXPECT_GT(shipped.size(), 900000u) << path;
  // Where the system copy exists (Debian's opencv-data), it is the same file.
  const std::string system = ReadFile(steadiface::FaceDetectorOptions().cascade_path);
  if (!system.empty()) EXPECT_TRUE(shipped == system);

  const steadiface::Status s = LoadWithOverlay(
      "face:\n  landmark_model: package://no_such_package_xyz/model.dat\n", &po, &wo);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("face/landmark_model"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("no_such_package_xyz"), std::string::npos) << s.message();

  // The dlib detector does not use the cascade: an unresolvable cascade URL
  // is kept as it is, not an error (a run outside a sourced workspace).
  steadiface::PipelineOptions dlib;
  const steadiface::Status ok =
      LoadWithOverlay("face:\n  cascade_path: package://no_such_package_xyz/c.xml\n", &dlib, &wo);
  EXPECT_TRUE(ok.ok()) << ok.message();
  EXPECT_EQ(dlib.face.detector.cascade_path, "package://no_such_package_xyz/c.xml");
}

TEST(ParamsTest, ReconfigureDefaultsAreTheCoreDefaults) {
  dynamic_reconfigure::Config from_cfg, from_core;
  steadiface::SteadifaceConfig::__getDefault__().__toMessage__(from_cfg);
  ConfigFromOptions(steadiface::PipelineOptions()).__toMessage__(from_core);
  ASSERT_EQ(from_cfg.doubles.size(), from_core.doubles.size());
  ASSERT_GT(from_cfg.doubles.size(), 10u);
  for (size_t i = 0; i < from_cfg.doubles.size(); ++i) {
    EXPECT_EQ(from_cfg.doubles[i].name, from_core.doubles[i].name);
    EXPECT_DOUBLE_EQ(from_cfg.doubles[i].value, from_core.doubles[i].value)
        << from_cfg.doubles[i].name;
  }
  ASSERT_EQ(from_cfg.ints.size(), from_core.ints.size());
  for (size_t i = 0; i < from_cfg.ints.size(); ++i) {
    EXPECT_EQ(from_cfg.ints[i].value, from_core.ints[i].value) << from_cfg.ints[i].name;
  }
  ASSERT_EQ(from_cfg.bools.size(), from_core.bools.size());
  for (size_t i = 0; i < from_cfg.bools.size(); ++i) {
    EXPECT_EQ(from_cfg.bools[i].value, from_core.bools[i].value) << from_cfg.bools[i].name;
  }
  ASSERT_EQ(from_cfg.strs.size(), from_core.strs.size());
  for (size_t i = 0; i < from_cfg.strs.size(); ++i) {
    EXPECT_EQ(from_cfg.strs[i].value, from_core.strs[i].value) << from_cfg.strs[i].name;
  }
}

TEST(ParamsTest, ReconfigureSwitchesTheWarpMode) {
  steadiface::SteadifaceConfig c = steadiface::SteadifaceConfig::__getDefault__();
  c.warp_mode = "layered";
  c.band_width = 0.8;
  c.torso = false;
  steadiface::PipelineOptions o;
  o.warp.mode = steadiface::WarpMode::kGlobal;
  ApplyConfig(c, &o);
  EXPECT_EQ(o.warp.mode, steadiface::WarpMode::kLayered);
  EXPECT_DOUBLE_EQ(o.warp.layered.blend.band_width, 0.8);
  EXPECT_FALSE(o.warp.layered.region.torso);
  c.warp_mode = "sideways";  // not a mode: left as it was
  ApplyConfig(c, &o);
  EXPECT_EQ(o.warp.mode, steadiface::WarpMode::kLayered);
}

// Reconfigure sets keys one at a time: a low threshold raised past its high
// one lifts the high one just above it, so the options stay valid.
TEST(ParamsTest, ReconfigureKeepsEachLowBelowItsHigh) {
  steadiface::SteadifaceConfig c = steadiface::SteadifaceConfig::__getDefault__();
  c.gyro_still = 0.5;
  c.gyro_active = 0.2;
  c.pose_low = 0.4;
  c.pose_high = 0.1;
  steadiface::PipelineOptions o;
  ApplyConfig(c, &o);
  EXPECT_DOUBLE_EQ(o.stabilizer.dynamic.gyro_active_rad_s, 0.5 + 1e-4);
  EXPECT_DOUBLE_EQ(o.stabilizer.dynamic.pose_high_rad, 0.4 + 1e-3);
  EXPECT_TRUE(steadiface::ValidatePipelineOptions(o).ok());
}

// Reads through another source and records every key asked for.
class KeyRecorder : public ParamSource {
 public:
  explicit KeyRecorder(const ParamSource& inner) : inner_(inner) {}
  bool Get(const std::string& k, double* v) const override { return Note(k, v); }
  bool Get(const std::string& k, int* v) const override { return Note(k, v); }
  bool Get(const std::string& k, bool* v) const override { return Note(k, v); }
  bool Get(const std::string& k, std::string* v) const override { return Note(k, v); }
  bool Get(const std::string& k, std::vector<double>* v) const override { return Note(k, v); }
  const std::set<std::string>& keys() const { return keys_; }

 private:
  template <typename T>
  bool Note(const std::string& k, T* v) const {
    keys_.insert(k);
    return inner_.Get(k, v);
  }
  const ParamSource& inner_;
  mutable std::set<std::string> keys_;
};

TEST(ParamsTest, LoadOptionsReadsExactlyTheTablesKeys) {
  std::unique_ptr<ParamSource> yaml;
  ASSERT_TRUE(YamlParams({kDefaultYaml}, &yaml).ok());
  KeyRecorder recorder(*yaml);
  steadiface::PipelineOptions po;
  WrapperOptions wo;
  const steadiface::Status s = LoadOptions(recorder, &po, &wo);
  ASSERT_TRUE(s.ok()) << s.message();  // every key read is in the table, with its type
  std::set<std::string> table;
  for (const ParameterSpec& p : ParameterTable()) {
    if (p.read_by_node) table.insert(p.key);
  }
  EXPECT_GT(table.size(), 120u);
  EXPECT_EQ(recorder.keys(), table);
}

TEST(ParamsTest, ReconfigureRangesAndNamesAreTheTables) {
  dynamic_reconfigure::Config lo, hi, def;
  steadiface::SteadifaceConfig::__getMin__().__toMessage__(lo);
  steadiface::SteadifaceConfig::__getMax__().__toMessage__(hi);
  steadiface::SteadifaceConfig::__getDefault__().__toMessage__(def);
  std::map<std::string, std::pair<double, double>> cfg;
  for (size_t i = 0; i < lo.doubles.size(); ++i) {
    cfg[lo.doubles[i].name] = {lo.doubles[i].value, hi.doubles[i].value};
  }
  for (size_t i = 0; i < lo.ints.size(); ++i) cfg[lo.ints[i].name] = {lo.ints[i].value, hi.ints[i].value};
  size_t dynamic = 0;
  for (const ParameterSpec& p : ParameterTable()) {
    if (std::string(p.dynamic_name).empty()) continue;
    ++dynamic;
    if (p.type != ParameterType::kDouble && p.type != ParameterType::kInt) continue;
    ASSERT_EQ(cfg.count(p.dynamic_name), 1u) << p.dynamic_name;
    EXPECT_EQ(cfg[p.dynamic_name].first, p.min) << p.key;
    EXPECT_EQ(cfg[p.dynamic_name].second, p.max) << p.key;
  }
  EXPECT_EQ(dynamic, def.doubles.size() + def.ints.size() + def.bools.size() + def.strs.size());
}

// Both directions of the reconfigure <-> options map cover every run-time
// parameter: a value set in the config survives ApplyConfig and
// ConfigFromOptions, for each parameter at once (distinct, valid values).
TEST(ParamsTest, EveryReconfigureParameterReachesTheOptionsAndBack) {
  dynamic_reconfigure::Config lo, hi, msg;
  steadiface::SteadifaceConfig::__getMin__().__toMessage__(lo);
  steadiface::SteadifaceConfig::__getMax__().__toMessage__(hi);
  steadiface::SteadifaceConfig::__getDefault__().__toMessage__(msg);
  for (size_t i = 0; i < msg.doubles.size(); ++i) {
    const double span = std::min(hi.doubles[i].value - lo.doubles[i].value, 1e4);
    msg.doubles[i].value = lo.doubles[i].value + 0.37 * span;
  }
  for (size_t i = 0; i < msg.ints.size(); ++i) msg.ints[i].value = lo.ints[i].value + 1;
  for (auto& b : msg.bools) b.value = !b.value;
  for (auto& s : msg.strs) s.value = s.value == "global" ? "layered" : "global";
  steadiface::SteadifaceConfig c = steadiface::SteadifaceConfig::__getDefault__();
  ASSERT_TRUE(c.__fromMessage__(msg));
  steadiface::PipelineOptions o;
  ApplyConfig(c, &o);
  dynamic_reconfigure::Config back;
  ConfigFromOptions(o).__toMessage__(back);
  ASSERT_EQ(back.doubles.size(), msg.doubles.size());
  for (size_t i = 0; i < msg.doubles.size(); ++i) {
    EXPECT_DOUBLE_EQ(back.doubles[i].value, msg.doubles[i].value) << msg.doubles[i].name;
  }
  for (size_t i = 0; i < msg.ints.size(); ++i) {
    EXPECT_EQ(back.ints[i].value, msg.ints[i].value) << msg.ints[i].name;
  }
  for (size_t i = 0; i < msg.bools.size(); ++i) {
    EXPECT_EQ(back.bools[i].value, msg.bools[i].value) << msg.bools[i].name;
  }
  for (size_t i = 0; i < msg.strs.size(); ++i) {
    EXPECT_EQ(back.strs[i].value, msg.strs[i].value) << msg.strs[i].name;
  }
}

TEST(ParamsTest, AChoiceOutsideTheTablesNamesTheChoices) {
  steadiface::PipelineOptions po;
  WrapperOptions wo;
  const steadiface::Status s = LoadWithOverlay("late_frame_policy: wait\n", &po, &wo);
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.message(),
            "parameter 'late_frame_policy' must be one of extrapolate | drop, got 'wait'");
  ASSERT_TRUE(
      LoadWithOverlay("late_frame_policy: drop\ncamera:\n  stamp: middle_row\n", &po, &wo).ok());
  EXPECT_EQ(wo.scheduler.late_frame_policy, steadiface::LateFramePolicy::kDrop);
  EXPECT_EQ(po.shutter.stamp, steadiface::StampConvention::kMiddleRow);
}

// The core's validation accepts every value the table's ranges allow: each
// number at its min and at its max (a pair's partner, and its partner's,
// set to the same end, so low < high still holds).
TEST(ParamsTest, TheCoreAcceptsEveryValueInTheTablesRanges) {
  const std::map<std::string, std::string> low_to_high = {
      {"face/min_spread_ratio", "face/max_spread_ratio"},
      {"dynamic/gyro_still", "dynamic/gyro_active"},
      {"dynamic/pose_low", "dynamic/pose_high"},
      {"dynamic/centre_variation_low", "dynamic/centre_variation_high"},
      {"dynamic/scale_variation_low", "dynamic/scale_variation_high"},
      {"visual/min_inliers_precise", "visual/min_inliers"},
      {"visual/min_inliers", "visual/max_features"}};
  std::map<std::string, const ParameterSpec*> spec;
  for (const ParameterSpec& p : ParameterTable()) spec[p.key] = &p;
  // A source holding only the values the test sets.
  class Values : public ParamSource {
   public:
    std::map<std::string, double> v;
    bool Get(const std::string& k, double* x) const override {
      const auto it = v.find(k);
      if (it == v.end()) return false;
      *x = it->second;
      return true;
    }
    bool Get(const std::string& k, int* x) const override {
      const auto it = v.find(k);
      if (it == v.end()) return false;
      *x = static_cast<int>(it->second);
      return true;
    }
    bool Get(const std::string&, bool*) const override { return false; }
    bool Get(const std::string&, std::string*) const override { return false; }
    bool Get(const std::string&, std::vector<double>*) const override { return false; }
  };
  int checked = 0;
  for (const ParameterSpec& p : ParameterTable()) {
    if (!p.read_by_node || (p.type != ParameterType::kDouble && p.type != ParameterType::kInt)) {
      continue;
    }
    for (const bool at_max : {false, true}) {
      Values values;
      values.v[p.key] = at_max ? p.max : p.min;
      // Partners follow along chains (a <= b <= c): repeat until none moves.
      for (size_t round = 0; round < low_to_high.size(); ++round) {
        for (const auto& pair : low_to_high) {
          if (at_max && values.v.count(pair.first) != 0) {
            values.v[pair.second] = spec[pair.second]->max;
          }
          if (!at_max && values.v.count(pair.second) != 0) {
            values.v[pair.first] = spec[pair.first]->min;
          }
        }
      }
      steadiface::PipelineOptions po;
      WrapperOptions wo;
      const steadiface::Status s = LoadOptions(values, &po, &wo);
      EXPECT_TRUE(s.ok()) << p.key << " = " << values.v[p.key] << ": " << s.message();
      ++checked;
    }
  }
  EXPECT_GT(checked, 180);
}

TEST(ParamsTest, AnOutOfRangeValueNamesItsKey) {
  steadiface::PipelineOptions po;
  WrapperOptions wo;
  const steadiface::Status s = LoadWithOverlay("output:\n  crop_ratio: 0.7\n", &po, &wo);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("output/crop_ratio"), std::string::npos) << s.message();
}

// The rotation from the video's options come from visual/*; a combination
// the core refuses (more inliers required than features tracked) names it.
TEST(ParamsTest, TheRotationFromTheVideoTakesItsKeys) {
  steadiface::PipelineOptions po;
  WrapperOptions wo;
  ASSERT_TRUE(LoadWithOverlay("rotation_source: visual\nvisual:\n  max_features: 300\n"
                              "  klt_window: 15\n  inlier_threshold: 1.5\n  body_width: 2.0\n",
                              &po, &wo)
                  .ok());
  EXPECT_EQ(po.rotation_source, steadiface::RotationSource::kVisual);
  EXPECT_EQ(po.visual.max_features, 300);
  EXPECT_EQ(po.visual.klt_window_px, 15);
  EXPECT_EQ(po.visual.inlier_threshold_px, 1.5);
  EXPECT_EQ(po.visual.body_width, 2.0);
  EXPECT_EQ(po.visual.min_inliers, steadiface::VisualRotationOptions().min_inliers);
  const steadiface::Status s = LoadWithOverlay(
      "rotation_source: visual\nvisual:\n  max_features: 10\n  min_inliers: 12\n", &po, &wo);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("max_features"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace steadiface_ros
