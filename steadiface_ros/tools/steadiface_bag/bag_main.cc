// steadiface_bag: processes a bag offline, as fast as the machine allows,
// through the same StabilizerWrapper as the nodelet (no ROS master).
//
//   rosrun steadiface steadiface_bag --in input.bag [--out output.bag]
//     [--params a.yaml [--params b.yaml]] [--image camera/image_raw]
//     [--info camera/camera_info] [--imu imu] [--landmarks TOPIC]
//     [--compress none|lz4|bz2] [--debug-images-in-bag]
//     [--video side_by_side.mp4] [--debug-overlay] [--report report.json]
//     [--trajectory traj.csv] [--gyro-only]
//
// Three stages on three threads (bag_reader, bag_stabilizer, bag_writer):
// the reader decodes messages in bag order into a bounded queue; the main
// thread runs the wrapper exactly as the nodelet's callbacks would (same
// order, same results); the writer drains a bounded queue of bag writes.
// Bounded both ways, so memory stays at a few frames whatever the bag size.
#include <malloc.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <iostream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <ros/package.h>
#include <rosbag/bag.h>

#include "steadiface_bag/bag_reader.h"
#include "steadiface_bag/bag_report.h"
#include "steadiface_bag/bag_stabilizer.h"
#include "steadiface_bag/bag_writer.h"
#include "steadiface_core/common/command_line.h"
#include "steadiface_core/face/landmark_predictor.h"
#include "steadiface_ros/camera_info_source.h"
#include "steadiface_ros/params.h"
#include "steadiface_ros/stabilizer_wrapper.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Args {
  std::string in, out, video, report, trajectory, truth, plot_dir,
      plot_name = "bag";
  std::vector<std::string> params;
  steadiface_bag::BagTopics topics;
  std::string compress = "none";
  bool debug_overlay = false, debug_images_in_bag = false, gyro_only = false,
       quiet = false, no_pipeline = false, rosbag_reader = false,
       verify_checksums = false;
  double start_stamp = 0.0;  // images before this stamp are skipped
  std::string
      only_stamps;  // file of image stamps [s] to process; others skipped
};

