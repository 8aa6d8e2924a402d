#pragma once

// The shuffle warp kernels (mesh_sampler_shuffle.cc), internal to
// mesh_sampler*.cc. Where a group of output pixels reads one source row
// pair and one 16-byte span of it, one load per row and byte shuffles
// replace the portable kernels' per-pixel loads; same arithmetic, same
// output. Built for x86 (SSSE3, chosen at run time) and AArch64; elsewhere
// STEADIFACE_SHUFFLE_KERNEL is not defined and only the portable kernels
// run.

#include <opencv2/core.hpp>
#include <opencv2/core/hal/intrin.hpp>

#include "steadiface_core/warp/mesh_sampler.h"
#include "warp/mesh_scanline.h"

#if CV_SIMD128 && defined(__GNUC__) && \
    (defined(__x86_64__) || defined(__i386__))
#define STEADIFACE_SHUFFLE_KERNEL 1
// Declarations and definitions carry the same target (GCC treats functions
// with different targets as versions of one another).
#define STEADIFACE_SHUFFLE_TARGET __attribute__((target("ssse3")))
#elif CV_SIMD128 && CV_NEON && defined(__aarch64__)
#define STEADIFACE_SHUFFLE_KERNEL 1
#define STEADIFACE_SHUFFLE_TARGET
#endif

namespace steadiface {
namespace mesh_sampler_internal {

/// Whether this CPU runs the shuffle kernels (always false where they are
/// not built).
bool ShuffleSupported();

#ifdef STEADIFACE_SHUFFLE_KERNEL
/// A stepped 3-channel segment of an output row `width` px wide (`out` is
/// the row): shuffle groups where they apply, the portable group or single
/// pixels elsewhere. Adds its pixel counts to `counts`.
STEADIFACE_SHUFFLE_TARGET void Color3SegmentShuffle(const ScanSegment& seg,
                                                    const cv::Mat& in,
                                                    int width, uchar* out,
                                                    SampleStats* counts);
/// The same for a stepped 1-channel segment.
STEADIFACE_SHUFFLE_TARGET void Mono8SegmentShuffle(const ScanSegment& seg,
                                                   const cv::Mat& in,
                                                   uchar* out,
                                                   SampleStats* counts);
#endif

}  // namespace mesh_sampler_internal
}  // namespace steadiface
