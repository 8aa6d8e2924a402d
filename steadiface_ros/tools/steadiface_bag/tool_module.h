#pragma once

#include <string>

namespace steadiface_bag {

/// dlopen()s a module the bag tools load on demand, `name` (a file name such
/// as "libsteadiface_video_encoder.so"): the tools are in <prefix>/lib/steadiface/
/// and the libraries in <prefix>/lib/, in the devel and the install space
/// alike, so it is looked for beside the tool's directory first, then on the
/// library path (steadiface_ros::OpenModule). The module stays loaded for
/// the rest of the process. nullptr when it does not load, with why in
/// `errors`.
void* OpenToolModule(const std::string& name, std::string* errors);

}  // namespace steadiface_bag
