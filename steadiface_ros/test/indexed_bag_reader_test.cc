// IndexedBagReader against rosbag::View: the same messages, bytes and times
// in the same order, on bags written by rosbag::Bag itself (chunks
// uncompressed and LZ4, many chunks, times out of order, ties between
// connections, two connections on one topic); the bags it must refuse;
// corrupt files.
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include "steadiface_bag/indexed_bag_reader.h"

namespace steadiface_bag {
namespace {

struct Seen {
  std::string topic;
  ros::Time time;
  std::vector<uint8_t> bytes;
  bool operator==(const Seen& o) const {
    return topic == o.topic && time == o.time && bytes == o.bytes;
  }
};

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/steadiface_bag_reader_testXXXXXX";
    const char* d = mkdtemp(tmpl);
    path_ = d != nullptr ? d : "/tmp";
  }
  ~TempDir() { std::system(("rm -rf '" + path_ + "'").c_str()); }
  std::string File(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

std::vector<Seen> ReadWithView(const std::string& path,
                               const std::vector<std::string>& topics) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::vector<Seen> out;
  for (const rosbag::MessageInstance& m :
       rosbag::View(bag, rosbag::TopicQuery(topics))) {
    Seen s;
    s.topic = m.getTopic();
    s.time = m.getTime();
    s.bytes.resize(m.size());
    ros::serialization::OStream os(s.bytes.data(), s.bytes.size());
    m.write(os);
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<Seen> ReadIndexed(const std::string& path,
                              const std::vector<std::string>& topics,
                              bool verify_checksums, std::string* error) {
  IndexedBagReader reader(verify_checksums);
  std::string why;
  EXPECT_TRUE(reader.Open(path, &why)) << why;
  reader.Select(topics);
  std::vector<Seen> out;
  IndexedBagReader::Message m;
  while (reader.Next(&m, error)) {
    Seen s;
    s.topic = reader.connections().at(m.connection).topic;
    s.time = m.time;
    s.bytes.assign(m.data, m.data + m.size);
    out.push_back(std::move(s));
  }
  return out;
}

// Image i: small and regular, or (`noise`) 64 x 64 of pseudo-random
// pixels, so that chunk data outweighs the index.
sensor_msgs::Image MakeImage(int i, bool noise = false) {
  sensor_msgs::Image im;
  im.header.seq = i;
  im.header.frame_id = "camera";
  im.width = noise ? 64 : 16 + i % 5;
  im.height = noise ? 64 : 8;
  im.encoding = "mono8";
  im.step = im.width;
  im.data.resize(im.width * im.height);
  std::mt19937 rng(i);
  for (size_t k = 0; k < im.data.size(); ++k) {
    im.data[k] = static_cast<uint8_t>(noise ? rng() : k * 7 + i);
  }
  return im;
}

// A bag with the traits that decide View's order: images and camera_info
// at the same stamps, IMU on a grid that meets the image stamps every third
// frame, a second IMU connection (another publisher) on the same topic, a
// few messages written out of time order, and chunks small enough that
// they split mid-stream.
void WriteBag(const std::string& path,
              rosbag::compression::CompressionType compression,
              uint32_t chunk_threshold, bool shuffle,
              bool noisy_images = false) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(compression);
  bag.setChunkThreshold(chunk_threshold);
  std::mt19937 rng(5);
  ros::M_string other_publisher;
  other_publisher["callerid"] = "/imu_driver_2";
  other_publisher["topic"] = "/imu";
  other_publisher["type"] = ros::message_traits::datatype<sensor_msgs::Imu>();
  other_publisher["md5sum"] = ros::message_traits::md5sum<sensor_msgs::Imu>();
  other_publisher["message_definition"] =
      ros::message_traits::definition<sensor_msgs::Imu>();
  const ros::Time t0(1700000000, 0);
  for (int i = 0; i < 60; ++i) {
    const ros::Time ti = t0 + ros::Duration(i / 30.0);
    for (int k = 0; k < 7; ++k) {
      sensor_msgs::Imu imu;
      imu.header.seq = i * 7 + k;
      imu.angular_velocity.x = 0.01 * k;
      ros::Time tk = t0 + ros::Duration(0.005 * (i * 7 + k));
      if (shuffle && rng() % 11 == 0)
        tk -= ros::Duration(0.02);  // late arrival
      if (k == 3) {
        bag.write("/imu", tk, imu,
                  boost::make_shared<ros::M_string>(other_publisher));
      } else {
        bag.write("/imu", tk, imu);
      }
    }
    sensor_msgs::CameraInfo info;
    info.header.seq = i;
    info.width = 16;
    bag.write("camera/camera_info", ti, info);
    bag.write("/camera/image_raw", ti, MakeImage(i, noisy_images));
  }
  bag.close();
}

struct Case {
  rosbag::compression::CompressionType compression;
  uint32_t chunk_threshold;
  bool shuffle;
};

class IndexedBagReaderOrderTest : public ::testing::TestWithParam<Case> {};

TEST_P(IndexedBagReaderOrderTest, SameMessagesAndOrderAsRosbagView) {
  TempDir dir;
  const std::string path = dir.File("order.bag");
  WriteBag(path, GetParam().compression, GetParam().chunk_threshold,
           GetParam().shuffle);
  for (const std::vector<std::string>& topics :
       {std::vector<std::string>{"/imu", "/camera/image_raw",
                                 "camera/camera_info"},
        std::vector<std::string>{"/imu", "imu", "/camera/image_raw",
                                 "camera/image_raw"},
        std::vector<std::string>{"/camera/image_raw"},
        std::vector<std::string>{"nothing"}}) {
    const std::vector<Seen> want = ReadWithView(path, topics);
    {
      IndexedBagReader counter;
      std::string why;
      ASSERT_TRUE(counter.Open(path, &why)) << why;
      EXPECT_EQ(counter.Count(topics), want.size()) << topics.front();
    }
    for (bool verify : {false, true}) {
      std::string error;
      const std::vector<Seen> got = ReadIndexed(path, topics, verify, &error);
      EXPECT_TRUE(error.empty()) << error;
      ASSERT_EQ(got.size(), want.size()) << topics.front();
      for (size_t i = 0; i < want.size(); ++i) {
        ASSERT_TRUE(got[i] == want[i])
            << "message " << i << ": " << got[i].topic << " at " << got[i].time
            << " against " << want[i].topic << " at " << want[i].time;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Bags, IndexedBagReaderOrderTest,
    ::testing::Values(Case{rosbag::compression::Uncompressed, 768 * 1024,
                           false},
                      Case{rosbag::compression::LZ4, 768 * 1024, false},
                      Case{rosbag::compression::LZ4, 1500, true},
                      Case{rosbag::compression::Uncompressed, 1500, true},
                      Case{rosbag::compression::LZ4, 1, true}));

TEST(IndexedBagReaderTest, TheBagMatchesWhatWasWritten) {
  // Not only the same as View: the image bytes deserialize to the image.
  TempDir dir;
  const std::string path = dir.File("content.bag");
  WriteBag(path, rosbag::compression::LZ4, 4000, false);
  IndexedBagReader reader;
  std::string why;
  ASSERT_TRUE(reader.Open(path, &why)) << why;
  reader.Select({"/camera/image_raw"});
  IndexedBagReader::Message m;
  std::string error;
  int n = 0;
  while (reader.Next(&m, &error)) {
    EXPECT_EQ(reader.connections().at(m.connection).datatype,
              "sensor_msgs/Image");
    sensor_msgs::Image im;
    ros::serialization::IStream s(const_cast<uint8_t*>(m.data), m.size);
    ros::serialization::deserialize(s, im);
    const sensor_msgs::Image want = MakeImage(n);
    EXPECT_EQ(im.header.seq, want.header.seq);
    EXPECT_EQ(im.width, want.width);
    EXPECT_EQ(im.data, want.data);
    EXPECT_EQ(m.time, ros::Time(1700000000, 0) + ros::Duration(n / 30.0));
    ++n;
  }
  EXPECT_TRUE(error.empty()) << error;
  EXPECT_EQ(n, 60);
}

TEST(IndexedBagReaderTest, RefusesWhatItDoesNotRead) {
  TempDir dir;
  IndexedBagReader reader;
  std::string why;
  // BZ2 chunks: the caller reads them through rosbag::View.
  const std::string bz2 = dir.File("bz2.bag");
  WriteBag(bz2, rosbag::compression::BZ2, 768 * 1024, false);
  EXPECT_FALSE(reader.Open(bz2, &why));
  EXPECT_NE(why.find("bz2"), std::string::npos) << why;
  EXPECT_FALSE(reader.Open(dir.File("missing.bag"), &why));
  EXPECT_NE(why.find("cannot open"), std::string::npos) << why;
  const std::string text = dir.File("text.bag");
  std::ofstream(text) << "not a bag\n";
  EXPECT_FALSE(reader.Open(text, &why));
  EXPECT_NE(why.find("version 2.0"), std::string::npos) << why;
}

std::vector<char> Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)),
                           std::istreambuf_iterator<char>());
}

void Spill(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), bytes.size());
}

