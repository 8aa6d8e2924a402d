#include "steadiface_bag/bag_run.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <iostream>
#include <memory>

#include <rosbag/bag.h>

#include "steadiface_bag/bag_report.h"
#include "steadiface_bag/bag_stabilizer.h"
#include "steadiface_bag/bag_writer.h"
#include "steadiface_core/face/landmark_predictor.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_ros/camera_info_source.h"
#include "steadiface_ros/params.h"
#include "steadiface_ros/stabilizer_wrapper.h"

namespace steadiface_bag {
namespace {

using Clock = std::chrono::steady_clock;
using steadiface::Status;

// The package defaults, then the user's files; then what the run itself
// decides (pipelined rendering, gyro only, landmarks from a topic).
Status LoadBagOptions(const BagRunOptions& a, steadiface::PipelineOptions* po,
                      steadiface_ros::WrapperOptions* wo) {
  const Status st = steadiface_ros::LoadPackageOptions(a.params, po, wo);
  if (!st.ok()) return st;
  // Offline, throughput counts and latency does not: render each frame on
  // a second thread while the next one is processed (same output).
  wo->pipelined = !a.no_pipeline;
  wo->scheduler.pipeline_hold_s = 1.0;  // bag time: the next frame's gyro comes later
  if (a.gyro_only) {
    po->stabilizer.gyro_only = true;
    po->landmark_source = steadiface::LandmarkSource::kNone;
  }
  if (!a.topics.landmarks.empty()) po->landmark_source = steadiface::LandmarkSource::kExternal;
  return Status::Ok();
}

// The landmark model's load (~1 ms from its packed cache, whose leaves are
// mapped; 0.6-0.9 s when it must decode dlib's file) runs on a second
// thread while the bag is opened and its index read; the wrapper then finds
// the model in the process's memo. (A failed load is reported by the
// wrapper's own.)
std::future<std::unique_ptr<steadiface::LandmarkPredictor>> PreloadLandmarks(
    const steadiface::PipelineOptions& po) {
  if (po.landmark_source == steadiface::LandmarkSource::kNone) return {};
  return std::async(std::launch::async, [path = po.face.landmark_model_path] {
    std::unique_ptr<steadiface::LandmarkPredictor> model;
    if (!steadiface::LandmarkPredictor::Load(path, &model).ok()) model.reset();
    return model;
  });
}

// The camera namespace the output topics go to: the image topic's, without
// a /compressed transport suffix (camera/image_raw/compressed publishes as
// camera/image_stabilized/...).
std::string OutputNamespace(const std::string& image_topic, bool compressed) {
  std::string img = NormalizeTopic(image_topic);
  const std::string suffix = "/compressed";
  if (compressed && img.size() > suffix.size() &&
      img.compare(img.size() - suffix.size(), suffix.size(), suffix) == 0) {
    img.resize(img.size() - suffix.size());
  }
  const size_t slash = img.rfind('/');
  return slash == 0 || slash == std::string::npos ? "" : img.substr(0, slash);
}

// Opens `path` for writing with the compression asked for. Constructed only
// for --out: a rosbag::Bag loads rosbag's encryptor plugins (pluginlib asks
// rospack for every package's exports).
Status OpenOutBag(const std::string& path, const std::string& compress,
                  std::unique_ptr<rosbag::Bag>* out) {
  try {
    out->reset(new rosbag::Bag);
    (*out)->open(path, rosbag::bagmode::Write);
    (*out)->setCompression(compress == "lz4"   ? rosbag::compression::LZ4
                           : compress == "bz2" ? rosbag::compression::BZ2
                                               : rosbag::compression::Uncompressed);
  } catch (const rosbag::BagException& e) {
    return Status::Error("cannot write '" + path + "': " + e.what());
  }
  return Status::Ok();
}

// The frames to process: from --start-stamp on, and only --only-stamps'.
Status ReadSelection(const BagRunOptions& a, FrameSelection* selection) {
  selection->start_stamp = a.start_stamp;
  if (a.only_stamps.empty()) return Status::Ok();
  std::ifstream f(a.only_stamps);
  if (!f) return Status::Error("cannot read '" + a.only_stamps + "'");
  double t;
  while (f >> t) selection->only.insert(std::llround(t * 1e3));
  if (selection->only.empty()) return Status::Error("no stamps in '" + a.only_stamps + "'");
  return Status::Ok();
}

// Progress on stderr: a bar on a terminal, else a line per 100 frames.
class Progress {
 public:
  Progress(size_t total, bool quiet)
      : total_(total), tty_(isatty(STDERR_FILENO) && !quiet), quiet_(quiet) {}
  void Update(size_t done) {
    if (done == written_ || !(tty_ || done % 100 == 0)) return;
    written_ = done;
    const double el = std::chrono::duration<double>(Clock::now() - start_).count();
    const double fps = done / std::max(el, 1e-9);
    const double eta = total_ > done ? (total_ - done) / std::max(fps, 1e-9) : 0.0;
    if (tty_) {
      fprintf(stderr, "\r[%-30s] %zu/%zu frames  %.1f fps  ETA %.0f s ",
              std::string(30 * done / std::max<size_t>(1, total_), '#').c_str(), done, total_,
              fps, eta);
    } else if (!quiet_) {
      fprintf(stderr, "steadiface_bag: %zu/%zu frames, %.1f fps, ETA %.0f s\n", done, total_,
              fps, eta);
    }
  }
  void End() const {
    if (tty_) fprintf(stderr, "\n");
  }
  double Elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  const size_t total_;
  const bool tty_, quiet_;
  const Clock::time_point start_ = Clock::now();
  size_t written_ = 0;
};

// One run: the options, the three stages and what they produce.
class BagRun {
 public:
  explicit BagRun(const BagRunOptions& a) : a_(a), out_tmp_(a.out + ".part") {}
  Status Prepare();
  Status Run();
  // The summary line, the report and the trajectory; the exit status.
  int Finish();

