#include "steadiface_calibrate/calibrate_run.h"

#include <algorithm>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "steadiface_bag/bounded_queue.h"
#include "steadiface_core/calibration/calibrator.h"
#include "steadiface_core/calibration/video_readout.h"
#include "steadiface_core/common/grey.h"
#include "steadiface_ros/camera_info_source.h"
#include "steadiface_ros/msg_conversion.h"
#include "steadiface_ros/params.h"
#include "steadiface_ros/time_conversion.h"

namespace steadiface_calibrate {
namespace {

using steadiface::Status;
using Queue = steadiface_bag::BoundedQueue<steadiface_bag::BagItem>;

// Angular speed from the video and the gyro, before and after, as a PNG.
void Plot(const steadiface::CalibrationResult& r, const std::string& path) {
  const int W = 1000, Hp = 260, pad = 40;
  cv::Mat img(2 * Hp + pad, W, CV_8UC3, cv::Scalar(255, 255, 255));
  double vmax = 1e-6, tmax = 1e-6;
  for (size_t i = 0; i < r.plot_t.size(); ++i) {
    vmax = std::max(
        {vmax, r.plot_video[i], r.plot_gyro_before[i], r.plot_gyro_after[i]});
    tmax = std::max(tmax, r.plot_t[i]);
  }
  auto pt = [&](double t, double v, int panel) {
    return cv::Point(
        static_cast<int>(50 + (W - 70) * t / tmax),
        static_cast<int>(panel * (Hp + pad) + Hp - 25 - (Hp - 50) * v / vmax));
  };
  for (int panel = 0; panel < 2; ++panel) {
    const auto& gyro = panel == 0 ? r.plot_gyro_before : r.plot_gyro_after;
    cv::rectangle(img, pt(0, 0, panel), pt(tmax, vmax, panel),
                  cv::Scalar(200, 200, 200));
    for (size_t i = 1; i < r.plot_t.size(); ++i) {
      cv::line(img, pt(r.plot_t[i - 1], r.plot_video[i - 1], panel),
               pt(r.plot_t[i], r.plot_video[i], panel), cv::Scalar(0, 0, 0), 1,
               cv::LINE_AA);
      cv::line(img, pt(r.plot_t[i - 1], gyro[i - 1], panel),
               pt(r.plot_t[i], gyro[i], panel), cv::Scalar(0, 0, 220), 1,
               cv::LINE_AA);
    }
    std::ostringstream title;
    title << (panel == 0 ? "before (configured offset)"
                         : "after (estimated offset, bias)")
          << ": |omega| video (black), gyro (red); max " << std::setprecision(3)
          << vmax << " rad/s over " << tmax << " s";
    cv::putText(img, title.str(), cv::Point(55, panel * (Hp + pad) + 18),
                cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
                cv::LINE_AA);
  }
  cv::imwrite(path, img);
}


// Feeds a bag's gyro samples and images to a Calibrator, made at the first
// image (it needs the intrinsics).
class Feeder {
 public:
  Feeder(const CalibrateOptions& o, const steadiface::PipelineOptions& po,
         steadiface_ros::CameraInfoSource* info_source)
      : o_(o), po_(po), info_source_(*info_source) {}
  // Reads every message of `queue`; an error ends the run.
  Status Feed(Queue* queue, size_t total);
  std::unique_ptr<steadiface::Calibrator>& calibrator() { return cal_; }
  size_t frames() const { return frames_; }
  size_t skipped() const { return skipped_; }
  size_t imu() const { return imu_; }

 private:
  void AddGyro(const sensor_msgs::Imu& m);
  Status AddImage(const sensor_msgs::Image& image);