// Writes `bytes` to `path`: Open must refuse it, saying `reason`.
void ExpectRefused(const std::string& path, const std::vector<char>& bytes,
                   const std::string& reason) {
  Spill(path, bytes);
  IndexedBagReader reader;
  std::string why;
  EXPECT_FALSE(reader.Open(path, &why)) << path;
  EXPECT_NE(why.find(reason), std::string::npos) << why;
}

// Cut anywhere: either refused at Open (the index is at the end) or, if
// the cut leaves the index, an error while reading.
void ExpectCutsRefused(const std::vector<char>& bytes, TempDir* dir) {
  for (size_t cut : {size_t{20}, size_t{4200}, bytes.size() / 2, bytes.size() - 10}) {
    const std::string path = dir->File("cut.bag");
    Spill(path, std::vector<char>(bytes.begin(), bytes.begin() + cut));
    IndexedBagReader reader;
    std::string why;
    EXPECT_FALSE(reader.Open(path, &why)) << "cut at " << cut;
    EXPECT_FALSE(why.empty());
  }
}

// An index time out of ros::Time's range (it throws on construction):
// refused, not thrown. Index entries are the (sec, nsec) pairs of the first
// stamp not behind a "name=" (message and chunk headers have one).
void ExpectBadIndexTimeRefused(std::vector<char> bad, TempDir* dir) {
  const uint32_t sec = 1700000000, nsec = 0;
  char pattern[8];
  std::memcpy(pattern, &sec, 4);
  std::memcpy(pattern + 4, &nsec, 4);
  size_t hits = 0;
  for (size_t i = 1; i + 8 <= bad.size(); ++i) {
    if (bad[i - 1] != '=' && std::memcmp(&bad[i], pattern, 8) == 0) {
      std::memset(&bad[i], 0xff, 8);
      ++hits;
    }
  }
  ASSERT_GT(hits, 0u);
  ExpectRefused(dir->File("bad_time.bag"), bad, "bad index");
}

