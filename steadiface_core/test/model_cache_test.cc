// The model cache (model_cache.h): the decoded landmark model and the
// serialized face detector give the same results as dlib's shipped forms,
// and a damaged cache file is ignored and rewritten.
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <dlib/image_processing/shape_predictor.h>
#include <dlib/opencv/cv_image.h>
#include <gtest/gtest.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "face/landmark_predictor_impl.h"
#include "steadiface_core/common/model_cache.h"
#include "steadiface_core/face/face_detector.h"
#include "steadiface_core/face/landmark_predictor.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::LoadImage;

// A value of type T at byte `offset` of the file `path`, read or written in
// place (the checks that damage a cache file); false on any I/O failure.
template <class T>
bool ReadAt(const std::string& path, long offset, T* value) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return false;
  const bool ok = std::fseek(f, offset, SEEK_SET) == 0 &&
                  std::fread(value, sizeof(T), 1, f) == 1;
  std::fclose(f);
  return ok;
}
template <class T>
bool WriteAt(const std::string& path, long offset, const T& value) {
  std::FILE* f = std::fopen(path.c_str(), "r+b");
  if (f == nullptr) return false;
  const bool ok = std::fseek(f, offset, SEEK_SET) == 0 &&
                  std::fwrite(&value, sizeof(T), 1, f) == 1;
  return std::fclose(f) == 0 && ok;
}

// Where a landmark cache's cascade count is: after the magic, the model
// file's size and mtime, its name (with its length at byte 24) and the
// shape's 136 floats (with their count). -1 if unreadable.
long CascadeCountOffset(const std::string& path) {
  uint64_t len = 0;
  if (!ReadAt(path, 24, &len)) return -1;
  return static_cast<long>(32 + len + 8 + 136 * 4);
}