int Usage() {
  std::cerr
      << "usage: steadiface_bag --in IN.bag [--out OUT.bag] [--params "
         "P.yaml]...\n"
         "  [--image TOPIC] [--info TOPIC] [--imu TOPIC] [--landmarks TOPIC]\n"
         "  [--compress none|lz4|bz2: chunk compression of OUT.bag (default "
         "none)]\n"
         "  [--debug-images-in-bag: also write the debug overlay images into "
         "OUT.bag]\n"
         "  [--video OUT.mp4] [--debug-overlay] [--report OUT.json]\n"
         "  [--trajectory OUT.csv] [--gyro-only] [--quiet]\n"
         "  [--no-pipeline: render each frame before processing the next (by "
         "default\n"
         "   frame n renders on a second thread while frame n+1 is processed)]\n"
         "  [--rosbag-reader: read IN.bag through rosbag::View (by default an "
         "indexed\n"
         "   reader gives the same messages in the same order with less work; "
         "bags it\n"
         "   does not handle, e.g. BZ2 chunks, are read through rosbag::View "
         "anyway)]\n"
         "  [--verify-checksums: check the LZ4 chunks' checksums in the "
         "indexed reader too\n"
         "   (rosbag::View always does; about 10 % slower on an LZ4 bag)]\n"
         "  [--truth IN.bag.truth.csv (default: found beside the bag)]\n"
         "  [--plots DIR --name NAME: trajectories for "
         "scripts/plot_report.py]\n"
         "  [--start-stamp S: skip images stamped before S (IMU is still "
         "read)]\n"
         "  [--only-stamps FILE: process only the images whose stamps [s] are "
         "listed,\n"
         "   one per line (to replay exactly the frames a live run received)]\n"
         "The image topic may hold sensor_msgs/CompressedImage (jpeg/png, "
         "e.g.\n"
         "--image camera/image_raw/compressed); it is decoded on the reader "
         "thread.\n"
         "Intrinsics come from the bag's camera_info topic or, when the bag "
         "has none,\n"
         "from the camera_info_url parameter (file://, package:// or a path to "
         "a\n"
         "camera_calibration YAML/INI) in a --params file.\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  // An offline batch run: freed memory stays in the allocator for the next
  // frame's buffers (images of several MB, which glibc would otherwise map
  // and unmap, or trim off its heap) instead of going back to the kernel
  // and coming back as fresh pages, each cleared and faulted in again.
  // Peak memory is unchanged (maximum RSS within 2 MB either way on the
  // speed protocol's clip); minor page faults 24 500 -> 18 600.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  Args a;
  steadiface::CommandLine cl;
  cl.String("--in", &a.in).String("--out", &a.out).Strings("--params", &a.params);
  cl.String("--image", &a.topics.image).String("--info", &a.topics.info);
  cl.String("--imu", &a.topics.imu).String("--landmarks", &a.topics.landmarks);
  cl.String("--compress", &a.compress).Flag("--debug-images-in-bag", &a.debug_images_in_bag);
  cl.String("--video", &a.video).Flag("--debug-overlay", &a.debug_overlay);
  cl.String("--report", &a.report).String("--trajectory", &a.trajectory);
  cl.Flag("--gyro-only", &a.gyro_only).Flag("--no-pipeline", &a.no_pipeline);
  cl.Flag("--rosbag-reader", &a.rosbag_reader).Flag("--verify-checksums", &a.verify_checksums);
  cl.Flag("--quiet", &a.quiet).String("--truth", &a.truth);
  cl.Double("--start-stamp", &a.start_stamp).String("--only-stamps", &a.only_stamps);
  cl.String("--plots", &a.plot_dir).String("--name", &a.plot_name);
  std::string error;
  const steadiface::CommandLine::Result parsed = cl.Parse(argc, argv, &error);
  if (parsed == steadiface::CommandLine::Result::kHelp) {
    Usage();
    return 0;
  }
  if (parsed == steadiface::CommandLine::Result::kError) {
    std::cerr << "steadiface_bag: " << error << "\n";
    return Usage();
  }
  if (a.in.empty()) return Usage();
  if (a.compress != "none" && a.compress != "lz4" && a.compress != "bz2") {
    std::cerr << "steadiface_bag: --compress takes none, lz4 or bz2, not '"
              << a.compress << "'\n";
    return 2;
  }
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
  // Offline, throughput counts and latency does not: render each frame on
  // a second thread while the next one is processed (same output).
  wo.pipelined = !a.no_pipeline;
  wo.scheduler.pipeline_hold_s = 1.0;  // bag time: the next frame's gyro comes later
  if (a.gyro_only) {
    po.stabilizer.gyro_only = true;
    po.landmark_source = steadiface::LandmarkSource::kNone;
  }
  if (!a.topics.landmarks.empty())
    po.landmark_source = steadiface::LandmarkSource::kExternal;
  // The landmark model's load (~1 ms from its packed cache, whose leaves
  // are mapped; 0.6-0.9 s when it must decode dlib's file) runs on a second
  // thread while the bag is opened and its index read; the wrapper then
  // finds the model in the process's memo. (A failed load is reported by
  // the wrapper's own.)
  std::future<std::unique_ptr<steadiface::LandmarkPredictor>> preload;
  if (po.landmark_source != steadiface::LandmarkSource::kNone) {
    preload = std::async(std::launch::async, [path = po.face.landmark_model_path] {
      std::unique_ptr<steadiface::LandmarkPredictor> model;
      steadiface::LandmarkPredictor::Load(path, &model);
      return model;
    });
  }
  steadiface_ros::CameraInfoSource info_source(
      [&a](bool is_error, const std::string& text) {
        if (is_error || !a.quiet)
          std::cerr << "steadiface_bag: " << text << "\n";
      });
  st = info_source.Load(wo.camera_info_url);
  if (!st.ok()) {
    std::cerr << "steadiface_bag: " << st.message() << "\n";
    return 1;
  }

  // Reader stage.
  steadiface_bag::BagReader reader(a.in, a.topics, !a.rosbag_reader, a.verify_checksums);
  st = reader.Open(/*info_required=*/!info_source.has_file_info());
  if (!st.ok()) {
    std::cerr << "steadiface_bag: " << st.message() << "\n";
    return 1;
  }

  // Writer stage.
  steadiface_bag::BagSink sink;
  sink.debug = (a.debug_overlay && !a.video.empty()) ||
               (a.debug_images_in_bag && !a.out.empty());
  sink.debug_to_bag = a.debug_images_in_bag;
  {
    std::string img = steadiface_bag::NormalizeTopic(a.topics.image);
    // camera/image_raw/compressed publishes as camera/image_stabilized/...
    const std::string suffix = "/compressed";
    if (reader.compressed() && img.size() > suffix.size() &&
        img.compare(img.size() - suffix.size(), suffix.size(), suffix) == 0) {
      img.resize(img.size() - suffix.size());
    }
    const size_t slash = img.rfind('/');
    sink.ns =
        slash == 0 || slash == std::string::npos ? "" : img.substr(0, slash);
  }
  // Constructed only for --out: a rosbag::Bag loads rosbag's encryptor
  // plugins (pluginlib asks rospack for every package's exports).
  std::unique_ptr<rosbag::Bag> out;
  const std::string out_tmp = a.out + ".part";
  if (!a.out.empty()) {
    try {
      out.reset(new rosbag::Bag);
      out->open(out_tmp, rosbag::bagmode::Write);
      out->setCompression(a.compress == "lz4" ? rosbag::compression::LZ4
                         : a.compress == "bz2"
                             ? rosbag::compression::BZ2
                             : rosbag::compression::Uncompressed);
    } catch (const rosbag::BagException& e) {
      std::cerr << "steadiface_bag: cannot write '" << out_tmp
                << "': " << e.what() << "\n";
      return 1;
    }
  }
  std::unique_ptr<steadiface_bag::AsyncBagWriter> writer;
  if (!a.out.empty()) {
    writer.reset(new steadiface_bag::AsyncBagWriter(out.get()));
    sink.out = writer.get();
  }
  // Ground truth (simulator bags): the run is scored as it goes.
  std::string truth = a.truth;
  if (truth.empty() && std::ifstream(a.in + ".truth.csv").good()) truth = a.in + ".truth.csv";
  std::unique_ptr<steadiface_bag::TruthScorer> scorer;
  if (!truth.empty()) {
    st = steadiface_bag::TruthScorer::Create(truth, po, &scorer);
    if (!st.ok()) {
      std::cerr << "steadiface_bag: " << st.message() << "; the report has no ground truth\n";
      scorer.reset();
    } else {
      steadiface_bag::TruthScorer* sc = scorer.get();
      sink.on_frame = [sc](const steadiface::PipelineFrame& f, const steadiface::Pipeline& p) {
        sc->Add(f.stabilizer.stamp, f, p);
      };
    }
  }
  steadiface_bag::SideBySideVideo video(a.video);
  sink.wants_image = !a.out.empty() || video.enabled();

  // Stabilizer stage.
  steadiface_bag::FrameSelection selection;
  selection.start_stamp = a.start_stamp;
  if (!a.only_stamps.empty()) {
    std::ifstream f(a.only_stamps);
    if (!f) {
      std::cerr << "steadiface_bag: cannot read '" << a.only_stamps << "'\n";
      return 1;
    }
    double t;
    while (f >> t) selection.only.insert(std::llround(t * 1e3));
    if (selection.only.empty()) {
      std::cerr << "steadiface_bag: no stamps in '" << a.only_stamps << "'\n";
      return 1;
    }
  }
  // Held until the wrapper has its own reference (the memo is weak).
  const std::unique_ptr<steadiface::LandmarkPredictor> preloaded =
      preload.valid() ? preload.get() : nullptr;
  steadiface_ros::StabilizerWrapper wrapper(po, wo, &sink);
  steadiface_bag::BagStabilizer stabilizer(&wrapper, &info_source,
                                           reader.has_info(), selection);
  stabilizer.set_on_image(
      [&video](const sensor_msgs::Image& img) { video.AddInput(img); });

  const size_t total_images = reader.ImageCount();
  const bool tty = isatty(STDERR_FILENO) && !a.quiet;
  const auto start = Clock::now();
  size_t state_written = 0;
  steadiface_bag::BoundedQueue<steadiface_bag::BagItem> read_queue(64);
  reader.Start(&read_queue);
  steadiface_bag::BagItem item;
  while (read_queue.Pop(&item)) {
    stabilizer.Process(item);
    video.AddOutput(&sink);
    const size_t done = sink.states.size();
    if (done != state_written && (tty || done % 100 == 0)) {
      state_written = done;
      const double el =
          std::chrono::duration<double>(Clock::now() - start).count();
      const double fps = done / std::max(el, 1e-9);
      const double eta = total_images > done
                             ? (total_images - done) / std::max(fps, 1e-9)
                             : 0.0;
      if (tty) {
        fprintf(stderr, "\r[%-30s] %zu/%zu frames  %.1f fps  ETA %.0f s ",
                std::string(30 * done / std::max<size_t>(1, total_images), '#')
                    .c_str(),
                done, total_images, fps, eta);
      } else if (!a.quiet) {
        fprintf(stderr,
                "steadiface_bag: %zu/%zu frames, %.1f fps, ETA %.0f s\n", done,
                total_images, fps, eta);
      }
    }
  }
  const std::string read_error = reader.Join();
  if (!read_error.empty()) {
    std::cerr << "steadiface_bag: reading " << a.in << " failed: " << read_error
              << "\n";
    if (writer) writer->Finish();
    if (!a.out.empty()) std::remove(out_tmp.c_str());
    return 1;
  }
  if (reader.decode_failures() > 0) {
    std::cerr << "steadiface_bag: " << reader.decode_failures()
              << " compressed images did not decode and were skipped\n";
  }
  wrapper.Flush();
  video.AddOutput(&sink);
  if (tty) fprintf(stderr, "\n");
  reader.Close();
  if (writer) {
    const std::string err = writer->Finish();
    if (!err.empty()) {
      std::cerr << "steadiface_bag: writing " << out_tmp << " failed: " << err
                << "\n";
      std::remove(out_tmp.c_str());
      return 1;
    }
  }
  video.Finish();
  const double elapsed =
      std::chrono::duration<double>(Clock::now() - start).count();
  if (out) {
    out->close();
    if (std::rename(out_tmp.c_str(), a.out.c_str()) != 0) {
      std::cerr << "steadiface_bag: cannot rename " << out_tmp << "\n";
      return 1;
    }
  }

  // Report: what can be measured without ground truth, and the ground
  // truth's jitter for simulator bags.
  const steadiface_ros::WrapperStatus ws = wrapper.Status();
  steadiface_bag::ReportInputs r;
  r.in = a.in;
  r.truth = truth;
  r.scorer = scorer.get();
  r.plot_dir = a.plot_dir;
  r.plot_name = a.plot_name;
  r.gyro_only = a.gyro_only;
  // The stabilizer's wall time: scoring against ground truth is not its.
  r.scoring_s = scorer ? scorer->seconds() : 0.0;
  r.elapsed_s = elapsed - r.scoring_s;
  r.crop_ratio = po.warp.output.crop_ratio;
  const std::string report = steadiface_bag::MakeReport(r, sink, ws);
  if (!a.report.empty()) {
    std::ofstream f(a.report + ".part");
    f << report;
    f.close();
    std::rename((a.report + ".part").c_str(), a.report.c_str());
  }
  if (!a.trajectory.empty())
    steadiface_bag::WriteTrajectory(a.trajectory, sink);
  if (!a.quiet) {
    std::cerr << "steadiface_bag: " << ws.counters.frames_out << " frames in "
              << elapsed << " s ("
              << ws.counters.frames_out / std::max(elapsed, 1e-9) << " fps)"
              << (a.out.empty() ? "" : ", wrote " + a.out)
              << (a.video.empty() || video.failed() ? "" : ", " + a.video)
              << (a.report.empty() ? "" : ", " + a.report) << "\n";
  }
  return ws.counters.frames_out > 0 && !video.failed() ? 0 : 1;
}
