#include "steadiface_core/common/model_cache.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>

namespace steadiface {

std::string DefaultModelCacheDir() {
  if (const char* d = std::getenv("STEADIFACE_CACHE_DIR")) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME")) {
    if (x[0] != '\0') return std::string(x) + "/steadiface";
  }
  if (const char* h = std::getenv("HOME")) {
    if (h[0] != '\0') return std::string(h) + "/.cache/steadiface";
  }
  return "";
}

bool MakeCacheDirs(const std::string& dir) {
  if (dir.empty()) return false;
  for (size_t i = 1; i <= dir.size(); ++i) {
    if (i == dir.size() || dir[i] == '/') {
      const std::string part = dir.substr(0, i);
      if (mkdir(part.c_str(), 0755) != 0 && errno != EEXIST) return false;
    }
  }
  return true;
}

bool WriteFileAtomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp" + std::to_string(getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out.good()) return false;
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out.good()) {
      out.close();
      std::remove(tmp.c_str());
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

bool ReadWholeFile(const std::string& path, std::string* bytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in.good()) return false;
  const std::streamoff n = in.tellg();
  if (n < 0) return false;
  bytes->resize(static_cast<size_t>(n));
  in.seekg(0);
  return static_cast<bool>(in.read(&(*bytes)[0], n));
}

uint64_t Fnv1a64(const std::string& bytes) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace steadiface
