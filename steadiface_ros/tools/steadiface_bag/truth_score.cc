#include "steadiface_bag/truth_score.h"

#include <dlfcn.h>

#include "steadiface_bag/tool_module.h"

namespace steadiface_bag {
namespace {

constexpr char kModule[] = "libsteadiface_truth_scorer.so";

}  // namespace

steadiface::Status TruthScorer::Create(const std::string& truth_path,
                                       const steadiface::PipelineOptions& options,
                                       std::unique_ptr<TruthScorer>* out) {
  // The module stays loaded for the rest of the process (its scorer's code).
  std::string errors;
  void* handle = OpenToolModule(kModule, &errors);
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
