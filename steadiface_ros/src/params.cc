// LoadOptions: every key read, checked against the parameter table
// (config/parameters.yaml), into the option field its row names
// (parameter_fields.inc, generated), and the dynamic_reconfigure mapping.
#include "steadiface_ros/params.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

#include <ros/package.h>

#include "steadiface_ros/resource_url.h"

namespace steadiface_ros {
namespace {

using steadiface::Status;

// The table of every key (config/parameters.yaml, generated).
const std::vector<ParameterSpec>& Table() {
  static const std::vector<ParameterSpec> table = {
#include "parameter_table.inc"
  };
  return table;
}

const ParameterSpec* Find(const std::string& key) {
  static const std::map<std::string, const ParameterSpec*> by_key = [] {
    std::map<std::string, const ParameterSpec*> m;
    for (const ParameterSpec& p : Table()) m[p.key] = &p;
    return m;
  }();
  const auto it = by_key.find(key);
  return it == by_key.end() ? nullptr : it->second;
}

// An enum's values by their names in the table (its enum: row).
template <typename E>
using EnumNames = std::vector<std::pair<const char*, E>>;

template <typename E>
std::string NameOf(E v, const EnumNames<E>& names) {
  for (const auto& n : names) {
    if (n.second == v) return n.first;
  }
  return "";
}

// Sets *v to the value named `name`; leaves it for a name not in the list.
template <typename E>
void FromName(const std::string& name, const EnumNames<E>& names, E* v) {
  for (const auto& n : names) {
    if (name == n.first) *v = n.second;
  }
}

// Reads `key` if present, checked against its row of the table (range or
// choices). Records the first error.
class Reader {
 public:
  explicit Reader(const ParamSource& p) : p_(p) {}
  void Num(const std::string& key, double* v) {
    const ParameterSpec* spec = Spec(key, ParameterType::kDouble);
    double x = *v;
    if (!p_.Get(key, &x)) {
      int i;
      if (p_.Get(key, &i)) x = i;
    }
    if (spec == nullptr) return;
    if (!std::isfinite(x) || x < spec->min || x > spec->max) {
      Fail(key, x, spec->min, spec->max);
      return;
    }
    *v = x;
  }
  void Int(const std::string& key, int* v) {
    const ParameterSpec* spec = Spec(key, ParameterType::kInt);
    int x = *v;
    p_.Get(key, &x);
    if (spec == nullptr) return;
    if (x < spec->min || x > spec->max) {
      Fail(key, x, spec->min, spec->max);
      return;
    }
    *v = x;
  }
  void Bool(const std::string& key, bool* v) {
    Spec(key, ParameterType::kBool);
    p_.Get(key, v);
  }
  void Str(const std::string& key, std::string* v) {
    Spec(key, ParameterType::kString);
    p_.Get(key, v);
  }
  // One of the key's choices (the table's); *v keeps its value otherwise.
  void Choice(const std::string& key, std::string* v) {
    const ParameterSpec* spec = Spec(key, ParameterType::kString);
    std::string x = *v;
    p_.Get(key, &x);
    if (spec == nullptr) return;
    std::stringstream choices(spec->choices);
    std::string c, all;
    while (std::getline(choices, c, '|')) {
      if (c == x) {
        *v = x;
        return;
      }
      all += (all.empty() ? "" : " | ") + c;
    }
    Error("parameter '" + key + "' must be one of " + all + ", got '" + x + "'");
  }
  // A key whose choices name an enum's values (`names`, the table's
  // enum: row); *v keeps its value when the choice is refused.
  template <typename E>
  void Enum(const std::string& key, E* v, const EnumNames<E>& names) {
    std::string s = NameOf(*v, names);
    Choice(key, &s);
    FromName(s, names, v);
  }
  // A file parameter: a plain path, file:// or package:// (ResolveResourceUrl).
  void Path(const std::string& key, std::string* v) {
    Spec(key, ParameterType::kString);
    std::string url = *v;
    p_.Get(key, &url);
    if (url.empty()) {
      *v = url;
      return;
    }
    const Status s = ResolveResourceUrl("parameter '" + key + "'", url, v);
    if (!s.ok()) Error(s.message());
  }
  void Vec(const std::string& key, std::vector<double>* v) {
    Spec(key, ParameterType::kList);
    p_.Get(key, v);
  }
  void Error(const std::string& msg) {
    if (error_.empty()) error_ = msg;
  }
  Status status() const { return error_.empty() ? Status::Ok() : Status::Error(error_); }

