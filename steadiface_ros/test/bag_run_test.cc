// RunBag (steadiface_bag's run) on the simulated rostest bag: every image
// comes out stabilized into the output bag, the trajectory has a row per
// frame, the report scores the run against the bag's ground truth, and bad
// requests end with the tool's exit statuses and leave no output behind.
#include "steadiface_bag/bag_run.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

namespace steadiface_bag {
namespace {

class BagRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/steadiface_bag_run_test_XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    o_.in = STEADIFACE_TEST_BAG;
    o_.quiet = true;
  }
  void TearDown() override {
    for (const char* f : {"/out.bag", "/out.bag.part", "/traj.csv", "/report.json", "/stamps"}) {
      std::remove((dir_ + f).c_str());
    }
    rmdir(dir_.c_str());
  }
  static size_t Count(const std::string& bag, const std::string& topic) {
    rosbag::Bag b(bag, rosbag::bagmode::Read);
    return rosbag::View(b, rosbag::TopicQuery(topic)).size();
  }
  static std::string Read(const std::string& path) {
    std::ifstream f(path);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  }
  std::string dir_;
  BagRunOptions o_;
};

TEST_F(BagRunTest, EveryImageComesOutStabilizedAndScored) {
  o_.out = dir_ + "/out.bag";
  o_.trajectory = dir_ + "/traj.csv";
  o_.report = dir_ + "/report.json";
  ASSERT_EQ(RunBag(o_), 0);
  const size_t images = Count(o_.in, "/camera/image_raw");
  ASSERT_GT(images, 100u);
  EXPECT_EQ(Count(o_.out, "/camera/image_stabilized/image_raw"), images);
  EXPECT_EQ(Count(o_.out, "/camera/image_stabilized/camera_info"), images);
  EXPECT_EQ(Count(o_.out, "/camera/state"), images);
  const std::string traj = Read(o_.trajectory);
  EXPECT_EQ(static_cast<size_t>(std::count(traj.begin(), traj.end(), '\n')), images + 1);
  // The bag's truth file was found and the face held: the output head
  // jitters less than the input's.
  const std::string report = Read(o_.report);
  const auto number = [&report](const std::string& key) {
    const size_t at = report.find("\"" + key + "\": ");
    return at == std::string::npos ? -1.0 : std::stod(report.substr(at + key.size() + 4));
  };
  ASSERT_GT(number("head_jitter_in_px"), 0.0) << report;
  EXPECT_LT(number("head_jitter_out_px"), 0.5 * number("head_jitter_in_px")) << report;
}

TEST_F(BagRunTest, BadRequestsEndWithTheToolsStatusesAndNoOutput) {
  o_.out = dir_ + "/out.bag";
  o_.compress = "zip";
  EXPECT_EQ(RunBag(o_), 2);
  o_.compress = "lz4";
  o_.in = dir_ + "/missing.bag";
  EXPECT_EQ(RunBag(o_), 1);
  o_.in = STEADIFACE_TEST_BAG;
  std::ofstream(dir_ + "/stamps") << "\n";  // lists no frame
  o_.only_stamps = dir_ + "/stamps";
  EXPECT_EQ(RunBag(o_), 1);
  struct stat st;
  EXPECT_NE(stat(o_.out.c_str(), &st), 0);  // nothing written under the output's name
}

}  // namespace
}  // namespace steadiface_bag
