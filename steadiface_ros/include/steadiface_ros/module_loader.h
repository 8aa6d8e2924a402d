#pragma once

#include <string>
#include <vector>

namespace steadiface_ros {

/// dlopen()s (RTLD_NOW | RTLD_LOCAL) the first of `candidates` (paths, or
/// bare names for the library path) that loads; the module then stays for
/// the rest of the process. nullptr when none loads, with every
/// candidate's dlerror() in `errors`. For the modules that keep heavy
/// libraries out of every start (the image decoder, the bag tool's video
/// encoder).
void* OpenModule(const std::vector<std::string>& candidates,
                 std::string* errors);

}  // namespace steadiface_ros