 private:
  // The key's row; a key the table lacks, or of another type, is an error
  // (a programming one: params_test reads every key).
  const ParameterSpec* Spec(const std::string& key, ParameterType type) {
    const ParameterSpec* spec = Find(key);
    if (spec == nullptr || spec->type != type) {
      Error("parameter '" + key + "' is not in config/parameters.yaml as this type");
      return nullptr;
    }
    return spec;
  }
  void Fail(const std::string& key, double x, double lo, double hi) {
    std::ostringstream e;
    e << "parameter '" << key << "' = " << x << " is out of range [" << lo << ", " << hi
      << "]";
    Error(e.str());
  }
  const ParamSource& p_;
  std::string error_;
};

}  // namespace

#include "parameter_fields.inc"

namespace {

// The keys whose rows say field: custom: checked beyond their type.
void ReadImuCalibration(Reader& r, steadiface::OrientationTimelineOptions* imu) {
  const Eigen::Quaterniond& q0 = imu->R_cam_imu;
  std::vector<double> q = {q0.x(), q0.y(), q0.z(), q0.w()};
  r.Vec("imu/R_cam_imu", &q);
  if (q.size() != 4) {
    r.Error("parameter 'imu/R_cam_imu' must be a quaternion [x, y, z, w]");
  } else {
    const Eigen::Quaterniond e(q[3], q[0], q[1], q[2]);
    if (!(e.norm() > 0.5 && e.norm() < 2.0)) {
      r.Error("parameter 'imu/R_cam_imu' must be a unit quaternion [x, y, z, w]");
    } else {
      imu->R_cam_imu = e.normalized();
    }
  }
  const Eigen::Vector3d& b0 = imu->gyro_bias;
  std::vector<double> b = {b0.x(), b0.y(), b0.z()};
  r.Vec("imu/gyro_bias", &b);
  if (b.size() != 3 || !std::isfinite(b[0]) || !std::isfinite(b[1]) || !std::isfinite(b[2]) ||
      Eigen::Vector3d(b[0], b[1], b[2]).norm() >= 1.0) {
    r.Error("parameter 'imu/gyro_bias' must be [bx, by, bz] in rad/s with |bias| < 1");
  } else {
    imu->gyro_bias = Eigen::Vector3d(b[0], b[1], b[2]);
  }
}

void ReadCascadePath(Reader& r, steadiface::FaceDetectorOptions* d) {
  // Resolved only where it is used: a package:// cascade must not stop a
  // dlib_hog run started outside a sourced workspace.
  if (d->type == steadiface::FaceDetectorType::kOpenCvCascade) {
    r.Path("face/cascade_path", &d->cascade_path);
  } else {
    r.Str("face/cascade_path", &d->cascade_path);
  }
}

}  // namespace

const std::vector<ParameterSpec>& ParameterTable() { return Table(); }

Status LoadOptions(const ParamSource& params, steadiface::PipelineOptions* po,
                   WrapperOptions* wo) {
  Reader r(params);
  ReadTable(r, po, wo);
  ReadImuCalibration(r, &po->imu);
  ReadCascadePath(r, &po->face.detector);
  const Status st = r.status();
  if (!st.ok()) return st;
  // Cross-field checks of the core (e.g. low < high) with its own messages.
  return steadiface::ValidatePipelineOptions(*po);
}

Status LoadPackageOptions(const std::vector<std::string>& overlays,
                          steadiface::PipelineOptions* po, WrapperOptions* wo) {
  std::vector<std::string> files;
  const std::string pkg = ros::package::getPath("steadiface");
  if (!pkg.empty()) files.push_back(pkg + "/config/default.yaml");
  files.insert(files.end(), overlays.begin(), overlays.end());
  std::unique_ptr<ParamSource> params;
  Status st = YamlParams(files, &params);
  if (st.ok()) st = LoadOptions(*params, po, wo);
  return st;
}

}  // namespace steadiface_ros