// Our cascade (on the packed trees) against dlib's own shape_predictor on a
// real photo, for boxes around the face and off it (other leaves): every
// part dlib reports (rounded to whole pixels by dlib) is ours rounded the
// same way.
TEST(LandmarkPredictorTest, SameLandmarksAsDlibsShapePredictor) {
  dlib::shape_predictor sp;
  dlib::deserialize(kDefaultShapePredictorPath) >> sp;
  std::unique_ptr<LandmarkPredictor> p;
  ASSERT_TRUE(LandmarkPredictor::Load(kDefaultShapePredictorPath, &p, "").ok());
  cv::Mat grey;
  cv::cvtColor(LoadImage("astronaut.png"), grey, cv::COLOR_BGR2GRAY);
  dlib::cv_image<unsigned char> img(grey);
  int compared = 0;
  for (const cv::Rect2d& box :
       {cv::Rect2d(139, 38, 168, 188), cv::Rect2d(120, 20, 200, 200),
        cv::Rect2d(160, 70, 120, 140), cv::Rect2d(10, 200, 150, 150),
        cv::Rect2d(300, 300, 90, 60)}) {
    std::vector<Eigen::Vector2d> ours;
    ASSERT_TRUE(p->Predict(grey, box, &ours).ok());
    const dlib::rectangle r(
        static_cast<long>(std::lround(box.x)),
        static_cast<long>(std::lround(box.y)),
        static_cast<long>(std::lround(box.x + box.width - 1)),
        static_cast<long>(std::lround(box.y + box.height - 1)));
    const dlib::full_object_detection d = sp(img, r);
    ASSERT_EQ(ours.size(), d.num_parts());
    for (unsigned long i = 0; i < d.num_parts(); ++i) {
      EXPECT_EQ(std::floor(ours[i].x() + 0.5), d.part(i).x()) << "part " << i;
      EXPECT_EQ(std::floor(ours[i].y() + 0.5), d.part(i).y()) << "part " << i;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 5 * 68);
}

// A predictor loaded with `cache_dir`: whether it came from the cache.
bool LoadedFromCache(const std::string& cache_dir, bool* packed = nullptr) {
  std::unique_ptr<LandmarkPredictor> p;
  EXPECT_TRUE(LandmarkPredictor::Load(kDefaultShapePredictorPath, &p, cache_dir).ok());
  if (!p) return false;
  if (packed != nullptr) *packed = p->loaded_packed_from_cache();
  return p->loaded_from_cache();
}

// The cache file cut in half: ignored, and rewritten to its full size.
void ExpectACutCacheIsRewritten(const std::string& dir, const std::string& file) {
  struct stat st;
  ASSERT_EQ(stat(file.c_str(), &st), 0);
  const off_t full_size = st.st_size;
  ASSERT_EQ(truncate(file.c_str(), full_size / 2), 0);
  EXPECT_FALSE(LoadedFromCache(dir));
  ASSERT_EQ(stat(file.c_str(), &st), 0);
  EXPECT_EQ(st.st_size, full_size);
  EXPECT_TRUE(LoadedFromCache(dir));
}

// A damaged count (the number of cascades, to one the file's size would
// allow on its own): refused, decoded again from the model file.
void ExpectADamagedCountIsRefused(const std::string& dir, const std::string& file,
                                  const cv::Mat& grey, const cv::Rect2d& box,
                                  const std::vector<Eigen::Vector2d>& reference) {
  struct stat st;
  ASSERT_EQ(stat(file.c_str(), &st), 0);
  const long at = CascadeCountOffset(file);
  uint64_t cascades = 0;
  ASSERT_TRUE(ReadAt(file, at, &cascades));
  EXPECT_EQ(cascades, 15u);  // the 68-point model's
  const uint64_t damaged = static_cast<uint64_t>(st.st_size) / 16;
  ASSERT_TRUE(WriteAt(file, at, damaged));
  std::unique_ptr<LandmarkPredictor> p;
  ASSERT_TRUE(LandmarkPredictor::Load(kDefaultShapePredictorPath, &p, dir).ok());
  EXPECT_FALSE(p->loaded_from_cache());
  std::vector<Eigen::Vector2d> again;
  ASSERT_TRUE(p->Predict(grey, box, &again).ok());
  ASSERT_EQ(again.size(), reference.size());
  EXPECT_EQ(again[30].x(), reference[30].x());
}

// A split index past the cascade's features (Predict would read out of
// bounds with it): refused, decoded again, rewritten.
void ExpectABadSplitIsRefused(const std::string& dir, const std::string& file) {
  // After the cascade count: trees, splits and leaves per tree; then per
  // cascade its 500 anchors and 500 deltas (each with its count), then
  // the split count and the first split's idx1.
  const long counts = CascadeCountOffset(file);
  uint64_t c[4] = {0, 0, 0, 0};
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(ReadAt(file, counts + 8 * i, &c[i]));
  EXPECT_EQ(c[0], 15u);
  EXPECT_EQ(c[1], 500u);
  EXPECT_EQ(c[2], 15u);
  EXPECT_EQ(c[3], 16u);
  const long first_split = counts + 32 + 15 * (8 + 500 * 8 + 8 + 500 * 8) + 8;
  uint32_t idx1 = 0;
  ASSERT_TRUE(ReadAt(file, first_split, &idx1));
  EXPECT_LT(idx1, 500u);
  ASSERT_TRUE(WriteAt(file, first_split, uint32_t{500}));
  EXPECT_FALSE(LoadedFromCache(dir));  // released: else the memo hands it back
  bool packed = false;
  EXPECT_TRUE(LoadedFromCache(dir, &packed));
  EXPECT_TRUE(packed);
}

// A cache in the plain form (dlib's structures, as older versions wrote
// it): read, packed, and rewritten in the packed form for the next run.
void ExpectAPlainCacheIsRepacked(const std::string& dir, const std::string& file,
                                 const cv::Mat& grey, const cv::Rect2d& box,
                                 const std::vector<Eigen::Vector2d>& reference) {
  LandmarkModelKey key;
  ASSERT_TRUE(StatLandmarkModel(kDefaultShapePredictorPath, &key));
  {
    LandmarkPredictor::Impl m;
    std::ifstream in(kDefaultShapePredictorPath, std::ios::binary);
    int version = 0;
    dlib::deserialize(version, in);
    dlib::deserialize(m.initial_shape, in);
    dlib::deserialize(m.forests, in);
    dlib::deserialize(m.anchor_idx, in);
    dlib::deserialize(m.deltas, in);
    m.WriteCache(dir, file, key);
  }
  std::string bytes;
  ASSERT_TRUE(ReadWholeFile(file, &bytes));
  EXPECT_EQ(bytes.substr(0, 8), "SFLMCAC1");
  std::vector<Eigen::Vector2d> plain, repacked;
  for (std::vector<Eigen::Vector2d>* out : {&plain, &repacked}) {
    std::unique_ptr<LandmarkPredictor> p;
    ASSERT_TRUE(LandmarkPredictor::Load(kDefaultShapePredictorPath, &p, dir).ok());
    EXPECT_TRUE(p->loaded_from_cache());
    EXPECT_EQ(p->loaded_packed_from_cache(), out == &repacked);
    ASSERT_TRUE(p->Predict(grey, box, out).ok());
    if (out == &plain) {
      ASSERT_TRUE(ReadWholeFile(file, &bytes));
      EXPECT_EQ(bytes.substr(0, 8), "SFLMPAK2");
    }
  }
  ASSERT_EQ(plain.size(), reference.size());
  ASSERT_EQ(repacked.size(), reference.size());
  for (size_t i = 0; i < reference.size(); ++i) {
    EXPECT_EQ(plain[i], reference[i]) << i;
    EXPECT_EQ(repacked[i], reference[i]) << i;
  }
}

// The decoded-model cache gives the very same model: identical landmarks
// to the last bit on a real photo, read straight into the packed trees (the
// fast load); a damaged cache file is ignored and rewritten.
TEST(LandmarkPredictorTest, ModelCacheGivesTheSameLandmarks) {
  char dir_template[] = "/tmp/steadiface_cache_test_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::string dir = std::string(dir_template) + "/nested";
  cv::Mat grey;
  cv::cvtColor(LoadImage("astronaut.png"), grey, cv::COLOR_BGR2GRAY);
  const cv::Rect2d box(139, 38, 168, 188);  // the face in astronaut.png
  std::vector<Eigen::Vector2d> reference, cached;
  {
    std::unique_ptr<LandmarkPredictor> p;
    ASSERT_TRUE(LandmarkPredictor::Load(kDefaultShapePredictorPath, &p, "").ok());
    EXPECT_FALSE(p->loaded_from_cache());
    EXPECT_FALSE(p->loaded_packed_from_cache());
    ASSERT_TRUE(p->Predict(grey, box, &reference).ok());
  }
  EXPECT_FALSE(LoadedFromCache(dir));  // decodes the .dat, writes the cache
  {
    std::unique_ptr<LandmarkPredictor> p;
    ASSERT_TRUE(LandmarkPredictor::Load(kDefaultShapePredictorPath, &p, dir).ok());
    EXPECT_TRUE(p->loaded_from_cache());
    // Straight into the packed trees, not through dlib's structures.
    EXPECT_TRUE(p->loaded_packed_from_cache());
    ASSERT_TRUE(p->Predict(grey, box, &cached).ok());
  }
  ASSERT_EQ(cached.size(), reference.size());
  for (size_t i = 0; i < cached.size(); ++i) {
    EXPECT_EQ(cached[i].x(), reference[i].x()) << i;
    EXPECT_EQ(cached[i].y(), reference[i].y()) << i;
  }
  std::vector<cv::String> files;
  cv::glob(dir + "/*.sfcache", files, false);
  ASSERT_EQ(files.size(), 1u);
  ExpectACutCacheIsRewritten(dir, files[0]);
  ExpectADamagedCountIsRefused(dir, files[0], grey, box, reference);
  ExpectABadSplitIsRefused(dir, files[0]);
  ExpectAPlainCacheIsRepacked(dir, files[0], grey, box, reference);
  // An unwritable cache directory is not an error.
  EXPECT_FALSE(LoadedFromCache("/proc/steadiface"));
  std::remove(files[0].c_str());
  rmdir(dir.c_str());
  rmdir(dir_template);
}

}  // namespace
}  // namespace steadiface