  const CalibrateOptions& o_;
  const steadiface::PipelineOptions& po_;
  steadiface_ros::CameraInfoSource& info_source_;
  std::unique_ptr<steadiface::Calibrator> cal_;
  sensor_msgs::CameraInfoConstPtr last_info_;
  size_t frames_ = 0, skipped_ = 0, imu_ = 0;
  // Gyro samples before the first image (the calibrator needs its
  // intrinsics first); bounded: an hour at 1 kHz would be 3.6e6.
  static constexpr size_t kMaxEarly = 1000000;
  std::vector<steadiface::GyroSample> early_;
};

void Feeder::AddGyro(const sensor_msgs::Imu& m) {
  ++imu_;
  if (cal_) {
    cal_->AddGyro(steadiface_ros::ToGyroSample(m));
  } else if (early_.size() < kMaxEarly) {
    early_.push_back(steadiface_ros::ToGyroSample(m));  // until the first image
  }
}

Status Feeder::AddImage(const sensor_msgs::Image& image) {
  const sensor_msgs::CameraInfoConstPtr info = info_source_.Select(image, last_info_);
  if (!info) {
    ++skipped_;
    return Status::Ok();
  }
  if (!cal_) {
    steadiface::CameraIntrinsics k;
    steadiface::CalibratorOptions co;
    co.estimate_readout = o_.estimate_readout;
    Status st = steadiface_ros::ToCameraIntrinsics(*info, &k);
    if (st.ok()) {
      st = steadiface::Calibrator::Create(k, po_.shutter, po_.imu.R_cam_imu,
                                          po_.imu.imu_time_offset_s, co, &cal_);
    }
    if (!st.ok()) return st;
    for (const auto& g : early_) cal_->AddGyro(g);
    early_.clear();
  }
  cv::Mat cv_image;
  Status st = steadiface_ros::ToCvImage(image, &cv_image);
  if (st.ok()) st = cal_->AddFrame(cv_image, steadiface_ros::ToCoreTime(image.header.stamp));
  if (st.ok()) {
    ++frames_;
  } else {
    ++skipped_;
  }
  return Status::Ok();
}

Status Feeder::Feed(Queue* queue, size_t total) {
  steadiface_bag::BagItem item;
  while (queue->Pop(&item)) {
    if (item.imu) AddGyro(*item.imu);
    if (item.info) last_info_ = item.info;
    if (!item.image) continue;
    const size_t before = frames_;
    const Status st = AddImage(*item.image);
    if (!st.ok()) return st;
    if (!o_.quiet && frames_ != before && frames_ % 100 == 0) {
      std::cerr << "steadiface_calibrate: frame " << frames_ << " / " << total << "\n";
    }
  }
  return Status::Ok();
}

// The overlay: the estimates with their uncertainties in comments.
Status WriteOverlay(const steadiface::CalibrationResult& r, const std::string& in, size_t frames,
                    const std::string& out) {
  const Eigen::Quaterniond& q = r.R_cam_imu;
  std::ofstream y(out + ".part");
  y << std::setprecision(9);
  y << "# steadiface_calibrate --in " << in << "\n"
    << "# " << frames << " frames, " << r.pairs << " frame pairs, " << r.tracks
    << " tracks; median reprojection residual " << r.residual_before_px
    << " px (configured) -> " << r.residual_after_px
    << " px. Uncertainties are formal 1-sigma (Ceres covariance).\n"
    << "# Load with: roslaunch steadiface stabilize.launch params:=<this "
       "file>\n"
    << "#        or: steadiface_bag --in IN.bag --params <this file> ...\n"
    << "imu:\n"
    << "  R_cam_imu: [" << q.x() << ", " << q.y() << ", " << q.z() << ", "
    << q.w() << "]  # +-" << r.rotation_sigma_deg << " deg; "
    << r.misalignment_deg << " deg from the axis permutation ["
    << r.nearest_permutation.x() << ", " << r.nearest_permutation.y() << ", "
    << r.nearest_permutation.z() << ", " << r.nearest_permutation.w() << "]\n"
    << "  time_offset: " << r.time_offset_s << "  # [s] +-"
    << r.time_offset_sigma_s * 1e3 << " ms (coarse " << r.coarse_offset_s
    << " s)\n"
    << "  gyro_bias: [" << r.bias.x() << ", " << r.bias.y() << ", "
    << r.bias.z() << "]  # [rad/s], IMU axes, +- [" << r.bias_sigma.x() << ", "
    << r.bias_sigma.y() << ", " << r.bias_sigma.z() << "]\n";
  if (r.readout_determined) {
    y << "camera:\n  readout_time: " << r.readout_s << "  # [s] +-"
      << r.readout_sigma_s * 1e3 << " ms\n";
  } else {
    y << "# camera/readout_time not determined (" << r.readout_s << " s +-"
      << r.readout_sigma_s * 1e3 << " ms): left as configured\n";
  }
  y.close();
  if (!y || std::rename((out + ".part").c_str(), out.c_str()) != 0) {
    return Status::Error("cannot write '" + out + "'");
  }
  return Status::Ok();
}

void WriteReport(const steadiface::CalibrationResult& r, const std::string& in, size_t frames,
                 size_t imu, const std::string& report) {
  const Eigen::Quaterniond& q = r.R_cam_imu;
  std::ofstream j(report);
  j << std::setprecision(9) << "{\n  \"in\": \"" << in
    << "\",\n  \"frames\": " << frames << ",\n  \"imu_samples\": " << imu
    << ",\n  \"pairs\": " << r.pairs << ",\n  \"tracks\": " << r.tracks
    << ",\n  \"duration_s\": " << r.duration_s
    << ",\n  \"mean_angular_speed\": " << r.mean_angular_speed
    << ",\n  \"R_cam_imu\": [" << q.x() << ", " << q.y() << ", " << q.z()
    << ", " << q.w()
    << "],\n  \"rotation_sigma_deg\": " << r.rotation_sigma_deg
    << ",\n  \"misalignment_deg\": " << r.misalignment_deg
    << ",\n  \"time_offset_s\": " << r.time_offset_s
    << ",\n  \"time_offset_sigma_s\": " << r.time_offset_sigma_s
    << ",\n  \"coarse_offset_s\": " << r.coarse_offset_s
    << ",\n  \"readout_s\": " << r.readout_s
    << ",\n  \"readout_sigma_s\": " << r.readout_sigma_s
    << ",\n  \"readout_determined\": "
    << (r.readout_determined ? "true" : "false") << ",\n  \"bias\": ["
    << r.bias.x() << ", " << r.bias.y() << ", " << r.bias.z()
    << "],\n  \"residual_before_px\": " << r.residual_before_px
    << ",\n  \"residual_after_px\": " << r.residual_after_px
    << ",\n  \"solver\": \"" << r.solver_report << "\"\n}\n";
}

void WritePlot(const steadiface::CalibrationResult& r, const std::string& dir) {
  std::ofstream c(dir + "/angular_speed.csv");
  c << "t,video,gyro_before,gyro_after\n";
  for (size_t i = 0; i < r.plot_t.size(); ++i) {
    c << r.plot_t[i] << "," << r.plot_video[i] << "," << r.plot_gyro_before[i]
      << "," << r.plot_gyro_after[i] << "\n";
  }
  Plot(r, dir + "/angular_speed.png");
}

void PrintSummary(const steadiface::CalibrationResult& r, const std::string& out) {
  const Eigen::Quaterniond& q = r.R_cam_imu;
  std::cout << "steadiface_calibrate: time_offset " << r.time_offset_s * 1e3
            << " ms (+-" << r.time_offset_sigma_s * 1e3 << "), readout "
            << r.readout_s * 1e3 << " ms"
            << (r.readout_determined ? "" : " (not determined)")
            << ", R_cam_imu [" << q.x() << ", " << q.y() << ", " << q.z()
            << ", " << q.w() << "] (" << r.misalignment_deg
            << " deg from an axis permutation), residual "
            << r.residual_before_px << " -> " << r.residual_after_px
            << " px; wrote " << out << "\n";
}

// The recording and what reading it needs: the package defaults with the
// user's overlays (the starting point), the camera_info source and the
// bag, opened once; then its messages, read on the reader's thread and
// handed to one of the two calibrations.
class Recording {
 public:
  explicit Recording(const CalibrateOptions& o)
      : o_(o), info_source_([this](bool is_error, const std::string& text) {
          if (is_error || !o_.quiet) std::cerr << "steadiface_calibrate: " << text << "\n";
        }),
        reader_(o.in, o.topics) {}
  Status Open() {
    Status st = steadiface_ros::LoadPackageOptions(o_.params, &po_, &wo_);
    if (st.ok()) st = info_source_.Load(wo_.camera_info_url);
    if (st.ok()) st = reader_.Open(/*info_required=*/!info_source_.has_file_info());
    return st;
  }
  bool has_imu() const { return reader_.ImuCount() > 0; }
  size_t images() const { return reader_.ImageCount(); }
  const steadiface::PipelineOptions& options() const { return po_; }
  steadiface_ros::CameraInfoSource* info_source() { return &info_source_; }
  // Every message through `feed`; its error, else the reader's.
  Status Read(const std::function<Status(Queue*)>& feed) {
    Queue queue(64);
    reader_.Start(&queue);
    const Status st = feed(&queue);
    if (!st.ok()) queue.Close();
    const std::string reader_error = reader_.Join();
    if (!st.ok()) return st;
    return reader_error.empty() ? Status::Ok() : Status::Error(reader_error);
  }

