// steadiface_calibrate: the camera-IMU calibration from a recording with a
// few seconds of hand shake (issue 16). Estimates the IMU->camera rotation,
// the clock offset, the rolling-shutter readout and a gyro bias
// (steadiface::Calibrator), and writes a parameter overlay that
// stabilize.launch (params:=) and steadiface_bag (--params) load as is.
//   steadiface_calibrate --in BAG [--image T] [--info T] [--imu T]
//       --out overlay.yaml [--report r.json] [--plot DIR] [--params P.yaml]...
// Refuses (exit 1, no overlay written) when the recording cannot determine
// the result, saying why.
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <ros/package.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "steadiface_bag/bag_reader.h"
#include "steadiface_bag/bounded_queue.h"
#include "steadiface_core/calibration/calibrator.h"
#include "steadiface_core/common/command_line.h"
#include "steadiface_ros/camera_info_source.h"
#include "steadiface_ros/msg_conversion.h"
#include "steadiface_ros/params.h"
#include "steadiface_ros/time_conversion.h"

namespace {

int Usage(std::ostream& os) {
  os << "usage: steadiface_calibrate --in BAG --out overlay.yaml [--report "
        "r.json]\n"
        "  [--plot DIR] [--image TOPIC] [--info TOPIC] [--imu TOPIC] [--params "
        "P.yaml]...\n"
        "  [--no-readout: keep camera/readout_time] [--quiet]\n"
        "Estimates imu/R_cam_imu, imu/time_offset, imu/gyro_bias and "
        "camera/readout_time\n"
        "from a recording with a few seconds of hand shake, and writes\n"
        "them as an overlay for stabilize.launch params:= and steadiface_bag "
        "--params.\n"
        "--params files (on top of config/default.yaml) give the starting "
        "point:\n"
        "camera/stamp, camera/readout_time, imu/time_offset (the search is "
        "+-0.5 s\n"
        "around it) and camera_info_url when the bag has no camera_info.\n"
        "Exit 0 with the overlay written; 1 when the recording cannot "
        "determine the\n"
        "result (the reason is printed; nothing is written); 2 on usage "
        "errors.\n";
  return &os == &std::cout ? 0 : 2;
}

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

}  // namespace

