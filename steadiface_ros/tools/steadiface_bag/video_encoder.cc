#include "steadiface_bag/video_encoder.h"

#include <dlfcn.h>

#include "steadiface_bag/tool_module.h"

namespace steadiface_bag {

namespace {

constexpr char kModule[] = "libsteadiface_video_encoder.so";

}  // namespace

std::unique_ptr<VideoEncoder> OpenVideoEncoder(const std::string& path,
                                               double fps, cv::Size size,
                                               std::string* why) {
  // The module stays loaded for the rest of the process (its encoder's code).
  std::string errors;
  void* handle = OpenToolModule(kModule, &errors);
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
