#include "steadiface_core/face/landmark_predictor.h"

#include <fcntl.h>
#include <malloc.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <sstream>

#include <dlib/image_processing/shape_predictor.h>
#include <dlib/opencv/cv_image.h>
#include <dlib/serialize.h>

#include "steadiface_core/model_cache.h"

namespace steadiface {

// The model's parts, read with dlib's own serialization. We run dlib's
// cascade ourselves (same code as dlib::shape_predictor::operator()) so the
// landmarks come out with sub-pixel precision; dlib's full_object_detection
// rounds every part to whole pixels.
struct LandmarkPredictor::Impl {
  dlib::matrix<float, 0, 1> initial_shape;
  std::vector<std::vector<dlib::impl::regression_tree>> forests;
  std::vector<std::vector<unsigned long>> anchor_idx;
  std::vector<std::vector<dlib::vector<float, 2>>> deltas;
  unsigned long num_parts() const { return initial_shape.size() / 2; }

  // The same trees packed (Pack()): a fit walks 5000 trees and reads one
  // leaf of each, and dlib keeps every leaf in its own heap block and
  // every split node in 24 bytes. Packed, the leaves are one contiguous,
  // cache-line-aligned block in tree order and each tree's splits one
  // 12-byte record per node. Empty when the model's trees are not all
  // alike (then dlib's own structures are walked).
  struct Split {
    uint32_t idx1, idx2;
    float thresh;
  };
  // Cascade c, tree t: its splits from (c * trees + t) * splits_per_tree,
  // its leaf l at ((c * trees + t) * leaves_per_tree + l) * n floats.
  std::vector<Split> splits;
  float* leaves = nullptr;
  size_t trees = 0, splits_per_tree = 0, leaves_per_tree = 0;
  bool packed() const { return leaves != nullptr; }
  void Pack();
  bool ReadPackedCache(const std::string& file, const std::string& canonical,
                       uint64_t source_size, int64_t source_mtime_ns);
  // The leaf block for `floats` floats: aligned and padded to 2 MiB and
  // advised onto transparent huge pages, so filling it takes a few dozen
  // page faults instead of ~17 000 (each costly in a VM). False if it
  // cannot be had.
  bool AllocateLeaves(size_t floats) {
    constexpr size_t kHuge = size_t{2} << 20;
    const size_t bytes = (floats * sizeof(float) + kHuge - 1) / kHuge * kHuge;
    leaves = static_cast<float*>(std::aligned_alloc(kHuge, bytes));
    if (leaves == nullptr) return false;
#ifdef MADV_HUGEPAGE
    madvise(leaves, bytes, MADV_HUGEPAGE);  // advice only: failure is fine
#endif
    return true;
  }
  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() { std::free(leaves); }
};

void LandmarkPredictor::Impl::Pack() {
  const size_t n = initial_shape.size();
  if (forests.empty() || forests[0].empty() || n == 0) return;
  trees = forests[0].size();
  splits_per_tree = forests[0][0].splits.size();
  leaves_per_tree = forests[0][0].leaf_values.size();
  if (leaves_per_tree != splits_per_tree + 1) return;
  for (const auto& forest : forests) {
    if (forest.size() != trees) return;
    for (const auto& tree : forest) {
      if (tree.splits.size() != splits_per_tree ||
          tree.leaf_values.size() != leaves_per_tree) {
        return;
      }
      for (const auto& leaf : tree.leaf_values) {
        if (static_cast<size_t>(leaf.size()) != n) return;
      }
      for (const auto& sp : tree.splits) {
        if (sp.idx1 > UINT32_MAX || sp.idx2 > UINT32_MAX) return;
      }
    }
  }
  if (!AllocateLeaves(forests.size() * trees * leaves_per_tree * n)) return;
  splits.reserve(forests.size() * trees * splits_per_tree);
  float* dst = leaves;
  for (auto& forest : forests) {
    for (auto& tree : forest) {
      for (const auto& sp : tree.splits) {
        splits.push_back(Split{static_cast<uint32_t>(sp.idx1),
                               static_cast<uint32_t>(sp.idx2), sp.thresh});
      }
      for (const auto& leaf : tree.leaf_values) {
        std::memcpy(dst, &leaf(0), n * sizeof(float));
        dst += n;
      }
      // The packed copy is the one used: do not hold the model twice.
      tree.leaf_values.clear();
      tree.leaf_values.shrink_to_fit();
      tree.splits.clear();
      tree.splits.shrink_to_fit();
    }
  }
#ifdef __GLIBC__
  // dlib's 80 000 small leaf blocks are free now, but scattered through the
  // heap: glibc keeps such pages unless asked (~60 MB of RSS in the soak).
  malloc_trim(0);
#endif
}

namespace {

// The decoded-model cache: plain native-endian arrays behind a header that
// names the source (canonical path, size, modification time).
constexpr char kCacheMagic[8] = {'S', 'F', 'L', 'M', 'C', 'A', 'C', '1'};

struct SourceKey {
  std::string canonical;
  uint64_t size = 0;
  int64_t mtime_ns = 0;
};

bool StatSource(const std::string& path, SourceKey* key) {
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

std::string CacheFile(const std::string& dir, const SourceKey& key) {
  std::ostringstream name;
  name << dir << "/landmarks_" << std::hex
       << std::hash<std::string>()(key.canonical) << ".sfcache";
  return name.str();
}

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
bool ReadCacheHeader(CacheReader* r, const SourceKey& key) {
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
                                              const std::string& canonical,
                                              uint64_t source_size,
                                              int64_t source_mtime_ns) {
  Impl* m = this;
  const MappedFile mapped(file);
  if (mapped.data() == nullptr) return false;
  CacheReader r(mapped.data(), mapped.size());
  uint64_t n_cascades = 0;
  if (!ReadCacheHeader(&r,
                       SourceKey{canonical, source_size, source_mtime_ns}) ||
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

LandmarkPredictor::LandmarkPredictor() = default;
LandmarkPredictor::~LandmarkPredictor() = default;

Status LandmarkPredictor::Load(const std::string& path,
                               std::unique_ptr<LandmarkPredictor>* out,
                               const std::string& cache_dir) {
  const std::string hint =
      " (the default model ships in Debian's libdlib-data package: "
      "apt-get install libdlib-data, or run scripts/install_deps)";
  std::ifstream probe(path, std::ios::binary);
  if (!probe.good()) {
    return Status::Error("landmark model '" + path + "' cannot be opened" +
                         hint);
  }
  probe.close();
  static std::mutex cache_mutex;
  static std::map<std::string, std::weak_ptr<const Impl>> cache;
  {
    std::lock_guard<std::mutex> lock(cache_mutex);
    auto it = cache.find(path);
    if (it != cache.end()) {
      if (std::shared_ptr<const Impl> shared = it->second.lock()) {
        std::unique_ptr<LandmarkPredictor> p(new LandmarkPredictor);
        p->impl_ = shared;
        *out = std::move(p);
        return Status::Ok();
      }
    }
  }
  std::unique_ptr<LandmarkPredictor> p(new LandmarkPredictor);
  auto impl = std::make_shared<Impl>();
  SourceKey key;
  const bool cacheable = !cache_dir.empty() && StatSource(path, &key);
  const std::string cache_file =
      cacheable ? CacheFile(cache_dir, key) : std::string();
  // The decoded model from the cache, if it is this model's.
  auto read_cache = [&](Impl* m) {
    std::string buf;
    if (!ReadWholeFile(cache_file, &buf)) return false;
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
  };
  // Writes the cache next to nothing else: a temporary file renamed into
  // place, so a reader never sees half a file. Failure is silent.
  auto write_cache = [&](const Impl& m) {
    if (!MakeCacheDirs(cache_dir)) return;
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
      WriteFileAtomically(cache_file, out.str());
    }
  };
  if (cacheable &&
      impl->ReadPackedCache(cache_file, key.canonical, key.size,
                            key.mtime_ns) &&
      impl->num_parts() == 68 &&
      impl->forests.size() == impl->anchor_idx.size() &&
      impl->forests.size() == impl->deltas.size()) {
    p->impl_ = impl;
    p->from_cache_ = true;
    p->packed_from_cache_ = true;
    {
      std::lock_guard<std::mutex> lock(cache_mutex);
      cache[path] = impl;
    }
    *out = std::move(p);
    return Status::Ok();
  }
  // Not packable straight from the cache (or no cache): dlib's structures.
  impl = std::make_shared<Impl>();
  if (cacheable && read_cache(impl.get()) && impl->num_parts() == 68 &&
      !impl->forests.empty() &&
      impl->forests.size() == impl->anchor_idx.size() &&
      impl->forests.size() == impl->deltas.size()) {
    impl->Pack();
    p->impl_ = impl;
    p->from_cache_ = true;
    {
      std::lock_guard<std::mutex> lock(cache_mutex);
      cache[path] = impl;
    }
    *out = std::move(p);
    return Status::Ok();
  }
  impl = std::make_shared<Impl>();
  try {
    std::ifstream in(path, std::ios::binary);
    int version = 0;
    dlib::deserialize(version, in);
    if (version != 1) {
      throw dlib::serialization_error("unexpected shape_predictor version " +
                                      std::to_string(version));
    }
    Impl& m = *impl;
    dlib::deserialize(m.initial_shape, in);
    dlib::deserialize(m.forests, in);
    dlib::deserialize(m.anchor_idx, in);
    dlib::deserialize(m.deltas, in);
    if (m.forests.empty() || m.forests.size() != m.anchor_idx.size() ||
        m.forests.size() != m.deltas.size()) {
      throw dlib::serialization_error("inconsistent cascade sizes");
    }
  } catch (const std::exception& e) {
    return Status::Error("landmark model '" + path +
                         "' is not a valid dlib shape predictor (" + e.what() +
                         ")" + hint);
  }
  if (impl->num_parts() != 68) {
    return Status::Error("landmark model '" + path + "' predicts " +
                         std::to_string(impl->num_parts()) +
                         " points; steadiface needs the 68-point model" + hint);
  }
  if (cacheable) write_cache(*impl);
  impl->Pack();
  p->impl_ = impl;
  {
    std::lock_guard<std::mutex> lock(cache_mutex);
    cache[path] = impl;
  }
  *out = std::move(p);
  return Status::Ok();
}

int LandmarkPredictor::num_parts() const {
  return static_cast<int>(impl_->num_parts());
}

Status LandmarkPredictor::Predict(
    const cv::Mat& gray, const cv::Rect2d& box,
    std::vector<Eigen::Vector2d>* landmarks) const {
  if (gray.empty() || gray.type() != CV_8UC1) {
    return Status::Error("landmarks: need an 8-bit single-channel image");
  }
  if (!(box.width > 4 && box.height > 4)) {
    return Status::Error("landmarks: face box too small");
  }
  dlib::cv_image<unsigned char> img(gray);
  const dlib::rectangle r(
      static_cast<long>(std::lround(box.x)),
      static_cast<long>(std::lround(box.y)),
      static_cast<long>(std::lround(box.x + box.width - 1)),
      static_cast<long>(std::lround(box.y + box.height - 1)));
  const Impl& m = *impl_;
  dlib::matrix<float, 0, 1> shape = m.initial_shape;
  thread_local std::vector<float> features;
  thread_local std::vector<const float*> leaves;
  float* s = &shape(0);
  const long n = shape.size();
  const size_t line_floats = 64 / sizeof(float);
  constexpr size_t kAhead = 6;  // leaves prefetched ahead of the sum
  for (size_t iter = 0; iter < m.forests.size(); ++iter) {
    dlib::impl::extract_feature_pixel_values(img, r, shape, m.initial_shape,
                                             m.anchor_idx[iter], m.deltas[iter],
                                             features);
    // dlib's tree walks first (they read only the small split tables and
    // this cascade's features), then the leaves' sum in the same order as
    // dlib's (bit-identical), each leaf fetched from memory a few leaves
    // ahead: the ~4 MB of leaves a fit touches in the 65 MB model are what
    // the predictor waits on.
    if (m.packed()) {
      // dlib's regression_tree::operator() on the packed splits.
      const Impl::Split* sp = &m.splits[iter * m.trees * m.splits_per_tree];
      const float* lv = m.leaves + iter * m.trees * m.leaves_per_tree * n;
      const float* f = features.data();
      leaves.resize(m.trees);
      for (size_t t = 0; t < m.trees; ++t, sp += m.splits_per_tree) {
        size_t i = 0;
        while (i < m.splits_per_tree) {
          i = f[sp[i].idx1] - f[sp[i].idx2] > sp[i].thresh ? 2 * i + 1
                                                           : 2 * i + 2;
        }
        leaves[t] = lv + (t * m.leaves_per_tree + (i - m.splits_per_tree)) * n;
      }
    } else {
      const auto& forest = m.forests[iter];
      leaves.resize(forest.size());
      for (size_t i = 0; i < forest.size(); ++i) {
        unsigned long leaf = 0;
        leaves[i] = &forest[i](features, leaf)(0);
      }
    }
    auto prefetch = [&](size_t i) {
      for (long k = 0; k < n; k += static_cast<long>(line_floats)) {
        __builtin_prefetch(leaves[i] + k);
      }
    };
    for (size_t i = 0; i < std::min(kAhead, leaves.size()); ++i) prefetch(i);
    for (size_t i = 0; i < leaves.size(); ++i) {
      if (i + kAhead < leaves.size()) prefetch(i + kAhead);
      const float* v = leaves[i];
      for (long k = 0; k < n; ++k) s[k] += v[k];
    }
  }
  const dlib::point_transform_affine to_img =
      dlib::impl::unnormalizing_tform(r);
  landmarks->resize(m.num_parts());
  for (unsigned long i = 0; i < m.num_parts(); ++i) {
    const dlib::dpoint p = to_img(dlib::impl::location(shape, i));
    (*landmarks)[i] = Eigen::Vector2d(p.x(), p.y());
  }
  return Status::Ok();
}

std::vector<Eigen::Vector2d> LandmarkPredictor::MeanShape() const {
  std::vector<Eigen::Vector2d> out(impl_->num_parts());
  for (unsigned long i = 0; i < impl_->num_parts(); ++i) {
    const dlib::vector<float, 2> p =
        dlib::impl::location(impl_->initial_shape, i);
    out[i] = Eigen::Vector2d(p.x(), p.y());
  }
  return out;
}

}  // namespace steadiface