// A chunk header stating an uncompressed size its LZ4 data cannot hold
// (damage): refused at Open, not allocated (4 GB) when the chunk is read.
void ExpectImpossibleChunkSizeRefused(std::vector<char> bad, TempDir* dir) {
  const std::string field = "compression=lz4";
  const auto at = std::search(bad.begin(), bad.end(), field.begin(), field.end());
  ASSERT_NE(at, bad.end());
  // The chunk header's next field: <len>"size=" + 4 bytes.
  const std::string size_field = "size=";
  const auto sz = std::search(at, bad.end(), size_field.begin(), size_field.end());
  ASSERT_NE(sz, bad.end());
  ASSERT_LT(sz - at, 64);
  const uint32_t huge = 0xfffffff0u;
  std::memcpy(&*(sz + size_field.size()), &huge, 4);
  ExpectRefused(dir->File("huge_size.bag"), bad, "impossible size");
}

// Noise over the first half of the file, which is mostly LZ4 chunk data
// (pseudo-random images do not compress), in 20 trials: how many ended in
// an error. Every Next either gives a message within its chunk or stops
// with an error (nothing past the buffers is read: valgrind shows that too).
int NoisyTrialsWithErrors(const std::vector<char>& bytes, bool verify, TempDir* dir) {
  std::mt19937 rng(3);
  int errors = 0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<char> noisy = bytes;
    for (int k = 0; k < 30; ++k) {
      const size_t at = 4200 + rng() % (noisy.size() / 2);
      noisy[at] = static_cast<char>(rng());
    }
    const std::string path = dir->File("noisy.bag");
    Spill(path, noisy);
    IndexedBagReader reader(verify);
    std::string why;
    if (!reader.Open(path, &why)) continue;
    reader.Select({"/imu", "/camera/image_raw", "camera/camera_info"});
    IndexedBagReader::Message m;
    std::string error;
    int n = 0;
    while (reader.Next(&m, &error) && n < 100000) ++n;
    if (!error.empty()) ++errors;
  }
  return errors;
}

TEST(IndexedBagReaderTest, CorruptFilesGiveErrorsNotCrashes) {
  TempDir dir;
  const std::string good = dir.File("good.bag");
  WriteBag(good, rosbag::compression::LZ4, 8000, false, /*noisy_images=*/true);
  WriteBag(dir.File("small.bag"), rosbag::compression::Uncompressed, 768 * 1024,
           false);
  const std::vector<char> bytes = Slurp(good);
  ASSERT_GT(bytes.size(), 200000u);
  ExpectCutsRefused(bytes, &dir);
  ExpectBadIndexTimeRefused(Slurp(dir.File("small.bag")), &dir);
  ExpectImpossibleChunkSizeRefused(bytes, &dir);
  // A corrupt chunk is noticed; the checksums notice at least whatever the
  // bounds checks notice.
  const int without = NoisyTrialsWithErrors(bytes, false, &dir);
  const int with = NoisyTrialsWithErrors(bytes, true, &dir);
  EXPECT_GT(without, 0) << "noise in LZ4 chunks went unnoticed in every trial";
  EXPECT_GE(with, without);
  EXPECT_GT(with, 0);
}

