// steadiface_bag: processes a bag offline, as fast as the machine allows,
// through the same StabilizerWrapper as the nodelet (no ROS master).
//
//   rosrun steadiface steadiface_bag --in input.bag [--out output.bag]
//     [--params a.yaml [--params b.yaml]] [--image camera/image_raw]
//     [--info camera/camera_info] [--imu imu] [--landmarks TOPIC]
//     [--video side_by_side.mp4] [--debug-overlay] [--report report.json]
//     [--trajectory traj.csv] [--gyro-only]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include <cv_bridge/cv_bridge.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <ros/package.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>

#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/percentile.h"
#include "steadiface_core/so3.h"
#include "steadiface_ros/msg_conversion.h"
#include "steadiface_ros/params.h"
#include "steadiface_ros/stabilizer_wrapper.h"

namespace {

using Clock = std::chrono::steady_clock;

// Threading: three threads, so reading (LZ4 decompression, deserialization),
// stabilizing and writing overlap. The reader thread fills a bounded queue
// of decoded messages in bag order; the main thread runs the wrapper exactly
// as before (same order, same results: only I/O moved); the writer thread
// drains a bounded queue of bag writes. Bounded both ways, so memory stays
// at a few frames whatever the bag size.
template <typename T>
class BoundedQueue {
 public:
  explicit BoundedQueue(size_t capacity) : capacity_(capacity) {}
  // Blocks while full; false once closed.
  bool Push(T item) {
    std::unique_lock<std::mutex> l(m_);
    not_full_.wait(l, [&] { return q_.size() < capacity_ || closed_; });
    if (closed_) return false;
    q_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }
  // Blocks while empty; false once closed and drained.
  bool Pop(T* item) {
    std::unique_lock<std::mutex> l(m_);
    not_empty_.wait(l, [&] { return !q_.empty() || closed_; });
    if (q_.empty()) return false;
    *item = std::move(q_.front());
    q_.pop_front();
    not_full_.notify_one();
    return true;
  }
  void Close() {
    std::lock_guard<std::mutex> l(m_);
    closed_ = true;
    not_empty_.notify_all();
    not_full_.notify_all();
  }

 private:
  const size_t capacity_;
  std::mutex m_;
  std::condition_variable not_full_, not_empty_;
  std::deque<T> q_;
  bool closed_ = false;
};

// Bag writes on their own thread; the first write error is kept and
// reported at the end (the output is then not renamed into place).
class AsyncBagWriter {
 public:
  explicit AsyncBagWriter(rosbag::Bag* bag) : bag_(bag), queue_(64) {
    thread_ = std::thread([this] {
      std::function<void()> job;
      while (queue_.Pop(&job)) {
        if (!error_.empty()) continue;  // drain after a failure
        try {
          job();
        } catch (const std::exception& e) {
          error_ = e.what();
        }
      }
    });
  }
  ~AsyncBagWriter() { Finish(); }
  template <typename M>
  void Write(const std::string& topic, const ros::Time& t, const boost::shared_ptr<const M>& m) {
    rosbag::Bag* bag = bag_;
    queue_.Push([bag, topic, t, m] { bag->write(topic, t, *m); });
  }
  template <typename M>
  void WriteCopy(const std::string& topic, const ros::Time& t, const M& m) {
    Write(topic, t, boost::shared_ptr<const M>(new M(m)));
  }
  // Waits for every queued write; returns the first error ("" if none).
  std::string Finish() {
    if (thread_.joinable()) {
      queue_.Close();
      thread_.join();
    }
    return error_;
  }

 private:
  rosbag::Bag* bag_;
  BoundedQueue<std::function<void()>> queue_;
  std::thread thread_;
  std::string error_;  // written by the writer thread only, read after join
};

// Video frames encoded on their own thread (cv::VideoWriter is used by that
// thread only once started).
class AsyncVideoWriter {
 public:
  explicit AsyncVideoWriter(cv::VideoWriter* video) : video_(video), queue_(8) {
    thread_ = std::thread([this] {
      cv::Mat frame;
      while (queue_.Pop(&frame)) video_->write(frame);
    });
  }
  ~AsyncVideoWriter() { Finish(); }
  void Write(const cv::Mat& frame) { queue_.Push(frame); }
  void Finish() {
    if (thread_.joinable()) {
      queue_.Close();
      thread_.join();
    }
  }

