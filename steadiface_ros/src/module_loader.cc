#include "steadiface_ros/module_loader.h"

#include <dlfcn.h>

namespace steadiface_ros {

void* OpenModule(const std::vector<std::string>& candidates,
                 std::string* errors) {
  errors->clear();
  for (const std::string& c : candidates) {
    void* handle = dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle != nullptr) return handle;
    const char* e = dlerror();
    *errors += std::string(errors->empty() ? "" : "; ") + (e ? e : c);
  }
  return nullptr;
}

}  // namespace steadiface_ros