namespace steadiface {
namespace {

// The face detector's cached copy (in the model cache) finds the same faces
// as dlib's shipped one; a damaged cache file is ignored and rewritten.
TEST(FaceDetectorTest, CachedDetectorFindsTheSameFaces) {
  char dir_template[] = "/tmp/steadiface_detcache_test_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const char* old = std::getenv("STEADIFACE_CACHE_DIR");
  const std::string saved = old != nullptr ? old : "";
  setenv("STEADIFACE_CACHE_DIR", dir_template, 1);
  cv::Mat grey;
  cv::cvtColor(LoadImage("astronaut.png"), grey, cv::COLOR_BGR2GRAY);
  const cv::Rect all(0, 0, grey.cols, grey.rows);
  auto detect = [&](std::vector<FaceBox>* faces) {
    std::unique_ptr<FaceDetector> d;
    ASSERT_TRUE(FaceDetector::Create(FaceDetectorOptions(), &d).ok());
    ASSERT_TRUE(d->Detect(grey, all, faces).ok());
  };
  std::vector<FaceBox> fresh, cached, repaired;
  detect(&fresh);  // decodes dlib's detector, writes the cache
  std::vector<cv::String> files;
  cv::glob(std::string(dir_template) + "/frontal_face_detector_*.sfcache",
           files, false);
  ASSERT_EQ(files.size(), 1u);
  std::string written;
  ASSERT_TRUE(ReadWholeFile(files[0], &written));
  detect(&cached);  // reads the cache
  {
    std::string damaged = written;
    damaged[damaged.size() / 2] ^= 0x5a;
    ASSERT_TRUE(WriteFileAtomically(files[0], damaged));
  }
  detect(&repaired);  // ignores the damaged file, rewrites it
  std::string rewritten;
  ASSERT_TRUE(ReadWholeFile(files[0], &rewritten));
  EXPECT_EQ(rewritten, written);
  ASSERT_FALSE(fresh.empty());
  for (const auto* other : {&cached, &repaired}) {
    ASSERT_EQ(other->size(), fresh.size());
    for (size_t i = 0; i < fresh.size(); ++i) {
      EXPECT_EQ((*other)[i].rect, fresh[i].rect);
      EXPECT_EQ((*other)[i].score, fresh[i].score);
    }
  }
  if (old != nullptr) {
    setenv("STEADIFACE_CACHE_DIR", saved.c_str(), 1);
  } else {
    unsetenv("STEADIFACE_CACHE_DIR");
  }
  std::remove(files[0].c_str());
  rmdir(dir_template);
}

}  // namespace
}  // namespace steadiface