 private:
  Status OpenStages();
  void SetUpTruth();
  Status Drain(steadiface_ros::StabilizerWrapper* wrapper, BagStabilizer* stabilizer);

  const BagRunOptions& a_;
  const std::string out_tmp_;
  steadiface::PipelineOptions po_;
  steadiface_ros::WrapperOptions wo_;
  std::future<std::unique_ptr<steadiface::LandmarkPredictor>> preload_;
  std::unique_ptr<steadiface_ros::CameraInfoSource> info_source_;
  std::unique_ptr<BagReader> reader_;
  BagSink sink_;
  std::unique_ptr<rosbag::Bag> out_;
  std::unique_ptr<AsyncBagWriter> writer_;
  std::string truth_;
  std::unique_ptr<TruthScorer> scorer_;
  std::unique_ptr<SideBySideVideo> video_;
  FrameSelection selection_;
  steadiface_ros::WrapperStatus status_;
  double elapsed_s_ = 0.0;
  // Last: destroyed first, while the sink and the scorer it feeds live.
  std::unique_ptr<steadiface_ros::StabilizerWrapper> wrapper_;
};

Status BagRun::Prepare() {
  Status st = LoadBagOptions(a_, &po_, &wo_);
  if (!st.ok()) return st;
  // Runs, as the node does (which WARNs on /diagnostics), but is said.
  const std::string conflict = steadiface::OptionsConflict(po_);
  if (!conflict.empty()) std::cerr << "steadiface_bag: warning: " << conflict << "\n";
  preload_ = PreloadLandmarks(po_);
  const bool quiet = a_.quiet;
  info_source_.reset(new steadiface_ros::CameraInfoSource(
      [quiet](bool is_error, const std::string& text) {
        if (is_error || !quiet) std::cerr << "steadiface_bag: " << text << "\n";
      }));
  st = info_source_->Load(wo_.camera_info_url);
  if (st.ok()) st = OpenStages();
  if (st.ok()) st = ReadSelection(a_, &selection_);
  return st;
}

Status BagRun::OpenStages() {
  reader_.reset(new BagReader(a_.in, a_.topics, !a_.rosbag_reader, a_.verify_checksums));
  Status st = reader_->Open(/*info_required=*/!info_source_->has_file_info());
  if (!st.ok()) return st;
  sink_.debug = (a_.debug_overlay && !a_.video.empty()) ||
                (a_.debug_images_in_bag && !a_.out.empty());
  sink_.debug_to_bag = a_.debug_images_in_bag;
  sink_.ns = OutputNamespace(a_.topics.image, reader_->compressed());
  if (!a_.out.empty()) {
    st = OpenOutBag(out_tmp_, a_.compress, &out_);
    if (!st.ok()) return st;
    writer_.reset(new AsyncBagWriter(out_.get()));
    sink_.out = writer_.get();
  }
  SetUpTruth();
  video_.reset(new SideBySideVideo(a_.video));
  sink_.wants_image = !a_.out.empty() || video_->enabled();
  return Status::Ok();
}

// Ground truth (simulator bags): the run is scored as it goes.
void BagRun::SetUpTruth() {
  truth_ = a_.truth;
  if (truth_.empty() && std::ifstream(a_.in + ".truth.csv").good()) truth_ = a_.in + ".truth.csv";
  if (truth_.empty()) return;
  const Status st = TruthScorer::Create(truth_, po_, &scorer_);
  if (!st.ok()) {
    std::cerr << "steadiface_bag: " << st.message() << "; the report has no ground truth\n";
    scorer_.reset();
    return;
  }
  TruthScorer* sc = scorer_.get();
  sink_.on_frame = [sc](const steadiface::PipelineFrame& f, const steadiface::Pipeline& p) {
    sc->Add(f.stabilizer.stamp, f, p);
  };
}

Status BagRun::Drain(steadiface_ros::StabilizerWrapper* wrapper, BagStabilizer* stabilizer) {
  Progress progress(reader_->ImageCount(), a_.quiet);
  BoundedQueue<BagItem> read_queue(64);
  reader_->Start(&read_queue);
  BagItem item;
  while (read_queue.Pop(&item)) {
    stabilizer->Process(item);
    video_->AddOutput(&sink_);
    progress.Update(sink_.states.size());
  }
  const std::string read_error = reader_->Join();
  if (!read_error.empty()) {
    if (writer_) writer_->Finish();
    if (!a_.out.empty()) std::remove(out_tmp_.c_str());
    return Status::Error("reading " + a_.in + " failed: " + read_error);
  }
  if (reader_->decode_failures() > 0) {
    std::cerr << "steadiface_bag: " << reader_->decode_failures()
              << " compressed images did not decode and were skipped\n";
  }
  wrapper->Flush();
  video_->AddOutput(&sink_);
  progress.End();
  reader_->Close();
  if (writer_) {
    const std::string err = writer_->Finish();
    if (!err.empty()) {
      std::remove(out_tmp_.c_str());
      return Status::Error("writing " + out_tmp_ + " failed: " + err);
    }
  }
  video_->Finish();
  elapsed_s_ = progress.Elapsed();
  return Status::Ok();
}

Status BagRun::Run() {
  // Held until the wrapper has its own reference (the memo is weak).
  const std::unique_ptr<steadiface::LandmarkPredictor> preloaded =
      preload_.valid() ? preload_.get() : nullptr;
  wrapper_.reset(new steadiface_ros::StabilizerWrapper(po_, wo_, &sink_));
  BagStabilizer stabilizer(wrapper_.get(), info_source_.get(), reader_->has_info(), selection_);
  SideBySideVideo* video = video_.get();
  stabilizer.set_on_image([video](const sensor_msgs::Image& img) { video->AddInput(img); });
  const Status st = Drain(wrapper_.get(), &stabilizer);
  if (!st.ok()) return st;
  if (out_) {
    out_->close();
    if (std::rename(out_tmp_.c_str(), a_.out.c_str()) != 0) {
      return Status::Error("cannot rename " + out_tmp_);
    }
  }
  status_ = wrapper_->CurrentStatus();
  return Status::Ok();
}

int BagRun::Finish() {
  // Report: what can be measured without ground truth, and the ground
  // truth's jitter for simulator bags.
  ReportInputs r;
  r.in = a_.in;
  r.truth = truth_;
  r.scorer = scorer_.get();
  r.plot_dir = a_.plot_dir;
  r.plot_name = a_.plot_name;
  r.gyro_only = a_.gyro_only;
  // The stabilizer's wall time: scoring against ground truth is not its.
  r.scoring_s = scorer_ ? scorer_->seconds() : 0.0;
  r.elapsed_s = elapsed_s_ - r.scoring_s;
  r.crop_ratio = po_.warp.output.crop_ratio;
  const std::string report = MakeReport(r, sink_, status_);
  if (!a_.report.empty()) {
    std::ofstream f(a_.report + ".part");
    f << report;
    f.close();
    std::rename((a_.report + ".part").c_str(), a_.report.c_str());
  }
  if (!a_.trajectory.empty()) WriteTrajectory(a_.trajectory, sink_);
  const size_t frames = status_.counters.frames_out;
  if (!a_.quiet) {
    std::cerr << "steadiface_bag: " << frames << " frames in " << elapsed_s_ << " s ("
              << frames / std::max(elapsed_s_, 1e-9) << " fps)"
              << (a_.out.empty() ? "" : ", wrote " + a_.out)
              << (a_.video.empty() || video_->failed() ? "" : ", " + a_.video)
              << (a_.report.empty() ? "" : ", " + a_.report) << "\n";
  }
  return frames > 0 && !video_->failed() ? 0 : 1;
}

}  // namespace

int RunBag(const BagRunOptions& a) {
  if (a.compress != "none" && a.compress != "lz4" && a.compress != "bz2") {
    std::cerr << "steadiface_bag: --compress takes none, lz4 or bz2, not '" << a.compress
              << "'\n";
    return 2;
  }
  BagRun run(a);
  Status st = run.Prepare();
  if (st.ok()) st = run.Run();
  if (!st.ok()) {
    std::cerr << "steadiface_bag: " << st.message() << "\n";
    return 1;
  }
  return run.Finish();
}

}  // namespace steadiface_bag