TEST(IndexedBagReaderTest, ChunksWhoseTimesMeetAreReadOnce) {
  // As steadiface_simulate writes: per frame the IMU samples, then the
  // image and its camera_info with one stamp. The image closes its chunk,
  // so the camera_info opens the next one at the same time, and View's order
  // goes back and forth across that boundary. Each chunk must still be read
  // and decompressed once (with one chunk kept: 121 reads of the 83 chunks
  // here, and every chunk twice in the speed protocol's clips).
  for (const auto compression :
       {rosbag::compression::Uncompressed, rosbag::compression::LZ4}) {
    TempDir dir;
    const std::string path = dir.File("meeting.bag");
    {
      rosbag::Bag bag(path, rosbag::bagmode::Write);
      bag.setCompression(compression);
      bag.setChunkThreshold(2000);  // below one 64 x 64 image
      const ros::Time t0(1700000000, 0);
      for (int i = 0; i < 40; ++i) {
        for (int k = 0; k < 7; ++k) {
          sensor_msgs::Imu imu;
          imu.header.seq = i * 7 + k;
          bag.write("/imu", t0 + ros::Duration(0.005 * (i * 7 + k)), imu);
        }
        const ros::Time ti = t0 + ros::Duration(0.005 * (i * 7 + 6));
        bag.write("/camera/image_raw", ti, MakeImage(i, /*noise=*/true));
        sensor_msgs::CameraInfo info;
        info.header.seq = i;
        bag.write("/camera/camera_info", ti, info);
      }
    }
    const std::vector<std::string> topics = {"/imu", "/camera/image_raw",
                                             "/camera/camera_info"};
    IndexedBagReader reader;
    std::string why, error;
    ASSERT_TRUE(reader.Open(path, &why)) << why;
    reader.Select(topics);
    std::vector<Seen> seen;
    IndexedBagReader::Message m;
    while (reader.Next(&m, &error)) {
      seen.push_back(Seen{reader.connections().at(m.connection).topic, m.time,
                          std::vector<uint8_t>(m.data, m.data + m.size)});
    }
    EXPECT_TRUE(error.empty()) << error;
    EXPECT_EQ(seen, ReadWithView(path, topics));
    EXPECT_GE(reader.chunk_count(), 40u);
    EXPECT_EQ(reader.chunks_read(), reader.chunk_count());
  }
}

TEST(IndexedBagReaderTest, AFileTruncatedWhileReadGivesAnError) {
  // The chunks are read with pread() after Open(): a bag cut short by
  // another process meanwhile ends the read with an error that says so, for
  // uncompressed and LZ4 chunks. (When the chunks were read through a map,
  // the cut read as zeros, "bad record in a chunk" or an LZ4 error, and a
  // page wholly past the cut would have raised SIGBUS.)
  for (const auto compression :
       {rosbag::compression::Uncompressed, rosbag::compression::LZ4}) {
    TempDir dir;
    const std::string path = dir.File("cut_later.bag");
    WriteBag(path, compression, 8000, false, /*noisy_images=*/true);
    const std::vector<char> bytes = Slurp(path);
    const std::vector<std::string> topics = {"/imu", "/camera/image_raw",
                                             "camera/camera_info"};
    const size_t whole = ReadWithView(path, topics).size();
    IndexedBagReader reader;
    std::string why;
    ASSERT_TRUE(reader.Open(path, &why)) << why;
    reader.Select(topics);
    IndexedBagReader::Message m;
    std::string error;
    ASSERT_TRUE(reader.Next(&m, &error)) << error;
    ASSERT_EQ(truncate(path.c_str(), static_cast<off_t>(bytes.size() / 3)), 0);
    size_t n = 1;
    while (reader.Next(&m, &error)) ++n;
    EXPECT_NE(error.find("truncated"), std::string::npos)
        << "after " << n << " messages: '" << error << "'";
    EXPECT_GT(whole, 400u);
    EXPECT_LT(n, whole * 2 / 3);
  }
}

}  // namespace
}  // namespace steadiface_bag
