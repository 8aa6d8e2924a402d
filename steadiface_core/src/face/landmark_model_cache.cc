// The decoded-model cache of LandmarkPredictor: reading (straight into the
// packed trees, or into dlib's structures) and writing.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <sstream>
#include <string>

#include "steadiface_core/face/landmark_predictor_impl.h"
#include "steadiface_core/model_cache.h"

namespace steadiface {

bool StatLandmarkModel(const std::string& path, LandmarkModelKey* key) {
  struct stat st;
  if (stat(path.c_str(), &st) != 0) return false;
  char* real = realpath(path.c_str(), nullptr);
  key->canonical = real != nullptr ? real : path;
  std::free(real);
  key->size = static_cast<uint64_t>(st.st_size);
  key->mtime_ns =
      static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
  return true;
}

std::string LandmarkCacheFile(const std::string& dir,
                              const LandmarkModelKey& key) {
  std::ostringstream name;
  name << dir << "/landmarks_" << std::hex
       << std::hash<std::string>()(key.canonical) << ".sfcache";
  return name.str();
}

namespace {

// The decoded-model cache: plain native-endian arrays behind a header that
// names the source (canonical path, size, modification time).
constexpr char kCacheMagic[8] = {'S', 'F', 'L', 'M', 'C', 'A', 'C', '1'};

class CacheWriter {
 public:
  explicit CacheWriter(std::ostream* out) : out_(out) {}
  template <class T>
  void Pod(const T& v) {
    out_->write(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void Floats(const float* p, uint64_t n) {
    Pod(n);
    out_->write(reinterpret_cast<const char*>(p),
                static_cast<std::streamsize>(n * sizeof(float)));
  }

 private:
  std::ostream* out_;
};

class CacheReader {
 public:
  CacheReader(const char* p, size_t n) : p_(p), end_(p + n) {}
  template <class T>
  bool Pod(T* v) {
    if (static_cast<size_t>(end_ - p_) < sizeof(T)) return false;
    std::memcpy(v, p_, sizeof(T));
    p_ += sizeof(T);
    return true;
  }
  // A count of elements of `element_bytes` each that must fit in the rest.
  bool Count(uint64_t* n, size_t element_bytes) {
    return Pod(n) && *n <= static_cast<uint64_t>(end_ - p_) /
                               std::max<size_t>(1, element_bytes);
  }
  bool Floats(float* dst, uint64_t n) {
    if (static_cast<uint64_t>(end_ - p_) < n * sizeof(float)) return false;
    std::memcpy(dst, p_, n * sizeof(float));
    p_ += n * sizeof(float);
    return true;
  }
  bool Bytes(std::string* s, uint64_t n) {
    if (static_cast<uint64_t>(end_ - p_) < n) return false;
    s->assign(p_, n);
    p_ += n;
    return true;
  }
  bool AtEnd() const { return p_ == end_; }

 private:
  const char* p_;
  const char* end_;
};

// The header: magic and the model file the cache was decoded from.
bool ReadCacheHeader(CacheReader* r, const LandmarkModelKey& key) {
  char magic[8];
  uint64_t size = 0, len = 0;
  int64_t mtime = 0;
  std::string canonical;
  for (char& c : magic) {
    if (!r->Pod(&c)) return false;
  }
  return std::memcmp(magic, kCacheMagic, sizeof(magic)) == 0 && r->Pod(&size) &&
         r->Pod(&mtime) && r->Count(&len, 1) && r->Bytes(&canonical, len) &&
         size == key.size && mtime == key.mtime_ns &&
         canonical == key.canonical;
}

// The initial (mean) shape, then the number of cascades.
bool ReadShapeAndCascades(CacheReader* r, dlib::matrix<float, 0, 1>* shape,
                          uint64_t* n_cascades) {
  uint64_t n = 0;
  if (!r->Count(&n, sizeof(float)) || n == 0) return false;
  shape->set_size(static_cast<long>(n));
  return r->Floats(&(*shape)(0), n) && r->Count(n_cascades, 8);
}

// One cascade's feature anchors and deltas (after its trees).
bool ReadAnchorsAndDeltas(CacheReader* r, std::vector<unsigned long>* anchors,
                          std::vector<dlib::vector<float, 2>>* deltas) {
  uint64_t n_anchor = 0, n_deltas = 0;
  if (!r->Count(&n_anchor, 8)) return false;
  anchors->resize(n_anchor);
  for (auto& a : *anchors) {
    uint64_t v = 0;
    if (!r->Pod(&v)) return false;
    a = v;
  }
  if (!r->Count(&n_deltas, 8)) return false;
  deltas->resize(n_deltas);
  for (auto& d : *deltas) {
    float x = 0, y = 0;
    if (!r->Pod(&x) || !r->Pod(&y)) return false;
    d = dlib::vector<float, 2>(x, y);
  }
  return true;
}

// The closing magic, and nothing after it.
bool ReadCacheTrailer(CacheReader* r) {
  char magic[8];
  for (char& c : magic) {
    if (!r->Pod(&c)) return false;
  }
  return std::memcmp(magic, kCacheMagic, sizeof(magic)) == 0 && r->AtEnd();
}

// The cache file mapped read-only (no copy into a buffer); unmapped when it
// goes out of scope.
class MappedFile {
 public:
  explicit MappedFile(const std::string& path) {
    const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;
    struct stat st;
    if (fstat(fd, &st) == 0 && st.st_size > 0) {
      void* p = mmap(nullptr, static_cast<size_t>(st.st_size), PROT_READ,
                     MAP_PRIVATE | MAP_POPULATE, fd, 0);
      if (p != MAP_FAILED) {
        data_ = static_cast<const char*>(p);
        size_ = static_cast<size_t>(st.st_size);
      }
    }
    close(fd);
  }
  ~MappedFile() {
    if (data_ != nullptr) munmap(const_cast<char*>(data_), size_);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  const char* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  const char* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace

// The cache read straight into the packed layout (Impl::Pack's): splits
// into their records and each leaf copied once into the leaf block, from
// the mapped file. No dlib tree objects, so none of their ~80 000 small
// allocations, copies and frees (this was ~0.9 s of every process start).
// False, with this Impl to be discarded, when the file is not this model's, is
// damaged (every count is checked against the bytes left, as in the dlib
// path), or holds trees that are not all alike (the caller then takes the
// dlib-structure path, which walks such trees as they are).
bool LandmarkPredictor::Impl::ReadPackedCache(const std::string& file,
                                              const LandmarkModelKey& key) {
  Impl* m = this;
  const MappedFile mapped(file);
  if (mapped.data() == nullptr) return false;
  CacheReader r(mapped.data(), mapped.size());
  uint64_t n_cascades = 0;
  if (!ReadCacheHeader(&r, key) ||
      !ReadShapeAndCascades(&r, &m->initial_shape, &n_cascades) ||
      n_cascades == 0) {
    return false;
  }
  const uint64_t n = static_cast<uint64_t>(m->initial_shape.size());
  float* dst = nullptr;
  for (uint64_t c = 0; c < n_cascades; ++c) {
    uint64_t n_trees = 0;
    if (!r.Count(&n_trees, 16) || n_trees == 0) return false;
    if (c == 0) {
      m->trees = n_trees;
    } else if (n_trees != m->trees) {
      return false;
    }
    for (uint64_t t = 0; t < n_trees; ++t) {
      uint64_t n_splits = 0, n_leaves = 0;
      if (!r.Count(&n_splits, 20)) return false;
      const bool first = c == 0 && t == 0;
      if (first) {
        m->splits_per_tree = n_splits;
      } else if (n_splits != m->splits_per_tree) {
        return false;
      }
      for (uint64_t i = 0; i < n_splits; ++i) {
        uint64_t a = 0, b = 0;
        float thresh = 0.0f;
        if (!r.Pod(&a) || !r.Pod(&b) || !r.Pod(&thresh) || a > UINT32_MAX ||
            b > UINT32_MAX) {
          return false;
        }
        m->splits.push_back(
            Split{static_cast<uint32_t>(a), static_cast<uint32_t>(b), thresh});
      }
      if (!r.Count(&n_leaves, 8)) return false;
      if (first) {
        if (n_leaves != n_splits + 1) return false;
        m->leaves_per_tree = n_leaves;
        // Every leaf must be in the file: checked before allocating.
        const uint64_t floats = n_cascades * n_trees * n_leaves * n;
        if (floats / n / n_leaves / n_trees != n_cascades ||
            floats > mapped.size() / sizeof(float)) {
          return false;
        }
        if (!m->AllocateLeaves(static_cast<size_t>(floats))) return false;
        dst = m->leaves;
        // Sized only now: the leaf block's check above bounds every count
        // (a damaged cache cannot ask for more than its own size).
        m->splits.reserve(n_cascades * n_trees * n_splits);
        m->forests.resize(n_cascades);  // their count only: trees are packed
        m->anchor_idx.resize(n_cascades);
        m->deltas.resize(n_cascades);
      } else if (n_leaves != m->leaves_per_tree) {
        return false;
      }
      for (uint64_t l = 0; l < n_leaves; ++l) {
        uint64_t k = 0;
        if (!r.Count(&k, sizeof(float)) || k != n || !r.Floats(dst, n)) {
          return false;
        }
        dst += n;
      }
    }
    if (!ReadAnchorsAndDeltas(&r, &m->anchor_idx[c], &m->deltas[c])) {
      return false;
    }
  }
  return ReadCacheTrailer(&r);
}

// The cache read into dlib's structures (for a model whose trees are not
// all alike; Pack() then declines and Predict walks dlib's trees).
bool LandmarkPredictor::Impl::ReadCache(const std::string& file,
                                        const LandmarkModelKey& key) {
  Impl* m = this;
  std::string buf;
  if (!ReadWholeFile(file, &buf)) return false;
  CacheReader r(buf.data(), buf.size());
  uint64_t n_cascades = 0;
  if (!ReadCacheHeader(&r, key) ||
      !ReadShapeAndCascades(&r, &m->initial_shape, &n_cascades)) {
    return false;
  }
  m->forests.resize(n_cascades);
  m->anchor_idx.resize(n_cascades);
  m->deltas.resize(n_cascades);
  for (uint64_t c = 0; c < n_cascades; ++c) {
    uint64_t n_trees = 0;
    if (!r.Count(&n_trees, 16)) return false;
    m->forests[c].resize(n_trees);
    for (auto& tree : m->forests[c]) {
      uint64_t n_splits = 0, n_leaves = 0;
      if (!r.Count(&n_splits, 20)) return false;
      tree.splits.resize(n_splits);
      for (auto& s : tree.splits) {
        uint64_t a = 0, b = 0;
        if (!r.Pod(&a) || !r.Pod(&b) || !r.Pod(&s.thresh)) return false;
        s.idx1 = a;
        s.idx2 = b;
      }
      if (!r.Count(&n_leaves, 8)) return false;
      tree.leaf_values.resize(n_leaves);
      for (auto& leaf : tree.leaf_values) {
        uint64_t k = 0;
        if (!r.Count(&k, sizeof(float))) return false;
        leaf.set_size(static_cast<long>(k));
        if (k > 0 && !r.Floats(&leaf(0), k)) return false;
      }
    }
    if (!ReadAnchorsAndDeltas(&r, &m->anchor_idx[c], &m->deltas[c])) {
      return false;
    }
  }
  return ReadCacheTrailer(&r);
}

// Writes the cache next to nothing else: a temporary file renamed into
// place, so a reader never sees half a file. Failure is silent.
void LandmarkPredictor::Impl::WriteCache(const std::string& dir,
                                         const std::string& file,
                                         const LandmarkModelKey& key) const {
  const Impl& m = *this;
  if (!MakeCacheDirs(dir)) return;
  {
    std::ostringstream out;
    CacheWriter w(&out);
    for (char c : kCacheMagic) w.Pod(c);
    w.Pod(key.size);
    w.Pod(key.mtime_ns);
    w.Pod(static_cast<uint64_t>(key.canonical.size()));
    out.write(key.canonical.data(),
              static_cast<std::streamsize>(key.canonical.size()));
    w.Floats(&m.initial_shape(0),
             static_cast<uint64_t>(m.initial_shape.size()));
    w.Pod(static_cast<uint64_t>(m.forests.size()));
    for (size_t c = 0; c < m.forests.size(); ++c) {
      w.Pod(static_cast<uint64_t>(m.forests[c].size()));
      for (const auto& tree : m.forests[c]) {
        w.Pod(static_cast<uint64_t>(tree.splits.size()));
        for (const auto& s : tree.splits) {
          w.Pod(static_cast<uint64_t>(s.idx1));
          w.Pod(static_cast<uint64_t>(s.idx2));
          w.Pod(s.thresh);
        }
        w.Pod(static_cast<uint64_t>(tree.leaf_values.size()));
        for (const auto& leaf : tree.leaf_values) {
          w.Floats(leaf.size() > 0 ? &leaf(0) : nullptr,
                   static_cast<uint64_t>(leaf.size()));
        }
      }
      w.Pod(static_cast<uint64_t>(m.anchor_idx[c].size()));
      for (unsigned long a : m.anchor_idx[c]) w.Pod(static_cast<uint64_t>(a));
      w.Pod(static_cast<uint64_t>(m.deltas[c].size()));
      for (const auto& d : m.deltas[c]) {
        w.Pod(d.x());
        w.Pod(d.y());
      }
    }
    for (char c : kCacheMagic) w.Pod(c);
    WriteFileAtomically(file, out.str());
  }
}

}  // namespace steadiface
