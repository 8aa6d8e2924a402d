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

#include "face/landmark_predictor_impl.h"
#include "steadiface_core/common/model_cache.h"

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
// names the source (canonical path, size, modification time). The plain
// form (dlib's structures) and the packed form (Impl's) differ in magic.
constexpr char kCacheMagic[8] = {'S', 'F', 'L', 'M', 'C', 'A', 'C', '1'};
constexpr char kPackedMagic[8] = {'S', 'F', 'L', 'M', 'P', 'A', 'K', '2'};
// The packed form's leaf block starts at a multiple of this in the file, so
// the mapped leaves are page- (and so cache-line-) aligned.
constexpr uint64_t kLeafAlignment = 4096;

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
  size_t left() const { return static_cast<size_t>(end_ - p_); }

 private:
  const char* p_;
  const char* end_;
};

// The header: magic and the model file the cache was decoded from.
bool ReadCacheHeader(CacheReader* r, const LandmarkModelKey& key,
                     const char (&expected)[8] = kCacheMagic) {
  char magic[8];
  uint64_t size = 0, len = 0;
  int64_t mtime = 0;
  std::string canonical;
  for (char& c : magic) {
    if (!r->Pod(&c)) return false;
  }
  return std::memcmp(magic, expected, sizeof(magic)) == 0 && r->Pod(&size) &&
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
bool ReadCacheTrailer(CacheReader* r, const char (&expected)[8] = kCacheMagic) {
  char magic[8];
  for (char& c : magic) {
    if (!r->Pod(&c)) return false;
  }
  return std::memcmp(magic, expected, sizeof(magic)) == 0 && r->AtEnd();
}

// The header both forms share: magic, the model file's key.
void WriteCacheHeader(CacheWriter* w, std::ostream* out,
                      const LandmarkModelKey& key, const char (&magic)[8]) {
  for (char c : magic) w->Pod(c);
  w->Pod(key.size);
  w->Pod(key.mtime_ns);
  w->Pod(static_cast<uint64_t>(key.canonical.size()));
  out->write(key.canonical.data(),
             static_cast<std::streamsize>(key.canonical.size()));
}

// One cascade's feature anchors and deltas, as ReadAnchorsAndDeltas reads.
void WriteAnchorsAndDeltas(CacheWriter* w,
                           const std::vector<unsigned long>& anchors,
                           const std::vector<dlib::vector<float, 2>>& deltas) {
  w->Pod(static_cast<uint64_t>(anchors.size()));
  for (unsigned long a : anchors) w->Pod(static_cast<uint64_t>(a));
  w->Pod(static_cast<uint64_t>(deltas.size()));
  for (const auto& d : deltas) {
    w->Pod(d.x());
    w->Pod(d.y());
  }
}

// The cache file mapped read-only (no copy into a buffer, and no page
// touched until read); unmapped when it goes out of scope unless released.
class MappedFile {
 public:
  explicit MappedFile(const std::string& path) {
    const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;
    struct stat st;
    if (fstat(fd, &st) == 0 && st.st_size > 0) {
      void* p = mmap(nullptr, static_cast<size_t>(st.st_size), PROT_READ,
                     MAP_PRIVATE, fd, 0);
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
  // Hands the mapping over: the caller unmaps it (data(), size()).
  void Release() { data_ = nullptr; }

 private:
  const char* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace

// The packed form, mapped: the splits copied into their records (2.8 MB for
// the 68-point model), the leaf block left where it is in the mapping (see
// Impl). False, with this Impl to be discarded, when the file is not this
// model's or not packed, or is damaged: every count is checked against the
// bytes left, the leaf block must end exactly at the trailer, and every
// split and anchor index must be in range (Predict indexes with them
// unchecked).
bool LandmarkPredictor::Impl::ReadPackedCache(const std::string& file,
                                              const LandmarkModelKey& key) {
  Impl* m = this;
  MappedFile mapped(file);
  if (mapped.data() == nullptr) return false;
  CacheReader r(mapped.data(), mapped.size());
  uint64_t n_cascades = 0, trees = 0, splits_per_tree = 0, leaves_per_tree = 0;
  if (!ReadCacheHeader(&r, key, kPackedMagic) ||
      !ReadShapeAndCascades(&r, &m->initial_shape, &n_cascades) ||
      n_cascades == 0 || !r.Count(&trees, 16) || trees == 0 ||
      !r.Count(&splits_per_tree, 12) || !r.Pod(&leaves_per_tree) ||
      leaves_per_tree != splits_per_tree + 1) {
    return false;
  }
  const uint64_t n = static_cast<uint64_t>(m->initial_shape.size());
  const uint64_t parts = n / 2;
  // The leaf block must fit in the file: checked before anything is sized
  // by these counts (a damaged count cannot ask for more than the file).
  const uint64_t floats = n_cascades * trees * leaves_per_tree * n;
  if (floats / n / leaves_per_tree / trees != n_cascades ||
      floats > mapped.size() / sizeof(float)) {
    return false;
  }
  m->forests.resize(n_cascades);  // their count only: the trees are packed
  m->anchor_idx.resize(n_cascades);
  m->deltas.resize(n_cascades);
  for (uint64_t c = 0; c < n_cascades; ++c) {
    if (!ReadAnchorsAndDeltas(&r, &m->anchor_idx[c], &m->deltas[c]) ||
        m->anchor_idx[c].size() != m->deltas[c].size()) {
      return false;
    }
    for (unsigned long a : m->anchor_idx[c]) {
      if (a >= parts) return false;
    }
  }
  uint64_t n_splits = 0;
  if (!r.Count(&n_splits, 12) ||
      n_splits / n_cascades / trees != splits_per_tree ||
      n_splits != n_cascades * trees * splits_per_tree) {
    return false;
  }
  m->splits.resize(n_splits);
  for (uint64_t c = 0, i = 0; c < n_cascades; ++c) {
    const uint64_t features = m->anchor_idx[c].size();
    for (uint64_t k = 0; k < trees * splits_per_tree; ++k, ++i) {
      Split& sp = m->splits[i];
      if (!r.Pod(&sp.idx1) || !r.Pod(&sp.idx2) || !r.Pod(&sp.thresh) ||
          sp.idx1 >= features || sp.idx2 >= features) {
        return false;
      }
    }
  }
  // The leaf block: at its page-aligned offset, filling the file up to the
  // trailer exactly.
  uint64_t offset = 0;
  if (!r.Pod(&offset) || offset % kLeafAlignment != 0 ||
      offset < mapped.size() - r.left() || offset > mapped.size()) {
    return false;
  }
  const uint64_t block = mapped.size() - offset;
  if (block < sizeof(kPackedMagic) ||
      (block - sizeof(kPackedMagic)) / sizeof(float) != floats ||
      (block - sizeof(kPackedMagic)) % sizeof(float) != 0) {
    return false;
  }
  CacheReader trailer(mapped.data() + offset + floats * sizeof(float),
                      sizeof(kPackedMagic));
  if (!ReadCacheTrailer(&trailer, kPackedMagic)) return false;
  m->trees = trees;
  m->splits_per_tree = splits_per_tree;
  m->leaves_per_tree = leaves_per_tree;
  m->leaves = reinterpret_cast<const float*>(mapped.data() + offset);
  m->mapping = const_cast<char*>(mapped.data());
  m->mapping_bytes = mapped.size();
  mapped.Release();
  return true;
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

// Writes the plain form: a temporary file renamed into place, so a reader
// never sees half a file. Failure is silent.
void LandmarkPredictor::Impl::WriteCache(const std::string& dir,
                                         const std::string& file,
                                         const LandmarkModelKey& key) const {
  const Impl& m = *this;
  if (!MakeCacheDirs(dir)) return;
  std::ostringstream out;
  CacheWriter w(&out);
  WriteCacheHeader(&w, &out, key, kCacheMagic);
  w.Floats(&m.initial_shape(0), static_cast<uint64_t>(m.initial_shape.size()));
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
    WriteAnchorsAndDeltas(&w, m.anchor_idx[c], m.deltas[c]);
  }
  for (char c : kCacheMagic) w.Pod(c);
  WriteFileAtomically(file, out.str());
}

// Writes the packed form (ReadPackedCache's layout) of a packed model, the
// same way. Failure is silent.
void LandmarkPredictor::Impl::WritePackedCache(
    const std::string& dir, const std::string& file,
    const LandmarkModelKey& key) const {
  const Impl& m = *this;
  if (!m.packed() || !MakeCacheDirs(dir)) return;
  std::ostringstream out;
  CacheWriter w(&out);
  WriteCacheHeader(&w, &out, key, kPackedMagic);
  const uint64_t n = static_cast<uint64_t>(m.initial_shape.size());
  w.Floats(&m.initial_shape(0), n);
  w.Pod(static_cast<uint64_t>(m.forests.size()));
  w.Pod(static_cast<uint64_t>(m.trees));
  w.Pod(static_cast<uint64_t>(m.splits_per_tree));
  w.Pod(static_cast<uint64_t>(m.leaves_per_tree));
  for (size_t c = 0; c < m.forests.size(); ++c) {
    WriteAnchorsAndDeltas(&w, m.anchor_idx[c], m.deltas[c]);
  }
  w.Pod(static_cast<uint64_t>(m.splits.size()));
  for (const Split& s : m.splits) {
    w.Pod(s.idx1);
    w.Pod(s.idx2);
    w.Pod(s.thresh);
  }
  const uint64_t here = static_cast<uint64_t>(out.tellp()) + sizeof(uint64_t);
  const uint64_t offset =
      (here + kLeafAlignment - 1) / kLeafAlignment * kLeafAlignment;
  w.Pod(offset);
  const std::string pad(offset - here, '\0');
  out.write(pad.data(), static_cast<std::streamsize>(pad.size()));
  const uint64_t floats = m.forests.size() * m.trees * m.leaves_per_tree * n;
  out.write(reinterpret_cast<const char*>(m.leaves),
            static_cast<std::streamsize>(floats * sizeof(float)));
  for (char c : kPackedMagic) w.Pod(c);
  WriteFileAtomically(file, out.str());
}

}  // namespace steadiface
