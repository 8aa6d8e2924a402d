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
// The run itself is RunBag (bag_run.h): three stages on three threads.
#include <malloc.h>

#include <iostream>
#include <string>

#include "steadiface_bag/bag_run.h"
#include "steadiface_core/common/command_line.h"

namespace {

const char kUsage[] =
    "usage: steadiface_bag --in IN.bag [--out OUT.bag] [--params "
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

void AddFlags(steadiface::CommandLine* cl, steadiface_bag::BagRunOptions* a) {
  cl->String("--in", &a->in).String("--out", &a->out).Strings("--params", &a->params);
  cl->String("--image", &a->topics.image).String("--info", &a->topics.info);
  cl->String("--imu", &a->topics.imu).String("--landmarks", &a->topics.landmarks);
  cl->String("--compress", &a->compress).Flag("--debug-images-in-bag", &a->debug_images_in_bag);
  cl->String("--video", &a->video).Flag("--debug-overlay", &a->debug_overlay);
  cl->String("--report", &a->report).String("--trajectory", &a->trajectory);
  cl->Flag("--gyro-only", &a->gyro_only).Flag("--no-pipeline", &a->no_pipeline);
  cl->Flag("--rosbag-reader", &a->rosbag_reader).Flag("--verify-checksums", &a->verify_checksums);
  cl->Flag("--quiet", &a->quiet).String("--truth", &a->truth);
  cl->Double("--start-stamp", &a->start_stamp).String("--only-stamps", &a->only_stamps);
  cl->String("--plots", &a->plot_dir).String("--name", &a->plot_name);
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
  steadiface_bag::BagRunOptions a;
  steadiface::CommandLine cl;
  AddFlags(&cl, &a);
  int status = 0;
  if (!cl.Start(argc, argv, "steadiface_bag", kUsage, [&a] { return !a.in.empty(); }, std::cout,
                std::cerr, &status)) {
    return status;
  }
  return steadiface_bag::RunBag(a);
}