 private:
  cv::VideoWriter* video_;
  BoundedQueue<cv::Mat> queue_;
  std::thread thread_;
};

// One decoded bag message: exactly one pointer is set for the topics the
// tool reads (none for a message whose type did not instantiate).
struct BagItem {
  ros::Time time;
  sensor_msgs::ImuConstPtr imu;
  sensor_msgs::CameraInfoConstPtr info;
  sensor_msgs::ImageConstPtr image;
  steadiface::FaceLandmarksConstPtr landmarks;
};

struct Args {
  std::string in, out, video, report, trajectory, truth, plot_dir, plot_name = "bag";
  std::vector<std::string> params;
  std::string image_topic = "camera/image_raw", info_topic = "camera/camera_info",
              imu_topic = "imu", landmarks_topic;
  bool debug_overlay = false, gyro_only = false, quiet = false;
  double start_stamp = 0.0;  // images before this stamp are skipped
  std::string only_stamps;   // file of image stamps [s] to process; others skipped
};

int Usage() {
  std::cerr
      << "usage: steadiface_bag --in IN.bag [--out OUT.bag] [--params P.yaml]...\n"
         "  [--image TOPIC] [--info TOPIC] [--imu TOPIC] [--landmarks TOPIC]\n"
         "  [--video OUT.mp4] [--debug-overlay] [--report OUT.json]\n"
         "  [--trajectory OUT.csv] [--gyro-only] [--quiet]\n"
         "  [--truth IN.bag.truth.csv (default: found beside the bag)]\n"
         "  [--plots DIR --name NAME: trajectories for scripts/plot_report.py]\n"
         "  [--start-stamp S: skip images stamped before S (IMU is still read)]\n"
         "  [--only-stamps FILE: process only the images whose stamps [s] are listed,\n"
         "   one per line (to replay exactly the frames a live run received)]\n";
  return 2;
}

using steadiface::Percentile;

// The scorecard's definition of jitter: > cutoff RMS, linear trend removed.
double HighPassRms(const std::vector<Eigen::Vector2d>& x, double fps, double cutoff) {
  return steadiface::eval::Scorecard::HighPassRms(x, fps, cutoff);
}

// Collects everything the wrapper produces: to the output bag, the video
// and the report.
class BagSink : public steadiface_ros::OutputSink {
 public:
  AsyncBagWriter* out = nullptr;
  bool debug = false;
  // Same names as the node publishes in the camera's namespace.
  std::string ns = "/camera";
  std::string T(const std::string& leaf) const { return ns + "/" + leaf; }
  sensor_msgs::ImagePtr last_image, last_debug;
  sensor_msgs::CameraInfo last_info;
  std::vector<steadiface::StabilizerState> states;
  std::vector<sensor_msgs::CameraInfo> infos_out;  // parallel to states
  std::vector<steadiface::FaceLandmarks> landmarks;
  std::vector<geometry_msgs::TransformStamped> tfs;
  std::map<std::string, int> warnings;

