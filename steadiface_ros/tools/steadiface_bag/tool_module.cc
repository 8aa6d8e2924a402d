#include "steadiface_bag/tool_module.h"

#include <limits.h>
#include <unistd.h>

#include <vector>

#include "steadiface_ros/module_loader.h"

namespace steadiface_bag {
namespace {

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

void* OpenToolModule(const std::string& name, std::string* errors) {
  std::vector<std::string> candidates;
  const std::string dir = ExeDir();
  if (!dir.empty()) candidates.push_back(dir + "/../" + name);
  candidates.push_back(name);
  return steadiface_ros::OpenModule(candidates, errors);
}

}  // namespace steadiface_bag
