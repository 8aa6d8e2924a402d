#pragma once

// LandmarkPredictor's model (internal to landmark_predictor.cc and
// landmark_model_cache.cc; not API).

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include <dlib/image_processing/shape_predictor.h>

#include "steadiface_core/face/landmark_predictor.h"

namespace steadiface {

/// The model file a decoded-model cache belongs to: canonical path, size
/// and modification time.
struct LandmarkModelKey {
  std::string canonical;
  uint64_t size = 0;
  int64_t mtime_ns = 0;
};
/// The model file's key; false if it cannot be stat'ed.
bool StatLandmarkModel(const std::string& path, LandmarkModelKey* key);
/// The cache file for that model in `dir`.
std::string LandmarkCacheFile(const std::string& dir,
                              const LandmarkModelKey& key);

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
  // The leaf block: either owned (owned_leaves, from Pack()) or the packed
  // cache file's own pages, mapped read-only (mapping; see ReadPackedCache).
  const float* leaves = nullptr;
  size_t trees = 0, splits_per_tree = 0, leaves_per_tree = 0;
  bool packed() const { return leaves != nullptr; }
  void Pack();
  // The decoded-model cache (landmark_model_cache.cc), named after the
  // model file it was decoded from, in one of two forms:
  //  - packed (models whose trees are all alike, as dlib's shipped ones):
  //    the packed splits, then the leaf block page-aligned in the file, so
  //    that ReadPackedCache maps it instead of reading it: a run faults in
  //    only the pages of the leaves its fits reach, from the page cache,
  //    where a copy cost ~0.1 CPU-s of zeroed huge pages and memcpy;
  //  - plain (any other model): dlib's structures as native-endian arrays,
  //    read by ReadCache.
  // The readers return false when the file is not this model's, is damaged
  // or is of the other form; the writers write atomically and fail silently.
  bool ReadPackedCache(const std::string& file, const LandmarkModelKey& key);
  bool ReadCache(const std::string& file, const LandmarkModelKey& key);
  void WritePackedCache(const std::string& dir, const std::string& file,
                        const LandmarkModelKey& key) const;
  void WriteCache(const std::string& dir, const std::string& file,
                  const LandmarkModelKey& key) const;
  // The owned leaf block for `floats` floats: aligned and padded to 2 MiB
  // and advised onto transparent huge pages, so filling it takes a few
  // dozen page faults instead of ~17 000 (each costly in a VM). False if it
  // cannot be had.
  bool AllocateLeaves(size_t floats) {
    constexpr size_t kHuge = size_t{2} << 20;
    const size_t bytes = (floats * sizeof(float) + kHuge - 1) / kHuge * kHuge;
    owned_leaves = static_cast<float*>(std::aligned_alloc(kHuge, bytes));
    if (owned_leaves == nullptr) return false;
#ifdef MADV_HUGEPAGE
    madvise(owned_leaves, bytes, MADV_HUGEPAGE);  // advice only
#endif
    leaves = owned_leaves;
    return true;
  }
  float* owned_leaves = nullptr;
  // The packed cache file, mapped read-only for the model's lifetime (the
  // cache is only ever replaced by rename, so these pages stay this file's).
  void* mapping = nullptr;
  size_t mapping_bytes = 0;
  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() {
    std::free(owned_leaves);
    if (mapping != nullptr) munmap(mapping, mapping_bytes);
  }
};

}  // namespace steadiface