  void PublishImage(const sensor_msgs::ImagePtr& image, const sensor_msgs::CameraInfoPtr& info) override {
    last_image = image;
    last_info = *info;
    if (out) {
      out->Write(T("image_stabilized/image_raw"), image->header.stamp,
                 sensor_msgs::ImageConstPtr(image));
      out->Write(T("image_stabilized/camera_info"), info->header.stamp,
                 sensor_msgs::CameraInfoConstPtr(info));
    }
  }
  void PublishLandmarks(const steadiface::FaceLandmarks& m) override {
    landmarks.push_back(m);
    if (out) out->WriteCopy(T("face_landmarks"), m.header.stamp, m);
  }
  void PublishState(const steadiface::StabilizerState& m) override {
    states.push_back(m);
    infos_out.push_back(last_info);  // PublishImage precedes PublishState
    if (out) out->WriteCopy(T("state"), m.header.stamp, m);
  }
  void PublishTf(const std::vector<geometry_msgs::TransformStamped>& tf) override {
    tfs.insert(tfs.end(), tf.begin(), tf.end());
    if (out && !tf.empty()) {
      tf2_msgs::TFMessage m;
      m.transforms = tf;
      out->WriteCopy("/tf", tf.front().header.stamp, m);
    }
  }
  bool WantsDebugImage() const override { return debug; }
  void PublishDebugImage(const sensor_msgs::ImagePtr& image) override {
    last_debug = image;
    if (out) out->Write(T("debug_image"), image->header.stamp, sensor_msgs::ImageConstPtr(image));
  }
  void Warn(const std::string& key, const std::string& text) override {
    if (warnings[key]++ == 0) std::cerr << "warning: " << text << "\n";
  }
  void Error(const std::string& key, const std::string& text) override {
    if (warnings[key]++ == 0) std::cerr << "error: " << text << "\n";
  }
};

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (s == "--in") a.in = next();
    else if (s == "--out") a.out = next();
    else if (s == "--params") a.params.push_back(next());
    else if (s == "--image") a.image_topic = next();
    else if (s == "--info") a.info_topic = next();
    else if (s == "--imu") a.imu_topic = next();
    else if (s == "--landmarks") a.landmarks_topic = next();
    else if (s == "--video") a.video = next();
    else if (s == "--debug-overlay") a.debug_overlay = true;
    else if (s == "--report") a.report = next();
    else if (s == "--trajectory") a.trajectory = next();
    else if (s == "--gyro-only") a.gyro_only = true;
    else if (s == "--quiet") a.quiet = true;
    else if (s == "--truth") a.truth = next();
    else if (s == "--start-stamp") a.start_stamp = std::atof(next().c_str());
    else if (s == "--only-stamps") a.only_stamps = next();
    else if (s == "--plots") a.plot_dir = next();
    else if (s == "--name") a.plot_name = next();
    else return Usage();
  }
  if (a.in.empty()) return Usage();
  // Parameters: the package defaults, then the user's files.
  std::vector<std::string> param_files;
  const std::string pkg = ros::package::getPath("steadiface");
  if (!pkg.empty()) param_files.push_back(pkg + "/config/default.yaml");
  param_files.insert(param_files.end(), a.params.begin(), a.params.end());
  std::unique_ptr<steadiface_ros::ParamSource> params;
  steadiface::Status st = steadiface_ros::YamlParams(param_files, &params);
  steadiface::PipelineOptions po;
  steadiface_ros::WrapperOptions wo;
  if (st.ok()) st = steadiface_ros::LoadOptions(*params, &po, &wo);
  if (!st.ok()) {
    std::cerr << "steadiface_bag: " << st.message() << "\n";
    return 1;
  }
  if (a.gyro_only) {
    po.stabilizer.gyro_only = true;
    po.landmark_source = steadiface::LandmarkSource::kNone;
  }
  if (!a.landmarks_topic.empty()) po.landmark_source = steadiface::LandmarkSource::kExternal;

  rosbag::Bag in;
  try {
    in.open(a.in, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    std::cerr << "steadiface_bag: cannot open '" << a.in << "': " << e.what() << "\n";
    return 1;
  }
  // Topics and types.
  auto norm = [](std::string t) { return t.empty() || t[0] == '/' ? t : "/" + t; };
  std::map<std::string, std::string> types;
  {
    rosbag::View all(in);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) types[norm(c->topic)] = c->datatype;
  }
  const std::vector<std::pair<std::string, std::string>> want = {
      {a.image_topic, "sensor_msgs/Image"},
      {a.info_topic, "sensor_msgs/CameraInfo"},
      {a.imu_topic, "sensor_msgs/Imu"}};
  for (const auto& w : want) {
    auto it = types.find(norm(w.first));
    if (it == types.end()) {
      std::cerr << "steadiface_bag: topic '" << norm(w.first) << "' (" << w.second
                << ") is not in " << a.in << "; topics there:";
      for (const auto& t : types) std::cerr << " " << t.first << " [" << t.second << "]";
      std::cerr << "\n";
      if (w.second != "sensor_msgs/Imu") return 1;
      std::cerr << "steadiface_bag: continuing without IMU: frames pass through unstabilized\n";
    } else if (it->second != w.second) {
      std::cerr << "steadiface_bag: topic '" << norm(w.first) << "' has type " << it->second
                << ", expected " << w.second << "\n";
      return 1;
    }
  }

  BagSink sink;
  sink.debug = a.debug_overlay && !a.video.empty();
  {
    const std::string img = norm(a.image_topic);
    const size_t slash = img.rfind('/');
    sink.ns = slash == 0 || slash == std::string::npos ? "" : img.substr(0, slash);
  }
  rosbag::Bag out;
  const std::string out_tmp = a.out + ".part";
  if (!a.out.empty()) {
    try {
      out.open(out_tmp, rosbag::bagmode::Write);
    } catch (const rosbag::BagException& e) {
      std::cerr << "steadiface_bag: cannot write '" << out_tmp << "': " << e.what() << "\n";
      return 1;
    }
  }
  std::unique_ptr<AsyncBagWriter> writer;
  if (!a.out.empty()) {
    writer.reset(new AsyncBagWriter(&out));
    sink.out = writer.get();
  }
  steadiface_ros::StabilizerWrapper wrapper(po, wo, &sink);

  // Bags store topics as recorded, with or without the leading '/'.
  auto both = [&](const std::string& t) {
    std::vector<std::string> v = {norm(t)};
    if (norm(t).size() > 1) v.push_back(norm(t).substr(1));
    return v;
  };
  std::vector<std::string> topics;
  for (const std::string& t : {a.image_topic, a.info_topic, a.imu_topic, a.landmarks_topic}) {
    if (t.empty()) continue;
    for (const auto& v : both(t)) topics.push_back(v);
  }
  rosbag::View view(in, rosbag::TopicQuery(topics));
  const size_t total_images = rosbag::View(in, rosbag::TopicQuery(both(a.image_topic))).size();
  std::map<ros::Time, sensor_msgs::CameraInfoConstPtr> infos;
  sensor_msgs::CameraInfo in_info;
  bool have_in_info = false;
  std::deque<sensor_msgs::ImageConstPtr> waiting;  // images whose info has not arrived
  cv::VideoWriter video;
  std::unique_ptr<AsyncVideoWriter> video_writer;
  const std::string video_tmp = a.video.empty() ? "" : a.video + ".part.mp4";
  std::map<ros::Time, cv::Mat> inputs;  // for the side-by-side video, bounded
  const bool tty = isatty(STDERR_FILENO) && !a.quiet;
  const auto start = Clock::now();
  size_t images_seen = 0;
  size_t state_written = 0;
  std::vector<Eigen::Vector2d> centre_in, centre_out;
  auto write_video = [&]() {
    // Pair every new stabilized output with its input frame.
    if (a.video.empty() || !sink.last_image) return;
    const ros::Time t = sink.last_image->header.stamp;
    auto it = inputs.find(t);
    if (it == inputs.end()) return;
    cv::Mat left = it->second, right;
    if (sink.debug && sink.last_debug && sink.last_debug->header.stamp == t) {
      left = cv_bridge::toCvCopy(sink.last_debug, "bgr8")->image;
    }
    right = cv_bridge::toCvCopy(sink.last_image, "bgr8")->image;
    if (left.channels() == 1) cv::cvtColor(left, left, cv::COLOR_GRAY2BGR);
    cv::resize(right, right, left.size());
    cv::Mat both;
    cv::hconcat(left, right, both);
    if (!video_writer) {  // first frame: open (the writer thread owns `video` after)
      const double fps = 30.0;
      video.open(video_tmp, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps, both.size());
      if (!video.isOpened()) {
        std::cerr << "steadiface_bag: cannot write video '" << video_tmp << "'\n";
        a.video.clear();
        return;
      }
      video_writer.reset(new AsyncVideoWriter(&video));
    }
    video_writer->Write(both);
    inputs.erase(inputs.begin(), std::next(it));
    sink.last_image.reset();
  };
  std::set<int64_t> only;  // stamps in ms
  if (!a.only_stamps.empty()) {
    std::ifstream f(a.only_stamps);
    if (!f) {
      std::cerr << "steadiface_bag: cannot read '" << a.only_stamps << "'\n";
      return 1;
    }
    double t;
    while (f >> t) only.insert(std::llround(t * 1e3));
    if (only.empty()) {
      std::cerr << "steadiface_bag: no stamps in '" << a.only_stamps << "'\n";
      return 1;
    }
  }
  BoundedQueue<BagItem> read_queue(64);
  std::string read_error;
  const std::string imu_topic = norm(a.imu_topic), info_topic = norm(a.info_topic),
                    landmarks_topic = norm(a.landmarks_topic), image_topic = norm(a.image_topic);
  std::thread reader([&] {
    try {
      for (const rosbag::MessageInstance& m : view) {
        BagItem item;
        const std::string topic = norm(m.getTopic());
        item.time = m.getTime();
        if (topic == imu_topic) {
          item.imu = m.instantiate<sensor_msgs::Imu>();
        } else if (topic == info_topic) {
          item.info = m.instantiate<sensor_msgs::CameraInfo>();
        } else if (topic == landmarks_topic) {
          item.landmarks = m.instantiate<steadiface::FaceLandmarks>();
        } else if (topic == image_topic) {
          item.image = m.instantiate<sensor_msgs::Image>();
        }
        if (!read_queue.Push(std::move(item))) break;
      }
    } catch (const std::exception& e) {
      read_error = e.what();
    }
    read_queue.Close();
  });
  BagItem item;
  while (read_queue.Pop(&item)) {
    if (item.imu) {
      wrapper.OnImu(*item.imu);
    } else if (const auto& info = item.info) {
      in_info = *info;
      have_in_info = true;
      infos[info->header.stamp] = info;
      while (infos.size() > 64) infos.erase(infos.begin());
    } else if (item.landmarks) {
      wrapper.OnLandmarks(*item.landmarks);
    } else if (const auto& img = item.image) {
      if (img->header.stamp.toSec() < a.start_stamp - 1e-6) continue;
      if (!only.empty() && !only.count(std::llround(img->header.stamp.toSec() * 1e3))) continue;
      waiting.push_back(img);
      ++images_seen;
    }
    // Pair images with the camera_info of the same stamp (either order).
    while (!waiting.empty()) {
      auto it = infos.find(waiting.front()->header.stamp);
      if (it == infos.end()) {
        if (waiting.size() > 8) {  // no info for this image: use the latest one
          if (infos.empty()) {
            waiting.pop_front();
            continue;
          }
          it = std::prev(infos.end());
        } else {
          break;
        }
      }
      const sensor_msgs::ImageConstPtr img = waiting.front();
      waiting.pop_front();
      if (!a.video.empty()) {
        cv::Mat mat;
        if (steadiface_ros::ToCvImage(*img, &mat).ok()) inputs[img->header.stamp] = mat.clone();
        while (inputs.size() > 32) inputs.erase(inputs.begin());
      }
      wrapper.OnImage(img, it->second, item.time);
    }
    wrapper.OnTimer(item.time);
    write_video();
    const size_t done = sink.states.size();
    if (done != state_written && (tty || done % 100 == 0)) {
      state_written = done;
      const double el = std::chrono::duration<double>(Clock::now() - start).count();
      const double fps = done / std::max(el, 1e-9);
      const double eta = total_images > done ? (total_images - done) / std::max(fps, 1e-9) : 0.0;
      if (tty) {
        fprintf(stderr, "\r[%-30s] %zu/%zu frames  %.1f fps  ETA %.0f s ",
                std::string(30 * done / std::max<size_t>(1, total_images), '#').c_str(), done,
                total_images, fps, eta);
      } else if (!a.quiet) {
        fprintf(stderr, "steadiface_bag: %zu/%zu frames, %.1f fps, ETA %.0f s\n", done,
                total_images, fps, eta);
      }
    }
  }
  reader.join();
  if (!read_error.empty()) {
    std::cerr << "steadiface_bag: reading " << a.in << " failed: " << read_error << "\n";
    if (writer) writer->Finish();
    if (!a.out.empty()) std::remove(out_tmp.c_str());
    return 1;
  }
  wrapper.Flush();
  write_video();
  if (tty) fprintf(stderr, "\n");
  in.close();
  if (writer) {
    const std::string err = writer->Finish();
    if (!err.empty()) {
      std::cerr << "steadiface_bag: writing " << out_tmp << " failed: " << err << "\n";
      std::remove(out_tmp.c_str());
      return 1;
    }
  }
  if (video_writer) video_writer->Finish();
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  if (!a.out.empty()) {
    out.close();
    if (std::rename(out_tmp.c_str(), a.out.c_str()) != 0) {
      std::cerr << "steadiface_bag: cannot rename " << out_tmp << "\n";
      return 1;
    }
  }
  if (video.isOpened()) {
    video.release();
    std::rename(video_tmp.c_str(), a.video.c_str());
  }

  // Report: what can be measured without ground truth.
  const steadiface_ros::WrapperStatus ws = wrapper.Status();
  std::vector<double> face_ms, stab_ms, warp_ms, total_ms, solver_ms, iters;
  std::vector<Eigen::Vector2d> c_in, c_out, shake;
  for (size_t i = 0; i < sink.states.size(); ++i) {
    const auto& s = sink.states[i];
    face_ms.push_back(s.face_ms);
    stab_ms.push_back(s.stabilizer_ms);
    warp_ms.push_back(s.warp_ms);
    total_ms.push_back(s.total_ms);
    solver_ms.push_back(s.solver_time_ms);
    iters.push_back(s.solver_iterations);
    // Residual camera shake: virtual rotation vector (what the viewer sees
    // of the camera's rotation).
    Eigen::Quaterniond q;
    steadiface_ros::ToEigen(s.virtual_rotation, &q);
    const Eigen::Vector3d v = steadiface::LogSO3(q);
    shake.emplace_back(v.x(), v.y());
    if (s.has_target) {
      c_in.emplace_back(s.centre_c[0], s.centre_c[1]);
      c_out.emplace_back(s.target_h[0], s.target_h[1]);
    }
  }
  double fps_data = 30.0;
  if (sink.states.size() > 2) {
    fps_data = (sink.states.size() - 1) /
               std::max(1e-9, (sink.states.back().header.stamp - sink.states.front().header.stamp).toSec());
  }
  // Ground truth (simulator bags): the true head centre and far-background
  // directions mapped through each frame's warp, as the scorecard does. The
  // warp of a frame is K_out R_v R_r^-1 K_in^-1 (middle-row R_r; the rolling
  // shutter's within-frame part is below a pixel here).
  std::string truth_json;
  if (a.truth.empty() && std::ifstream(a.in + ".truth.csv").good()) a.truth = a.in + ".truth.csv";
  if (!a.truth.empty() && !sink.states.empty() && have_in_info) {
    std::ifstream tf(a.truth);
    std::string line;
    std::getline(tf, line);
    struct T {
      Eigen::Vector2d head;
      bool in_view;
      std::vector<Eigen::Quaterniond> rows;
    };
    std::map<int64_t, T> truth;  // by stamp in ms
    while (std::getline(tf, line)) {
      std::vector<double> v;
      std::stringstream ss(line);
      std::string cell;
      while (std::getline(ss, cell, ',')) v.push_back(std::atof(cell.c_str()));
      if (v.size() < 9 + 64) continue;
      T t;
      t.head = Eigen::Vector2d(v[2], v[3]);
      t.in_view = v[4] != 0;
      for (int r = 0; r < 16; ++r) {
        t.rows.emplace_back(v[9 + 4 * r + 3], v[9 + 4 * r], v[9 + 4 * r + 1], v[9 + 4 * r + 2]);
      }
      truth[std::llround(v[1] * 1000.0)] = t;
    }
    const Eigen::Matrix3d K_in = (Eigen::Matrix3d() << in_info.K[0], 0, in_info.K[2], 0,
                                  in_info.K[4], in_info.K[5], 0, 0, 1).finished();
    std::vector<Eigen::Vector2d> h_in, h_out, b_in, b_out;
    Eigen::Vector3d dir = Eigen::Vector3d::Zero();
    std::ofstream traj_none, traj_method;
    if (!a.plot_dir.empty()) {
      const std::string head = "t,head_in_x,head_in_y,head_out_x,head_out_y,head_valid,bg_out_x,bg_out_y,"
                               "virt_rx,virt_ry,virt_rz,real_rx,real_ry,real_rz,tx,ty\n";
      traj_method.open(a.plot_dir + "/traj_" + a.plot_name + "_" +
                       (a.gyro_only ? "gyro-only" : "steadiface") + ".csv");
      traj_method << head;
      if (!a.gyro_only) {
        traj_none.open(a.plot_dir + "/traj_" + a.plot_name + "_none.csv");
        traj_none << head;
      }
    }
    const double t0 = sink.states.front().header.stamp.toSec();
    for (size_t i = 0; i < sink.states.size() && i < sink.infos_out.size(); ++i) {
      const auto& s = sink.states[i];
      auto it = truth.find(std::llround(s.header.stamp.toSec() * 1000.0));
      if (it == truth.end()) continue;
      const T& t = it->second;
      Eigen::Quaterniond Rv, Rr;
      steadiface_ros::ToEigen(s.virtual_rotation, &Rv);
      steadiface_ros::ToEigen(s.real_rotation, &Rr);
      const auto& ko = sink.infos_out[i].K;
      const Eigen::Matrix3d K_out = (Eigen::Matrix3d() << ko[0], 0, ko[2], 0, ko[4], ko[5], 0, 0, 1).finished();
      const Eigen::Matrix3d H = K_out * (Rv * Rr.conjugate()).toRotationMatrix() * K_in.inverse();
      // A far-background direction fixed in the world: the first frame's
      // view centre, seen in each frame through the true middle-row rotation.
      const Eigen::Quaterniond R_true = t.rows[7];
      if (dir.isZero()) dir = R_true.conjugate() * Eigen::Vector3d(0.05, 0.03, 1.0);
      const Eigen::Vector3d c = R_true * dir;
      const Eigen::Vector2d bin = (K_in * c).hnormalized();
      const Eigen::Vector2d bout = (H * bin.homogeneous()).hnormalized();
      b_in.push_back(bin);
      b_out.push_back(bout);
      Eigen::Vector2d hout = Eigen::Vector2d::Constant(NAN);
      if (t.in_view) {
        hout = (H * t.head.homogeneous()).hnormalized();
        h_in.push_back(t.head);
        h_out.push_back(hout);
      }
      const Eigen::Vector3d vr = steadiface::LogSO3(Rv), rr = steadiface::LogSO3(Rr);
      auto row = [&](std::ofstream& f, const Eigen::Vector2d& ho, const Eigen::Vector2d& bo,
                     const Eigen::Vector3d& v, const Eigen::Vector3d& r, double tx, double ty) {
        if (!f.is_open()) return;
        f << s.header.stamp.toSec() - t0 << "," << t.head.x() << "," << t.head.y() << "," << ho.x()
          << "," << ho.y() << "," << t.in_view << "," << bo.x() << "," << bo.y() << "," << v.x()
          << "," << v.y() << "," << v.z() << "," << r.x() << "," << r.y() << "," << r.z() << ","
          << tx << "," << ty << "\n";
      };
      row(traj_method, hout, bout, vr, rr, s.principal_offset[0], s.principal_offset[1]);
      row(traj_none, t.in_view ? t.head : Eigen::Vector2d::Constant(NAN), bin, rr, rr, 0.0, 0.0);
    }
    const double diag = std::hypot(in_info.width, in_info.height);
    std::ostringstream tj;
    tj << ",\n  \"ground_truth\": {\"truth\": \"" << a.truth << "\""
       << ", \"head_jitter_in_px\": " << HighPassRms(h_in, fps_data, 0.5)
       << ", \"head_jitter_out_px\": " << HighPassRms(h_out, fps_data, 0.5)
       << ", \"head_jitter_out_frac\": " << HighPassRms(h_out, fps_data, 0.5) / diag
       << ", \"background_jitter_in_px\": " << HighPassRms(b_in, fps_data, 0.5)
       << ", \"background_jitter_out_px\": " << HighPassRms(b_out, fps_data, 0.5)
       << ", \"cropping\": " << std::pow(1.0 - 2.0 * po.warp.output.crop_ratio, 2.0)
       << ", \"undefined_fraction\": "
       << static_cast<double>(ws.stabilizer.undefined_frames) / std::max<size_t>(1, sink.states.size())
       << "}";
    truth_json = tj.str();
  }
  std::ostringstream rep;
  rep.precision(6);
  rep << "{\n  \"input\": \"" << a.in << "\",\n  \"frames_in\": " << ws.counters.images_in
      << ",\n  \"frames_out\": " << ws.counters.frames_out
      << ",\n  \"wall_time_s\": " << elapsed
      << ",\n  \"throughput_fps\": " << ws.counters.frames_out / std::max(elapsed, 1e-9)
      << ",\n  \"landmark_centre_jitter_in_norm\": " << HighPassRms(c_in, fps_data, 0.5)
      << ",\n  \"target_jitter_out_norm\": " << HighPassRms(c_out, fps_data, 0.5)
      << ",\n  \"residual_rotation_jitter_rad\": " << HighPassRms(shake, fps_data, 0.5)
      << ",\n  \"crop_ratio\": " << po.warp.output.crop_ratio
      << ",\n  \"dropped\": {\"bad_image\": " << ws.counters.dropped_bad_image
      << ", \"bad_info\": " << ws.counters.dropped_bad_info
      << ", \"no_gyro\": " << ws.counters.dropped_no_gyro
      << ", \"queue_full\": " << ws.counters.dropped_queue_full
      << ", \"old_stamp\": " << ws.counters.dropped_old_stamp
      << ", \"refused\": " << ws.counters.dropped_pipeline_error << "}"
      << ",\n  \"passthrough_no_imu\": " << ws.counters.passthrough
      << ",\n  \"extrapolated\": " << ws.counters.extrapolated
      << ",\n  \"protrusion_searches\": " << ws.stabilizer.protrusion_searches
      << ",\n  \"previous_warp_fallbacks\": " << ws.stabilizer.previous_warp_fallbacks
      << ",\n  \"undefined_frames\": " << ws.stabilizer.undefined_frames
      << ",\n  \"solver_failures\": " << ws.stabilizer.solver_failures
      << ",\n  \"frames_with_face\": " << ws.stabilizer.frames_with_face
      << ",\n  \"timings_ms\": {"
      << "\"face\": [" << Percentile(face_ms, 0.5) << ", " << Percentile(face_ms, 0.99) << "], "
      << "\"stabilizer\": [" << Percentile(stab_ms, 0.5) << ", " << Percentile(stab_ms, 0.99) << "], "
      << "\"solver\": [" << Percentile(solver_ms, 0.5) << ", " << Percentile(solver_ms, 0.99) << "], "
      << "\"warp\": [" << Percentile(warp_ms, 0.5) << ", " << Percentile(warp_ms, 0.99) << "], "
      << "\"total\": [" << Percentile(total_ms, 0.5) << ", " << Percentile(total_ms, 0.99) << "]}"
      << ",\n  \"solver_iterations_median\": " << Percentile(iters, 0.5) << truth_json
      << ",\n  \"method\": \"" << (a.gyro_only ? "gyro-only" : "steadiface") << "\"\n}\n";
  if (!a.report.empty()) {
    std::ofstream f(a.report + ".part");
    f << rep.str();
    f.close();
    std::rename((a.report + ".part").c_str(), a.report.c_str());
  }
  if (!a.trajectory.empty()) {
    std::ofstream f(a.trajectory);
    f.precision(17);
    f << "stamp,qx,qy,qz,qw,tx,ty,rqx,rqy,rqz,rqw,has_target,hx,hy,cx,cy,w_fit\n";
    for (const auto& s : sink.states) {
      f << s.header.stamp.toSec() << "," << s.virtual_rotation.x << "," << s.virtual_rotation.y
        << "," << s.virtual_rotation.z << "," << s.virtual_rotation.w << ","
        << s.principal_offset[0] << "," << s.principal_offset[1] << "," << s.real_rotation.x
        << "," << s.real_rotation.y << "," << s.real_rotation.z << "," << s.real_rotation.w
        << "," << s.has_target << "," << s.target_h[0] << "," << s.target_h[1] << ","
        << s.centre_c[0] << "," << s.centre_c[1] << "," << s.w_fit << "\n";
    }
  }
  if (!a.quiet) {
    std::cerr << "steadiface_bag: " << ws.counters.frames_out << " frames in " << elapsed
              << " s (" << ws.counters.frames_out / std::max(elapsed, 1e-9) << " fps)"
              << (a.out.empty() ? "" : ", wrote " + a.out)
              << (a.video.empty() ? "" : ", " + a.video)
              << (a.report.empty() ? "" : ", " + a.report) << "\n";
  }
  return ws.counters.frames_out > 0 ? 0 : 1;
}
