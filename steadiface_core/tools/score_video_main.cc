// steadiface_score_video: the scorecard's approximate path on any video
// file (no ground truth): head jitter from the detected landmark centre,
// background jitter from KLT tracks outside the face, Liu et al. stability.
// Prints one JSON object. Used to compare steadiface with ffmpeg's vidstab
// and deshake on the same clip (scripts/dev/compare_peers).
//
//   steadiface_score_video VIDEO [--fps F] [--name LABEL]
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "steadiface_core/common/command_line.h"
#include "steadiface_core/eval/ffmpeg_baseline.h"
#include "steadiface_core/eval/video_scorer.h"

namespace {
std::string Num(double v) {
  std::ostringstream o;
  if (std::isfinite(v)) o << v; else o << "null";
  return o.str();
}
}  // namespace

int main(int argc, char** argv) {
  std::string name;
  double fps = 30.0;
  std::vector<std::string> paths;
  steadiface::CommandLine cl;
  cl.Double("--fps", &fps).String("--name", &name).Positional(&paths);
  int status = 0;
  if (!cl.Start(argc, argv, "steadiface_score_video",
                "usage: steadiface_score_video VIDEO [--fps F] [--name LABEL]\n",
                [&paths] { return paths.size() == 1; }, std::cout, std::cerr, &status)) {
    return status;
  }
  const std::string path = paths[0];
  steadiface::eval::VideoScorerOptions o;
  o.fps = fps;
  steadiface::eval::VideoFileScore v;
  const steadiface::Status s = steadiface::eval::ScoreVideoFile(path, o, &v);
  if (!s.ok()) {
    std::cerr << "steadiface_score_video: " << s.message() << "\n";
    return 1;
  }
  const steadiface::eval::Score& sc = v.score;
  const int w = v.width, h = v.height;
  std::cout << "{\"name\": \"" << name << "\", \"video\": \"" << path << "\", \"size\": [" << w
            << ", " << h << "], \"frames\": " << sc.frames
            << ", \"face_fraction\": " << Num(v.face_fraction)
            << ", \"head_jitter_px\": " << Num(sc.head_jitter_px)
            << ", \"head_jitter_frac\": " << Num(sc.head_jitter_frac)
            << ", \"background_jitter_px\": " << Num(sc.background_jitter_px)
            << ", \"head_stability\": " << Num(sc.head_stability)
            << ", \"background_stability\": " << Num(sc.background_stability)
            << ", \"scoring\": \"approximate\"}\n";
  return 0;
}
