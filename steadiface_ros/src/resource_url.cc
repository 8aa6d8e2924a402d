#include "steadiface_ros/resource_url.h"

#include <ros/package.h>

namespace steadiface_ros {

using steadiface::Status;

Status ResolveResourceUrl(const std::string& what, const std::string& url,
                          std::string* path) {
  const std::string file = "file://", package = "package://";
  const std::string prefix = what + " '" + url + "': ";
  if (url.compare(0, file.size(), file) == 0) {
    *path = url.substr(file.size());
  } else if (url.compare(0, package.size(), package) == 0) {
    const std::string rest = url.substr(package.size());
    const size_t slash = rest.find('/');
    if (slash == std::string::npos || slash == 0 || slash + 1 == rest.size()) {
      return Status::Error(prefix + "expected package://PACKAGE/PATH");
    }
    const std::string pkg = rest.substr(0, slash);
    const std::string dir = ros::package::getPath(pkg);
    if (dir.empty()) {
      return Status::Error(prefix + "package '" + pkg + "' not found");
    }
    *path = dir + rest.substr(slash);
  } else if (url.find("://") != std::string::npos) {
    return Status::Error(
        prefix + "unsupported scheme (use file://, package:// or a path)");
  } else {
    *path = url;
  }
  if (path->empty()) return Status::Error(prefix + "empty path");
  return Status::Ok();
}

}  // namespace steadiface_ros
