#include "steadiface_bag/truth_score.h"

#include <dlfcn.h>
#include <limits.h>
#include <unistd.h>

#include <vector>

#include "steadiface_ros/module_loader.h"

namespace steadiface_bag {
namespace {

constexpr char kModule[] = "libsteadiface_truth_scorer.so";

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

steadiface::Status TruthScorer::Create(const std::string& truth_path,
                                       const steadiface::PipelineOptions& options,
                                       std::unique_ptr<TruthScorer>* out) {
  // The tools are in <prefix>/lib/steadiface/ and the libraries in
  // <prefix>/lib/, in the devel and the install space alike. The module
  // stays loaded for the rest of the process (its scorer's code).
  std::vector<std::string> candidates;
  const std::string dir = ExeDir();
  if (!dir.empty()) candidates.push_back(dir + "/../" + kModule);
  candidates.push_back(kModule);
  std::string errors;
  void* handle = steadiface_ros::OpenModule(candidates, &errors);
  if (handle == nullptr) {
    return steadiface::Status::Error("cannot load the truth scorer module (" + errors + ")");
  }
  using Create = TruthScorer* (*)(const std::string&, const steadiface::PipelineOptions&,
                                  std::string*);
  auto create = reinterpret_cast<Create>(dlsym(handle, "steadiface_bag_create_truth_scorer"));
  if (create == nullptr) {
    return steadiface::Status::Error(std::string("the truth scorer module has no entry point (") +
                                     kModule + ")");
  }
  std::string error;
  out->reset(create(truth_path, options, &error));
  if (*out == nullptr) return steadiface::Status::Error(error);
  return steadiface::Status::Ok();
}

}  // namespace steadiface_bag
