// config/default.yaml and config/Steadiface.cfg restate the core's option
// defaults for users; these tests keep the three in step, and check that
// LoadOptions rejects bad values with a message naming the key.
#include "steadiface_ros/params.h"

#include <cstdio>
#include <fstream>
#include <iterator>
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

TEST(ParamsTest, FileParametersResolvePackageUrls) {
  const std::string cascade = ::testing::TempDir() + "steadiface_params_cascade.yaml";
  {
    std::ofstream f(cascade);
    f << "face:\n  detector: opencv_cascade\n";
  }
  std::unique_ptr<ParamSource> yaml;
  ASSERT_TRUE(YamlParams({kDefaultYaml, cascade}, &yaml).ok());
  steadiface::PipelineOptions po;
  WrapperOptions wo;
  ASSERT_TRUE(LoadOptions(*yaml, &po, &wo).ok());
  std::remove(cascade.c_str());
  // package:// needs ROS_PACKAGE_PATH; the catkin test environment has it.
  const std::string& path = po.face.detector.cascade_path;
  EXPECT_EQ(path.find("://"), std::string::npos) << path;
  EXPECT_NE(path.find("/data/haarcascade_frontalface_default.xml"), std::string::npos) << path;
  const std::string shipped = ReadFile(path);
  EXPECT_GT(shipped.size(), 900000u) << path;
  // Where the system copy exists (Debian's opencv-data), it is the same file.
  const std::string system = ReadFile(steadiface::FaceDetectorOptions().cascade_path);
  if (!system.empty()) EXPECT_TRUE(shipped == system);

  const std::string overlay = ::testing::TempDir() + "steadiface_params_url.yaml";
  {
    std::ofstream f(overlay);
    f << "face:\n  landmark_model: package://no_such_package_xyz/model.dat\n";
  }
  ASSERT_TRUE(YamlParams({kDefaultYaml, overlay}, &yaml).ok());
  const steadiface::Status s = LoadOptions(*yaml, &po, &wo);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("face/landmark_model"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("no_such_package_xyz"), std::string::npos) << s.message();
  std::remove(overlay.c_str());

  // The dlib detector does not use the cascade: an unresolvable cascade URL
  // is kept as it is, not an error (a run outside a sourced workspace).
  {
    std::ofstream f(overlay);
    f << "face:\n  cascade_path: package://no_such_package_xyz/c.xml\n";
  }
  ASSERT_TRUE(YamlParams({kDefaultYaml, overlay}, &yaml).ok());
  steadiface::PipelineOptions dlib;
  const steadiface::Status ok = LoadOptions(*yaml, &dlib, &wo);
  EXPECT_TRUE(ok.ok()) << ok.message();
  EXPECT_EQ(dlib.face.detector.cascade_path, "package://no_such_package_xyz/c.xml");
  std::remove(overlay.c_str());
}

TEST(ParamsTest, ReconfigureDefaultsAreTheCoreDefaults) {
  dynamic_reconfigure::Config from_cfg, from_core;
  steadiface::SteadifaceConfig::__getDefault__().__toMessage__(from_cfg);
  ConfigFromOptions(steadiface::StabilizerOptions(), steadiface::WarpOptions())
      .__toMessage__(from_core);
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
  steadiface::WarpMode mode = steadiface::WarpMode::kGlobal;
  steadiface::LayeredWarpOptions layered;
  ApplyConfig(c, &mode, &layered);
  EXPECT_EQ(mode, steadiface::WarpMode::kLayered);
  EXPECT_DOUBLE_EQ(layered.blend.band_width, 0.8);
  EXPECT_FALSE(layered.region.torso);
  c.warp_mode = "sideways";  // not a mode: left as it was
  ApplyConfig(c, &mode, &layered);
  EXPECT_EQ(mode, steadiface::WarpMode::kLayered);
}

TEST(ParamsTest, AnOutOfRangeValueNamesItsKey) {
  const std::string path = ::testing::TempDir() + "steadiface_params_test.yaml";
  {
    std::ofstream f(path);
    f << "output:\n  crop_ratio: 0.7\n";
  }
  std::unique_ptr<ParamSource> yaml;
  ASSERT_TRUE(YamlParams({kDefaultYaml, path}, &yaml).ok());
  steadiface::PipelineOptions po;
  WrapperOptions wo;
  const steadiface::Status s = LoadOptions(*yaml, &po, &wo);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("output/crop_ratio"), std::string::npos) << s.message();
  std::remove(path.c_str());
}

}  // namespace
}  // namespace steadiface_ros