int main(int argc, char** argv) {
  std::string in, out, report, plot;
  std::vector<std::string> extra_params;
  steadiface_bag::BagTopics topics;
  bool quiet = false, readout = true;
  steadiface::CommandLine cl;
  cl.String("--in", &in).String("--out", &out).String("--report", &report);
  cl.String("--plot", &plot).String("--image", &topics.image).String("--info", &topics.info);
  cl.String("--imu", &topics.imu).Strings("--params", &extra_params);
  cl.Flag("--quiet", &quiet).ClearFlag("--no-readout", &readout);
  std::string error;
  const steadiface::CommandLine::Result parsed = cl.Parse(argc, argv, &error);
  if (parsed == steadiface::CommandLine::Result::kHelp) return Usage(std::cout);
  if (parsed == steadiface::CommandLine::Result::kError) {
    std::cerr << "steadiface_calibrate: " << error << "\n";
    return Usage(std::cerr);
  }
  if (in.empty() || out.empty()) return Usage(std::cerr);
  // The starting point: the package defaults and the user's overlays.
  std::vector<std::string> files;
  const std::string pkg = ros::package::getPath("steadiface");
  if (!pkg.empty()) files.push_back(pkg + "/config/default.yaml");
  files.insert(files.end(), extra_params.begin(), extra_params.end());
  std::unique_ptr<steadiface_ros::ParamSource> params;
  steadiface::Status st = steadiface_ros::YamlParams(files, &params);
  steadiface::PipelineOptions po;
  steadiface_ros::WrapperOptions wo;
  if (st.ok()) st = steadiface_ros::LoadOptions(*params, &po, &wo);
  if (!st.ok()) {
    std::cerr << "steadiface_calibrate: " << st.message() << "\n";
    return 1;
  }
  steadiface_ros::CameraInfoSource info_source(
      [quiet](bool is_error, const std::string& text) {
        if (is_error || !quiet)
          std::cerr << "steadiface_calibrate: " << text << "\n";
      });
  st = info_source.Load(wo.camera_info_url);
  steadiface_bag::BagReader reader(in, topics);
  if (st.ok()) st = reader.Open(/*info_required=*/!info_source.has_file_info());
  if (!st.ok()) {
    std::cerr << "steadiface_calibrate: " << st.message() << "\n";
    return 1;
  }
  const size_t total = reader.ImageCount();
  steadiface_bag::BoundedQueue<steadiface_bag::BagItem> queue(64);
  reader.Start(&queue);
  steadiface::CalibratorOptions co;
  co.estimate_readout = readout;
  std::unique_ptr<steadiface::Calibrator> cal;
  sensor_msgs::CameraInfoConstPtr last_info;
  steadiface::CameraIntrinsics k;
  size_t frames = 0, skipped = 0, imu = 0;
  // Gyro samples before the first image (the calibrator needs its
  // intrinsics first); bounded: an hour at 1 kHz would be 3.6e6.
  constexpr size_t kMaxEarly = 1000000;
  std::vector<steadiface::GyroSample> early;
  steadiface_bag::BagItem item;
  while (queue.Pop(&item)) {
    if (item.imu) {
      ++imu;
      if (cal) {
        cal->AddGyro(steadiface_ros::ToGyroSample(*item.imu));
      } else if (early.size() < kMaxEarly) {
        early.push_back(
            steadiface_ros::ToGyroSample(*item.imu));  // until the first image
      }
    }
    if (item.info) last_info = item.info;
    if (!item.image) continue;
    const sensor_msgs::CameraInfoConstPtr info =
        info_source.Select(*item.image, last_info);
    if (!info) {
      ++skipped;
      continue;
    }
    if (!cal) {
      st = steadiface_ros::ToCameraIntrinsics(*info, &k);
      if (st.ok()) {
        st = steadiface::Calibrator::Create(k, po.shutter, po.imu.R_cam_imu,
                                            po.imu.imu_time_offset_s, co, &cal);
      }
      if (!st.ok()) {
        std::cerr << "steadiface_calibrate: " << st.message() << "\n";
        queue.Close();
        reader.Join();
        return 1;
      }
      for (const auto& g : early) cal->AddGyro(g);
      early.clear();
    }
    cv::Mat image;
    st = steadiface_ros::ToCvImage(*item.image, &image);
    if (st.ok())
      st = cal->AddFrame(image,
                         steadiface_ros::ToCoreTime(item.image->header.stamp));
    if (!st.ok()) {
      ++skipped;
      continue;
    }
    ++frames;
    if (!quiet && frames % 100 == 0) {
      std::cerr << "steadiface_calibrate: frame " << frames << " / " << total
                << "\n";
    }
  }
  const std::string reader_error = reader.Join();
  if (!reader_error.empty()) {
    std::cerr << "steadiface_calibrate: " << reader_error << "\n";
    return 1;
  }
  if (!cal) {
    std::cerr << "steadiface_calibrate: no usable image in '" << in << "' ("
              << skipped << " skipped)\n";
    return 1;
  }
  steadiface::CalibrationResult r;
  st = cal->Solve(&r);
  if (!st.ok()) {
    std::cerr << "steadiface_calibrate: " << st.message()
              << "\nnothing written.\n";
    return 1;
  }
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
    std::cerr << "steadiface_calibrate: cannot write '" << out << "'\n";
    return 1;
  }
  if (!report.empty()) {
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
  if (!plot.empty()) {
    std::ofstream c(plot + "/angular_speed.csv");
    c << "t,video,gyro_before,gyro_after\n";
    for (size_t i = 0; i < r.plot_t.size(); ++i) {
      c << r.plot_t[i] << "," << r.plot_video[i] << "," << r.plot_gyro_before[i]
        << "," << r.plot_gyro_after[i] << "\n";
    }
    Plot(r, plot + "/angular_speed.png");
  }
  std::cout << "steadiface_calibrate: time_offset " << r.time_offset_s * 1e3
            << " ms (+-" << r.time_offset_sigma_s * 1e3 << "), readout "
            << r.readout_s * 1e3 << " ms"
            << (r.readout_determined ? "" : " (not determined)")
            << ", R_cam_imu [" << q.x() << ", " << q.y() << ", " << q.z()
            << ", " << q.w() << "] (" << r.misalignment_deg
            << " deg from an axis permutation), residual "
            << r.residual_before_px << " -> " << r.residual_after_px
            << " px; wrote " << out << "\n";
  return 0;
}
