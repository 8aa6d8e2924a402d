#pragma once

#include <cstdint>
#include <string>

namespace steadiface {

/// Where decoded models are kept between runs (the dlib landmark model and
/// face detector decode slowly from their shipped forms):
/// $STEADIFACE_CACHE_DIR, else $XDG_CACHE_HOME/steadiface, else
/// $HOME/.cache/steadiface, else "" (no cache).
std::string DefaultModelCacheDir();

/// Creates `dir` and its parents (like mkdir -p). False on failure.
bool MakeCacheDirs(const std::string& dir);

/// Writes `bytes` to `path` through a temporary file renamed into place, so
/// a reader never sees half a file. False (and nothing left behind) on
/// failure.
bool WriteFileAtomically(const std::string& path, const std::string& bytes);

/// Reads a whole file. False when it cannot be read.
bool ReadWholeFile(const std::string& path, std::string* bytes);

/// 64-bit FNV-1a of `bytes` (cache integrity, not security).
uint64_t Fnv1a64(const std::string& bytes);

}  // namespace steadiface