 private:
  const CalibrateOptions& o_;
  steadiface::PipelineOptions po_;
  steadiface_ros::WrapperOptions wo_;
  steadiface_ros::CameraInfoSource info_source_;
  steadiface_bag::BagReader reader_;
};

// Reads the recording into a Calibrator and solves; the error says why not.
Status Calibrate(const CalibrateOptions& o, Recording* rec, steadiface::CalibrationResult* r,
                 size_t* frames, size_t* imu) {
  Feeder feeder(o, rec->options(), rec->info_source());
  const size_t total = rec->images();
  Status st = rec->Read([&](Queue* queue) { return feeder.Feed(queue, total); });
  if (!st.ok()) return st;
  if (!feeder.calibrator()) {
    return Status::Error("no usable image in '" + o.in + "' (" +
                         std::to_string(feeder.skipped()) + " skipped)");
  }
  *frames = feeder.frames();
  *imu = feeder.imu();
  st = feeder.calibrator()->Solve(r);
  return st.ok() ? st : Status::Error(st.message() + "\nnothing written.");
}

// Without an IMU: the readout from the video alone, fed frame by frame.
Status FeedVideo(const steadiface::PipelineOptions& po,
                 steadiface_ros::CameraInfoSource* info_source, Queue* queue,
                 std::unique_ptr<steadiface::VideoReadoutEstimator>* est) {
  steadiface_bag::BagItem item;
  sensor_msgs::CameraInfoConstPtr last_info;
  while (queue->Pop(&item)) {
    if (item.info) last_info = item.info;
    if (!item.image) continue;
    const sensor_msgs::CameraInfoConstPtr info = info_source->Select(*item.image, last_info);
    cv::Mat image;
    if (!info || !steadiface_ros::ToCvImage(*item.image, &image).ok()) continue;
    if (!*est) {
      steadiface::CameraIntrinsics k;
      Status st = steadiface_ros::ToCameraIntrinsics(*info, &k);
      if (st.ok()) st = steadiface::VideoReadoutEstimator::Create(k, po.shutter, {}, est);
      if (!st.ok()) return st;
    }
    const Status st = (*est)->AddFrame(steadiface::ToGrey(image),
                                       steadiface_ros::ToCoreTime(item.image->header.stamp));
    if (!st.ok()) return st;
  }
  return Status::Ok();
}

Status CalibrateFromVideo(const CalibrateOptions& o, Recording* rec,
                          steadiface::VideoReadoutResult* r, int* frames) {
  std::unique_ptr<steadiface::VideoReadoutEstimator> est;
  const Status st = rec->Read(
      [&](Queue* queue) { return FeedVideo(rec->options(), rec->info_source(), queue, &est); });
  if (!st.ok()) return st;
  if (!est) return Status::Error("no usable image in '" + o.in + "'");
  *r = est->Estimate();
  *frames = est->frames();
  if (!r->determined) {
    std::ostringstream why;
    why << "the readout is not determined from the video: " << r->reason << " ("
        << *frames << " frames, " << r->triples << " frame triples, correlation "
        << r->correlation << ", estimate " << r->readout_s * 1e3 << " +- " << r->sigma_s * 1e3
        << " ms); nothing written.";
    return Status::Error(why.str());
  }
  return Status::Ok();
}

// The overlay without an IMU: the readout alone.
Status WriteVideoOverlay(const steadiface::VideoReadoutResult& r, const std::string& in,
                         int frames, const std::string& out) {
  std::ofstream y(out + ".part");
  y << std::setprecision(9) << "# steadiface_calibrate --in " << in << " (no IMU in it)\n"
    << "# " << frames << " frames; the readout from the video alone: " << r.triples
    << " frame triples, correlation " << r.correlation << ", shake " << r.shake_hz << " Hz.\n"
    << "camera:\n  readout_time: " << r.readout_s << "  # [s] +-" << r.sigma_s * 1e3 << " ms\n";
  y.close();
  if (!y || std::rename((out + ".part").c_str(), out.c_str()) != 0) {
    return Status::Error("cannot write '" + out + "'");
  }
  return Status::Ok();
}

// A recording without IMU messages: the readout from the video alone.
int RunVideoCalibration(const CalibrateOptions& o, Recording* rec) {
  steadiface::VideoReadoutResult r;
  int frames = 0;
  Status st = CalibrateFromVideo(o, rec, &r, &frames);
  if (st.ok()) st = WriteVideoOverlay(r, o.in, frames, o.out);
  if (!st.ok()) {
    std::cerr << "steadiface_calibrate: " << st.message() << "\n";
    return 1;
  }
  if (!o.report.empty()) {
    std::ofstream j(o.report);
    j << std::setprecision(9) << "{\n  \"in\": \"" << o.in << "\",\n  \"frames\": " << frames
      << ",\n  \"imu_samples\": 0,\n  \"readout_s\": " << r.readout_s
      << ",\n  \"readout_sigma_s\": " << r.sigma_s << ",\n  \"readout_determined\": true"
      << ",\n  \"triples\": " << r.triples << ",\n  \"correlation\": " << r.correlation
      << ",\n  \"shake_hz\": " << r.shake_hz << "\n}\n";
  }
  std::cout << "steadiface_calibrate: no IMU in the recording; readout " << r.readout_s * 1e3
            << " ms (+-" << r.sigma_s * 1e3 << ") from the video alone; wrote " << o.out << "\n";
  return 0;
}

}  // namespace

int RunCalibration(const CalibrateOptions& o) {
  Recording rec(o);
  Status st = rec.Open();
  // Without IMU messages, the readout from the video alone.
  if (st.ok() && !rec.has_imu()) return RunVideoCalibration(o, &rec);
  steadiface::CalibrationResult r;
  size_t frames = 0, imu = 0;
  if (st.ok()) st = Calibrate(o, &rec, &r, &frames, &imu);
  if (st.ok()) st = WriteOverlay(r, o.in, frames, o.out);
  if (!st.ok()) {
    std::cerr << "steadiface_calibrate: " << st.message() << "\n";
    return 1;
  }
  if (!o.report.empty()) WriteReport(r, o.in, frames, imu, o.report);
  if (!o.plot.empty()) WritePlot(r, o.plot);
  PrintSummary(r, o.out);
  return 0;
}

}  // namespace steadiface_calibrate
