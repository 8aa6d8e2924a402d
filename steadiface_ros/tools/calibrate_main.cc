// steadiface_calibrate: the camera-IMU calibration from a recording with a
// few seconds of hand shake (issue 16). Estimates the IMU->camera rotation,
// the clock offset, the rolling-shutter readout and a gyro bias
// (steadiface::Calibrator), and writes a parameter overlay that
// stabilize.launch (params:=) and steadiface_bag (--params) load as is.
//   steadiface_calibrate --in BAG [--image T] [--info T] [--imu T]
//       --out overlay.yaml [--report r.json] [--plot DIR] [--params P.yaml]...
// Refuses (exit 1, no overlay written) when the recording cannot determine
// the result, saying why.
#include <iostream>
#include <string>

#include "steadiface_calibrate/calibrate_run.h"
#include "steadiface_core/common/command_line.h"

namespace {

const char kUsage[] =
    "usage: steadiface_calibrate --in BAG --out overlay.yaml [--report "
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
    "Without IMU messages (a camera without an IMU): camera/readout_time alone,\n"
    "from the video; wave the camera gently by hand (1-4 Hz) for a few seconds.\n"
    "Exit 0 with the overlay written; 1 when the recording cannot "
    "determine the\n"
    "result (the reason is printed; nothing is written); 2 on usage "
    "errors.\n";

}  // namespace

int main(int argc, char** argv) {
  steadiface_calibrate::CalibrateOptions o;
  steadiface::CommandLine cl;
  cl.String("--in", &o.in).String("--out", &o.out).String("--report", &o.report);
  cl.String("--plot", &o.plot).String("--image", &o.topics.image).String("--info", &o.topics.info);
  cl.String("--imu", &o.topics.imu).Strings("--params", &o.params);
  cl.Flag("--quiet", &o.quiet).ClearFlag("--no-readout", &o.estimate_readout);
  int status = 0;
  if (!cl.Start(argc, argv, "steadiface_calibrate", kUsage,
                [&o] { return !o.in.empty() && !o.out.empty(); }, std::cout, std::cerr, &status)) {
    return status;
  }
  return steadiface_calibrate::RunCalibration(o);
}
