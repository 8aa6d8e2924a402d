#include "steadiface_bag/video_encoder.h"

#include <dlfcn.h>
#include <limits.h>
#include <unistd.h>

#include <vector>

#include "steadiface_ros/module_loader.h"

namespace steadiface_bag {

namespace {

constexpr char kModule[] = "libsteadiface_video_encoder.so";

// The tool's own directory (from /proc/self/exe), or "" if unknown.
std::string ExeDir() {
  char buf[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  if (n <= 0) return "";
  const std::string exe(buf, static_cast<size_t>(n));
  const size_t slash = exe.rfind('/');
  return slash == std::string::npos ? "" : exe.substr(0, slash);
}

}  // namespace

std::unique_ptr<VideoEncoder> OpenVideoEncoder(const std::string& path,
                                               double fps, cv::Size size,
                                               std::string* why) {
  // The tools are in <prefix>/lib/steadiface/ and the libraries in
  // <prefix>/lib/, in the devel and the install space alike. The module
  // stays loaded for the rest of the process (its encoder's code).
  std::vector<std::string> candidates;
  const std::string dir = ExeDir();
  if (!dir.empty()) candidates.push_back(dir + "/../" + kModule);
  candidates.push_back(kModule);
  std::string errors;
  void* handle = steadiface_ros::OpenModule(candidates, &errors);
  if (handle == nullptr) {
    *why = "cannot load the video encoder module (" + errors + ")";
    return nullptr;
  }
  using Open = VideoEncoder* (*)(const char*, double, int, int);
  auto open = reinterpret_cast<Open>(
      dlsym(handle, "steadiface_bag_open_video_encoder"));
  if (open == nullptr) {
    *why = std::string("the video encoder module has no entry point (") +
           kModule + ")";
    return nullptr;
  }
  std::unique_ptr<VideoEncoder> encoder(
      open(path.c_str(), fps, size.width, size.height));
  if (!encoder) *why = "cannot write video '" + path + "'";
  return encoder;
}

}  // namespace steadiface_bag
