// Where parameters come from: the ROS parameter server (node, nodelet) or
// YAML files (the offline tools), behind ParamSource.
#include "steadiface_ros/params.h"

#include <sstream>

#include <yaml-cpp/yaml.h>

namespace steadiface_ros {
namespace {

using steadiface::Status;

class RosParamSource : public ParamSource {
 public:
  explicit RosParamSource(const ros::NodeHandle& nh) : nh_(nh) {}
  bool Get(const std::string& k, double* v) const override { return nh_.getParam(k, *v); }
  bool Get(const std::string& k, int* v) const override { return nh_.getParam(k, *v); }
  bool Get(const std::string& k, bool* v) const override { return nh_.getParam(k, *v); }
  bool Get(const std::string& k, std::string* v) const override { return nh_.getParam(k, *v); }
  bool Get(const std::string& k, std::vector<double>* v) const override {
    return nh_.getParam(k, *v);
  }

 private:
  ros::NodeHandle nh_;
};

class YamlParamSource : public ParamSource {
 public:
  explicit YamlParamSource(std::vector<YAML::Node> docs) : docs_(std::move(docs)) {}

  template <typename T>
  bool GetT(const std::string& key, T* v) const {
    // Later documents override earlier ones.
    for (auto it = docs_.rbegin(); it != docs_.rend(); ++it) {
      YAML::Node n;
      if (!Lookup(*it, key, &n) || n.IsNull()) continue;
      try {
        *v = n.as<T>();
        return true;
      } catch (const YAML::Exception&) {
        return false;
      }
    }
    return false;
  }
  bool Get(const std::string& k, double* v) const override { return GetT(k, v); }
  bool Get(const std::string& k, int* v) const override { return GetT(k, v); }
  bool Get(const std::string& k, bool* v) const override { return GetT(k, v); }
  bool Get(const std::string& k, std::string* v) const override { return GetT(k, v); }
  bool Get(const std::string& k, std::vector<double>* v) const override { return GetT(k, v); }

 private:
  // Walks '/'-separated `key` through nested maps without modifying them.
  static bool Lookup(const YAML::Node& root, const std::string& key, YAML::Node* out) {
    const YAML::Node* cur = &root;
    YAML::Node holder;
    std::stringstream ss(key);
    std::string part;
    while (std::getline(ss, part, '/')) {
      if (!cur->IsMap()) return false;
      const YAML::Node& c = *cur;
      const YAML::Node child = c[part];  // const operator[]: no insertion
      if (!child.IsDefined()) return false;
      holder.reset(child);
      cur = &holder;
    }
    *out = *cur;
    return true;
  }
  std::vector<YAML::Node> docs_;
};

}  // namespace

std::unique_ptr<ParamSource> RosParams(const ros::NodeHandle& nh) {
  return std::unique_ptr<ParamSource>(new RosParamSource(nh));
}

Status YamlParams(const std::vector<std::string>& paths, std::unique_ptr<ParamSource>* out) {
  std::vector<YAML::Node> docs;
  for (const auto& p : paths) {
    try {
      docs.push_back(YAML::LoadFile(p));
    } catch (const YAML::Exception& e) {
      return Status::Error("cannot read parameters '" + p + "': " + e.what());
    }
  }
  out->reset(new YamlParamSource(std::move(docs)));
  return Status::Ok();
}

}  // namespace steadiface_ros
