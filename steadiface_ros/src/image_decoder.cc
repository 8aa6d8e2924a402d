#include "image_decoder.h"

#include <dlfcn.h>

#include <climits>
#include <vector>

#include "steadiface_ros/module_loader.h"

namespace steadiface_ros {
namespace {

constexpr char kModule[] = "libsteadiface_image_decoder.so";
constexpr char kEntry[] = "steadiface_ros_decode_image";
using DecodeFn = int (*)(const uint8_t*, size_t, cv::Mat*);

struct Module {
  DecodeFn decode = nullptr;
  std::string error;  // why it could not be loaded
};

// The directory of the library this code is in (libsteadiface_ros.so, in
// <prefix>/lib of the devel or the install space), or "" if unknown.
std::string OwnDirectory() {
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&OwnDirectory), &info) == 0 ||
      info.dli_fname == nullptr) {
    return "";
  }
  const std::string file = info.dli_fname;
  const size_t slash = file.rfind('/');
  return slash == std::string::npos ? "" : file.substr(0, slash);
}

// Loaded once, on first use, and kept for the rest of the process.
const Module& LoadedModule() {
  static const Module module = [] {
    Module m;
    std::vector<std::string> candidates;
    const std::string dir = OwnDirectory();
    if (!dir.empty()) candidates.push_back(dir + "/" + kModule);
    candidates.push_back(kModule);  // the library path
    std::string errors;
    void* handle = OpenModule(candidates, &errors);
    if (handle == nullptr) {
      m.error = "cannot load the image decoder module (" + errors + ")";
      return m;
    }
    m.decode = reinterpret_cast<DecodeFn>(dlsym(handle, kEntry));
    if (m.decode == nullptr) {
      m.error = std::string("the image decoder module has no ") + kEntry;
    }
    return m;
  }();
  return module;
}

}  // namespace

bool LoadImageDecoder(std::string* why) {
  const Module& m = LoadedModule();
  if (m.decode == nullptr) *why = m.error;
  return m.decode != nullptr;
}

bool DecodeImage(const uint8_t* data, size_t size, cv::Mat* out,
                 std::string* why) {
  const Module& m = LoadedModule();
  if (m.decode == nullptr) {
    *why = m.error;
    return false;
  }
  if (size == 0 || size > static_cast<size_t>(INT_MAX)) {
    *why = "payload of " + std::to_string(size) + " bytes";
    return false;
  }
  if (m.decode(data, size, out) == 0) {
    *why = "the payload does not decode";
    return false;
  }
  return true;
}

}  // namespace steadiface_ros
