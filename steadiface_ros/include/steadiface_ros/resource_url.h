#pragma once

#include <string>

#include "steadiface_core/common/status.h"

namespace steadiface_ros {

/// A resource URL as ROS parameters give it -> a file path:
/// "file:///abs/path", "package://pkg/rel" (ros::package, so the package must
/// be on ROS_PACKAGE_PATH), or a plain path, returned as it is. Anything else
/// is an error that starts with `what` and the URL, e.g.
/// "camera_info_url 'http://x': unsupported scheme ...".
steadiface::Status ResolveResourceUrl(const std::string& what,
                                      const std::string& url,
                                      std::string* path);

}  // namespace steadiface_ros
