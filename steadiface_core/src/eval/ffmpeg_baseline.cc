#include "steadiface_core/eval/ffmpeg_baseline.h"

#include <sys/wait.h>

#include <chrono>
#include <cstdio>

namespace steadiface {
namespace eval {
namespace {

// Single-quotes a path for /bin/sh.
std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

Status PcloseStatus(FILE* pipe, const std::string& what) {
  const int rc = pclose(pipe);
  if (rc == -1 || !WIFEXITED(rc) || WEXITSTATUS(rc) != 0) {
    return Status::Error(what + " failed (exit status " +
                         std::to_string(WIFEXITED(rc) ? WEXITSTATUS(rc) : -1) + ")");
  }
  return Status::Ok();
}

std::string RunCapture(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
  pclose(p);
  return out;
}

// Runs `cmd` (an ffmpeg writing bgr24 frames of w x h to stdout) and hands
// each frame to `sink`; `what` names the command in errors.
Status ReadRawFrames(const std::string& cmd, int w, int h, const std::string& what,
                     const std::function<Status(const cv::Mat&)>& sink) {
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return Status::Error("cannot start ffmpeg");
  cv::Mat frame(h, w, CV_8UC3);
  const size_t bytes = frame.total() * 3;
  Status s = Status::Ok();
  int frames = 0;
  while (s.ok() && fread(frame.data, 1, bytes, p) == bytes) {
    ++frames;
    s = sink(frame);
  }
  if (!s.ok()) {
    // Drain so ffmpeg can exit, then report the sink's error.
    char buf[65536];
    while (fread(buf, 1, sizeof(buf), p) > 0) {
    }
    pclose(p);
    return s;
  }
  s = PcloseStatus(p, what);
  if (s.ok() && frames == 0) return Status::Error(what + ": no frames");
  return s;
}

}  // namespace

const char* FfmpegMethodName(FfmpegMethod m) {
  return m == FfmpegMethod::kVidstab ? "ffmpeg-vidstab" : "ffmpeg-deshake";
}

bool FfmpegAvailable(std::string* version) {
  const std::string v = RunCapture("ffmpeg -hide_banner -version 2>/dev/null");
  if (v.empty()) return false;
  const std::string filters = RunCapture("ffmpeg -hide_banner -filters 2>/dev/null");
  if (filters.find(" vidstabdetect ") == std::string::npos ||
      filters.find(" deshake ") == std::string::npos) {
    return false;
  }
  if (version != nullptr) *version = v.substr(0, v.find('\n'));
  return true;
}

LosslessVideoWriter::~LosslessVideoWriter() {
  if (pipe_ != nullptr) pclose(pipe_);
}

Status LosslessVideoWriter::Open(const std::string& path, int width, int height, double fps) {
  if (pipe_ != nullptr) return Status::Error("LosslessVideoWriter: already open");
  if (width <= 0 || height <= 0 || !(fps > 0.0)) {
    return Status::Error("LosslessVideoWriter: size and fps must be positive");
  }
  char args[256];
  std::snprintf(args, sizeof(args), "-f rawvideo -pix_fmt bgr24 -s %dx%d -r %.6f -i - ", width,
                height, fps);
  const std::string cmd = "ffmpeg -hide_banner -loglevel error -y " + std::string(args) +
                          "-c:v ffv1 -pix_fmt bgr0 " + Quote(path);
  pipe_ = popen(cmd.c_str(), "w");
  if (pipe_ == nullptr) return Status::Error("cannot start ffmpeg");
  width_ = width;
  height_ = height;
  return Status::Ok();
}

Status LosslessVideoWriter::Write(const cv::Mat& bgr) {
  if (pipe_ == nullptr) return Status::Error("LosslessVideoWriter: not open");
  if (bgr.type() != CV_8UC3 || bgr.cols != width_ || bgr.rows != height_) {
    return Status::Error("LosslessVideoWriter: frame must be bgr8 at the opened size");
  }
  for (int r = 0; r < bgr.rows; ++r) {
    const size_t n = static_cast<size_t>(bgr.cols) * 3;
    if (fwrite(bgr.ptr(r), 1, n, pipe_) != n) return Status::Error("ffmpeg pipe closed");
  }
  return Status::Ok();
}

Status LosslessVideoWriter::Close() {
  if (pipe_ == nullptr) return Status::Ok();
  FILE* p = pipe_;
  pipe_ = nullptr;
  return PcloseStatus(p, "ffmpeg (lossless encode)");
}

Status ReadVideo(const std::string& path, const std::function<Status(const cv::Mat&)>& sink,
                 int* width, int* height) {
  const std::string probe = RunCapture(
      "ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=p=0 " +
      Quote(path) + " 2>/dev/null");
  int w = 0, h = 0;
  if (std::sscanf(probe.c_str(), "%d,%d", &w, &h) != 2 || w <= 0 || h <= 0) {
    return Status::Error("cannot read the video size of '" + path + "' (ffprobe)");
  }
  if (width != nullptr) *width = w;
  if (height != nullptr) *height = h;
  const std::string cmd = "ffmpeg -hide_banner -loglevel error -nostdin -i " + Quote(path) +
                          " -f rawvideo -pix_fmt bgr24 -";
  return ReadRawFrames(cmd, w, h, "ffmpeg (decoding " + path + ")", sink);
}

Status RunFfmpegStabilizer(FfmpegMethod method, const std::string& input, int width,
                           int height, const std::string& work_dir,
                           const std::function<Status(const cv::Mat&)>& sink,
                           double* seconds, const FfmpegPeerOptions& peer) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string base = "ffmpeg -hide_banner -loglevel error -nostdin -y -i " + Quote(input);
  std::string filter;
  std::string trf;  // vidstab's transforms file, removed when done
  if (method == FfmpegMethod::kVidstab) {
    trf = work_dir + "/vidstab.trf";
    const std::string detect =
        base + " -vf format=yuv420p,vidstabdetect=result=" + Quote(trf) + " -f null - 2>&1";
    const std::string log = RunCapture(detect + "; echo \"rc=$?\"");
    if (log.find("rc=0") == std::string::npos) {
      std::remove(trf.c_str());
      return Status::Error("ffmpeg vidstabdetect failed: " + log);
    }
    filter = "format=yuv420p,vidstabtransform=input=" + Quote(trf);
    char extra[96] = "";
    if (std::isfinite(peer.vidstab_zoom_percent)) {
      std::snprintf(extra, sizeof(extra), ":optzoom=0:zoom=%.4f", peer.vidstab_zoom_percent);
      filter += extra;
    }
    if (peer.vidstab_smoothing >= 0) filter += ":smoothing=" + std::to_string(peer.vidstab_smoothing);
  } else {
    filter = "format=yuv420p,deshake";
  }
  const std::string cmd = base + " -vf " + filter + " -f rawvideo -pix_fmt bgr24 -";
  const Status s = ReadRawFrames(cmd, width, height, FfmpegMethodName(method), sink);
  if (!trf.empty()) std::remove(trf.c_str());
  if (!s.ok()) return s;
  if (seconds != nullptr) {
    *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return Status::Ok();
}

}  // namespace eval
}  // namespace steadiface
