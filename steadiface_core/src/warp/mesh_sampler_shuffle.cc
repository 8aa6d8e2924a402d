#include "warp/mesh_sampler_shuffle.h"

#include <cstdint>
#include <cstring>

#include <opencv2/core/utility.hpp>
#if defined(STEADIFACE_SHUFFLE_KERNEL) && \
    (defined(__x86_64__) || defined(__i386__))
#include <tmmintrin.h>
#endif

#include "warp/mesh_sampler_kernels.h"

namespace steadiface {
namespace mesh_sampler_internal {

#ifndef STEADIFACE_SHUFFLE_KERNEL
bool ShuffleSupported() { return false; }
#else
namespace {

// The two byte operations the shuffle kernel needs, which OpenCV's
// universal intrinsics do not offer outside OpenCV's own build:
// ShuffleBytes: r[i] = a[idx[i]] for idx[i] < 16, 0 for idx[i] >= 0x80;
// MulAddPairs: 16-bit r[i] = a[2i] w[2i] + a[2i+1] w[2i+1], bytes unsigned,
// w[] <= 127 (here <= 32, so no sum saturates).
// SSSE3's pshufb and pmaddubsw on x86 (chosen at run time: the functions
// carrying them are compiled for SSSE3, the rest of the file for the
// baseline); tbl and umull + addp on AArch64. Elsewhere the portable kernel
// runs.
#if defined(__x86_64__) || defined(__i386__)
STEADIFACE_SHUFFLE_TARGET inline cv::v_uint8x16 ShuffleBytes(
    const cv::v_uint8x16& a, const cv::v_uint8x16& idx) {
  return cv::v_uint8x16(_mm_shuffle_epi8(a.val, idx.val));
}
STEADIFACE_SHUFFLE_TARGET inline cv::v_int16x8 MulAddPairs(
    const cv::v_uint8x16& a, const cv::v_uint8x16& w) {
  return cv::v_int16x8(_mm_maddubs_epi16(a.val, w.val));
}
#else  // AArch64
inline cv::v_uint8x16 ShuffleBytes(const cv::v_uint8x16& a,
                                   const cv::v_uint8x16& idx) {
  return cv::v_uint8x16(vqtbl1q_u8(a.val, idx.val));
}
inline cv::v_int16x8 MulAddPairs(const cv::v_uint8x16& a,
                                 const cv::v_uint8x16& w) {
  const uint16x8_t lo = vmull_u8(vget_low_u8(a.val), vget_low_u8(w.val));
  const uint16x8_t hi = vmull_high_u8(a.val, w.val);
  return cv::v_int16x8(vreinterpretq_s16_u16(vpaddq_u16(lo, hi)));
}
#endif

// The shuffle kernel, 3 channels, 4 output pixels per step. When the 4
// pixels read one source row pair (same iy) and at most 4 adjacent source
// columns (ix0..ix0+3 and their right neighbours: 15 bytes), one 16-byte
// load per row holds every byte they need, and byte shuffles pick them out;
// no per-pixel address, no scalar loads. The group's 12 (pixel, channel)
// samples P = 3 pixel + channel each take a (left, right) byte pair; pairs
// 0-7 fill register A, 8-11 the low half of register B.
//   Horizontal step first: per pair left (32 - fx) + right fx, a byte-pair
//   dot product, <= 255 * 32 (exact in 16 bits).
//   Vertical step: the rows' sums zipped (top, bottom) and dotted with
//   64 ((32 - fy), fy), exact in 32 bits (<= 255 * 1024 * 64 < 2^24).
// The same integer sum h as cv::remap's (and the portable kernel's), times
// 64: (64 h + 2^15) >> 16 = (h + 512) >> 10, cv::remap's rounding, is byte 2
// of each 32-bit lane, which a shuffle picks out (no shifts, no packs). The
// three zipped registers hold P = 0-3, 4-7, 8-11: the output's bytes in
// order, bit for bit cv::remap's.
struct Color3ShuffleTables {
  /// Registers A, B: the byte of each pair's pixel's 32-bit lane (its low
  /// byte) for both bytes of the pair; 0x80 (zero) past pair 11.
  alignas(16) uint8_t pair_pixel_byte[2][16];
  /// Registers A, B: each byte's offset from its pixel's left column:
  /// channel (left byte), 3 + channel (right byte); 0x80 past pair 11.
  alignas(16) uint8_t pair_offset[2][16];
  /// Registers A, B: the two bytes of each pair's pixel's horizontal
  /// weights ((32 - fx), fx) in its 32-bit lane; 0x80 past pair 11.
  alignas(16) uint8_t pair_weight_byte[2][16];
  /// Zipped registers 0-2: each 32-bit lane (pair P = 4r + i) takes its
  /// pixel's 32-bit lane (the vertical weights).
  alignas(16) uint8_t pixel_word[3][16];
  /// Sums 0-2: output byte P = 4r + i is byte 2 of lane i of sum r; 0x80
  /// (zero) elsewhere, so the three OR into the output.
  alignas(16) uint8_t output_byte[3][16];
};

constexpr Color3ShuffleTables MakeColor3ShuffleTables() {
  Color3ShuffleTables t{};
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < 8; ++k) {
      const int pair = 8 * r + k, pixel = pair / 3, channel = pair % 3;
      const bool used = pair < 12;
      for (int right = 0; right < 2; ++right) {
        t.pair_pixel_byte[r][2 * k + right] =
            used ? static_cast<uint8_t>(4 * pixel) : 0x80;
        t.pair_offset[r][2 * k + right] =
            used ? static_cast<uint8_t>(3 * right + channel) : 0x80;
        t.pair_weight_byte[r][2 * k + right] =
            used ? static_cast<uint8_t>(4 * pixel + right) : 0x80;
      }
    }
  }
  for (int r = 0; r < 3; ++r) {
    for (int i = 0; i < 4; ++i) {
      const int pixel = (4 * r + i) / 3;
      for (int b = 0; b < 4; ++b) {
        t.pixel_word[r][4 * i + b] = static_cast<uint8_t>(4 * pixel + b);
      }
    }
    for (int b = 0; b < 16; ++b) {
      t.output_byte[r][b] =
          b / 4 == r ? static_cast<uint8_t>(4 * (b % 4) + 2) : 0x80;
    }
  }
  return t;
}
constexpr Color3ShuffleTables kColor3Shuffle = MakeColor3ShuffleTables();

}  // namespace

#if defined(__x86_64__) || defined(__i386__)
bool ShuffleSupported() { return cv::checkHardwareSupport(CV_CPU_SSSE3); }
#else
bool ShuffleSupported() { return true; }
#endif

namespace {

// A segment's start and steps in locals (the output stores may alias seg,
// so the compiler would reload its fields after each one), the lanes'
// offsets for 4-pixel coordinate vectors and their step per 4 pixels.
struct SegmentLanes {
  int32_t X0, Y0, DX, DY;
  int u0;
  cv::v_int32x4 ramp, rampy, dx4, dy4;
};

STEADIFACE_SHUFFLE_TARGET inline SegmentLanes Lanes(const ScanSegment& seg) {
  using namespace cv;
  const int32_t DX = seg.DX, DY = seg.DY;
  return {seg.X,
          seg.Y,
          DX,
          DY,
          seg.u0,
          v_int32x4(0, DX, 2 * DX, 3 * DX),
          v_int32x4(0, DY, 2 * DY, 3 * DY),
          v_setall_s32(4 * DX),
          v_setall_s32(4 * DY)};
}

// Moves the coordinates to pixel g of the segment (for the overlapping last
// group, as in SampleRow, and the start).
STEADIFACE_SHUFFLE_TARGET inline void MoveTo(const SegmentLanes& L, int g, int32_t* X, int32_t* Y,
                                             cv::v_int32x4* Xv, cv::v_int32x4* Yv) {
  *X = L.X0 + g * L.DX;
  *Y = L.Y0 + g * L.DY;
  *Xv = cv::v_setall_s32(*X) + L.ramp;
  *Yv = cv::v_setall_s32(*Y) + L.rampy;
}

// A segment shorter than one group of `group` pixels: sampled pixel by
// pixel. True when it was one.
inline bool ShortSegment(const ScanSegment& seg, const cv::Mat& in, int cn, int group,
                         uchar* out, SampleStats* counts) {
  const int n = seg.u1 - seg.u0 + 1;
  if (n >= group) return false;
  SamplePixels(in, cn, seg.X, seg.Y, seg.DX, seg.DY, n, out + seg.u0 * cn);
  counts->scalar_px += n;
  return true;
}

// How many pixels each path sampled, added to the segment's counts.
struct PathCounts {
  int64_t shuffled = 0, portable = 0, scalar = 0;
  void AddTo(SampleStats* counts) const {
    counts->shuffle_px += shuffled;
    counts->portable_simd_px += portable;
    counts->scalar_px += scalar;
  }
};

}  // namespace

namespace {

// Both kernels' interpolation constants: the fraction mask (31) and 32,
// each also times 64 (fy, 64 times, comes from Y in one shift:
// Y >> (kScanFrac - 6), masked), 255 and the rounding half.
struct InterConsts {
  cv::v_int32x4 m31, m31x64, k32, k32x64, half;
  cv::v_uint16x8 k255;
};

STEADIFACE_SHUFFLE_TARGET inline void LoadInterConsts(InterConsts* k) {
  using namespace cv;
  k->m31 = v_setall_s32(kInterTabSize - 1);
  k->m31x64 = v_setall_s32((kInterTabSize - 1) << 6);
  k->k32 = v_setall_s32(kInterTabSize);
  k->k32x64 = v_setall_s32(kInterTabSize << 6);
  k->k255 = v_setall_u16(255);
  k->half = v_setall_s32(1 << 15);
}

// The 3-channel kernel's constants and tables, loaded once per segment.
struct Color3Consts : InterConsts {
  cv::v_uint8x16 pix_a, pix_b, off_a, off_b, wsel_a, wsel_b, word0, word1, word2, out0, out1,
      out2;
};

STEADIFACE_SHUFFLE_TARGET inline Color3Consts LoadColor3Consts() {
  using namespace cv;
  Color3Consts k;
  LoadInterConsts(&k);
  k.pix_a = v_load(kColor3Shuffle.pair_pixel_byte[0]);
  k.pix_b = v_load(kColor3Shuffle.pair_pixel_byte[1]);
  k.off_a = v_load(kColor3Shuffle.pair_offset[0]);
  k.off_b = v_load(kColor3Shuffle.pair_offset[1]);
  k.wsel_a = v_load(kColor3Shuffle.pair_weight_byte[0]);
  k.wsel_b = v_load(kColor3Shuffle.pair_weight_byte[1]);
  k.word0 = v_load(kColor3Shuffle.pixel_word[0]);
  k.word1 = v_load(kColor3Shuffle.pixel_word[1]);
  k.word2 = v_load(kColor3Shuffle.pixel_word[2]);
  k.out0 = v_load(kColor3Shuffle.output_byte[0]);
  k.out1 = v_load(kColor3Shuffle.output_byte[1]);
  k.out2 = v_load(kColor3Shuffle.output_byte[2]);
  return k;
}

// One group of 4 pixels at (Xv, Yv) whose sources lie in the row pair at
// `p` (pixel ix0 of row iy0) within 16 bytes: the 12 output bytes (and 4
// zero bytes).
STEADIFACE_SHUFFLE_TARGET inline cv::v_uint8x16 Color3Group(const Color3Consts& k,
                                                            const uchar* p, size_t step,
                                                            int ix0, const cv::v_int32x4& Xv,
                                                            const cv::v_int32x4& Yv) {
  using namespace cv;
  constexpr int shift = kScanFrac + kInterBits;
  const v_uint8x16 top = v_load(p);
  const v_uint8x16 bottom = v_load(p + step);
  // Each pixel's byte offset from pixel ix0 (0..9), and its weights, one
  // 32-bit lane per pixel (adds and 16-bit multiplies rather than shifts:
  // shifts share the shuffles' ports).
  const v_int32x4 rel = v_shr<shift>(Xv) - v_setall_s32(ix0);
  const v_uint8x16 off = v_reinterpret_as_u8(rel + rel + rel);
  const v_int32x4 fx = v_shr<kScanFrac>(Xv) & k.m31;
  // Bytes (32 - fx, fx): 32 + 255 fx (fx < 32: the high 16 bits stay 0).
  const v_uint8x16 wx = v_reinterpret_as_u8(
      k.k32 + v_reinterpret_as_s32(v_mul_wrap(v_reinterpret_as_u16(fx), k.k255)));
  const v_int32x4 fy64 = v_shr<kScanFrac - 6>(Yv) & k.m31x64;
  // 16-bit halves (64 (32 - fy), 64 fy).
  const v_uint8x16 wy = v_reinterpret_as_u8((k.k32x64 - fy64) | v_shl<16>(fy64));
  // Horizontal step, per row and pair.
  const v_uint8x16 idx_a = ShuffleBytes(off, k.pix_a) + k.off_a;
  const v_uint8x16 idx_b = ShuffleBytes(off, k.pix_b) + k.off_b;
  const v_uint8x16 w_a = ShuffleBytes(wx, k.wsel_a);
  const v_uint8x16 w_b = ShuffleBytes(wx, k.wsel_b);
  const v_int16x8 top_a = MulAddPairs(ShuffleBytes(top, idx_a), w_a);
  const v_int16x8 top_b = MulAddPairs(ShuffleBytes(top, idx_b), w_b);
  const v_int16x8 bot_a = MulAddPairs(ShuffleBytes(bottom, idx_a), w_a);
  const v_int16x8 bot_b = MulAddPairs(ShuffleBytes(bottom, idx_b), w_b);
  // Vertical step: (top, bottom) per pair, P = 0-3, 4-7, 8-11; rounded,
  // and the result byte picked out.
  v_int16x8 z0, z1, z2, unused;
  v_zip(top_a, bot_a, z0, z1);
  v_zip(top_b, bot_b, z2, unused);
  const v_int32x4 h0 = v_dotprod(z0, v_reinterpret_as_s16(ShuffleBytes(wy, k.word0))) + k.half;
  const v_int32x4 h1 = v_dotprod(z1, v_reinterpret_as_s16(ShuffleBytes(wy, k.word1))) + k.half;
  const v_int32x4 h2 = v_dotprod(z2, v_reinterpret_as_s16(ShuffleBytes(wy, k.word2))) + k.half;
  return ShuffleBytes(v_reinterpret_as_u8(h0), k.out0) |
         ShuffleBytes(v_reinterpret_as_u8(h1), k.out1) |
         ShuffleBytes(v_reinterpret_as_u8(h2), k.out2);
}

}  // namespace

// A stepped 3-channel segment: shuffle groups where they apply, the
// portable 4-pixel group or scalar pixels elsewhere (same arithmetic).
STEADIFACE_SHUFFLE_TARGET void Color3SegmentShuffle(const ScanSegment& seg,
                                                    const cv::Mat& in,
                                                    int width, uchar* out,
                                                    SampleStats* counts) {
  using namespace cv;
  constexpr int shift = kScanFrac + kInterBits;
  const uchar* base = in.ptr<uchar>(0);
  const size_t step = in.step[0];
  if (ShortSegment(seg, in, 3, 4, out, counts)) return;
  const int n = seg.u1 - seg.u0 + 1;
  const SegmentLanes L = Lanes(seg);
  const int32_t X0 = L.X0, Y0 = L.Y0, DX = L.DX, DY = L.DY;
  const int max_iy = in.rows - 2;
  // A 16-byte load at pixel ix0 stays in its row for ix0 <= cols - 6.
  const int max_ix_shuffle = in.cols - 6;
  const int max_ix_portable = in.cols - 3;
  // The whole segment within the shuffle's margins and 0 <= DX <= 1 px (so
  // 4 pixels span at most ix0..ix0+3): only the source row can still differ
  // within a group, and only that is checked per group.
  const bool whole = DX >= 0 && DX <= (1 << shift) &&
                     GroupInside(X0, Y0, DX, DY, n, max_ix_shuffle, max_iy);
  const Color3Consts k = LoadColor3Consts();
  PathCounts c;
  int32_t X, Y;
  v_int32x4 Xv, Yv;  // the group's 4 coordinates, stepped like X and Y
  MoveTo(L, 0, &X, &Y, &Xv, &Yv);
  for (int g = 0; g < n; g += 4, X += 4 * DX, Y += 4 * DY, Xv += L.dx4, Yv += L.dy4) {
    if (g + 4 > n) MoveTo(L, g = n - 4, &X, &Y, &Xv, &Yv);
    const int u = L.u0 + g;
    const int ix0 = X >> shift, iy0 = Y >> shift;
    const int iy3 = (Y + 3 * DY) >> shift;
    uchar* dst = out + u * 3;
    if (iy0 != iy3 ||
        (!whole &&
         (static_cast<unsigned>(((X + 3 * DX) >> shift) - ix0) > 3u ||
          ix0 < 0 || ix0 > max_ix_shuffle || iy0 < 0 || iy0 > max_iy))) {
      if (GroupInside(X, Y, DX, DY, 4, max_ix_portable, max_iy)) {
        Color4<3>(base, step, Xv, Yv, u + 6 <= width, dst);
        c.portable += 4;
      } else {
        SamplePixels(in, 3, X, Y, DX, DY, 4, dst);
        c.scalar += 4;
      }
      continue;
    }
    const v_uint8x16 r =
        Color3Group(k, base + static_cast<size_t>(iy0) * step + ix0 * 3, step, ix0, Xv, Yv);
    if (u + 6 <= width) {
      v_store(dst, r);  // bytes 12-15 (zero): the next pixels', written later
    } else {
      v_store_low(dst, r);
      const unsigned tail = v_extract_n<2>(v_reinterpret_as_u32(r));
      std::memcpy(dst + 8, &tail, 4);
    }
    c.shuffled += 4;
  }
  c.AddTo(counts);
}
namespace {

// The 1-channel kernel's constants and tables, loaded once per segment.
struct Mono8Consts : InterConsts {
  cv::v_uint8x16 pair_low, left_right, out0, out1;
};

STEADIFACE_SHUFFLE_TARGET inline Mono8Consts LoadMono8Consts() {
  using namespace cv;
  // Pixel k's offset (16-bit lane k, < 16) to both bytes of pair k, plus
  // (0, 1): the left and right columns.
  alignas(16) static constexpr uint8_t kPairLow[16] = {
      0, 0, 2, 2, 4, 4, 6, 6, 8, 8, 10, 10, 12, 12, 14, 14};
  alignas(16) static constexpr uint8_t kLeftRight[16] = {
      0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1};
  // Byte 2 of sums 0 and 1's lanes to output bytes 0-3 and 4-7.
  alignas(16) static constexpr uint8_t kOut0[16] = {
      2,    6,    10,   14,   0x80, 0x80, 0x80, 0x80,
      0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80};
  alignas(16) static constexpr uint8_t kOut1[16] = {
      0x80, 0x80, 0x80, 0x80, 2,    6,    10,   14,
      0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80};
  Mono8Consts k;
  LoadInterConsts(&k);
  k.pair_low = v_load(kPairLow);
  k.left_right = v_load(kLeftRight);
  k.out0 = v_load(kOut0);
  k.out1 = v_load(kOut1);
  return k;
}

// One group of 8 pixels at (Xa, Ya) and (Xb, Yb) whose sources lie in the
// row pair at `p` (pixel ix0) within 16 bytes: their 8 output bytes, low half.
STEADIFACE_SHUFFLE_TARGET inline cv::v_uint8x16 Mono8Group(
    const Mono8Consts& k, const uchar* p, size_t step, int ix0, const cv::v_int32x4& Xa,
    const cv::v_int32x4& Xb, const cv::v_int32x4& Ya, const cv::v_int32x4& Yb) {
  using namespace cv;
  constexpr int shift = kScanFrac + kInterBits;
  const v_uint8x16 top = v_load(p);
  const v_uint8x16 bottom = v_load(p + step);
  // Offsets from ix0 (0..14) and horizontal weight bytes (32 - fx, fx)
  // = 32 + 255 fx, one 16-bit lane per pixel.
  const v_int32x4 col0 = v_setall_s32(ix0);
  const v_uint8x16 rel =
      v_reinterpret_as_u8(v_pack(v_shr<shift>(Xa) - col0, v_shr<shift>(Xb) - col0));
  const v_int32x4 fxa = v_shr<kScanFrac>(Xa) & k.m31;
  const v_int32x4 fxb = v_shr<kScanFrac>(Xb) & k.m31;
  const v_uint8x16 wx = v_reinterpret_as_u8(
      v_pack(k.k32 + v_reinterpret_as_s32(v_mul_wrap(v_reinterpret_as_u16(fxa), k.k255)),
             k.k32 + v_reinterpret_as_s32(v_mul_wrap(v_reinterpret_as_u16(fxb), k.k255))));
  const v_uint8x16 idx = ShuffleBytes(rel, k.pair_low) + k.left_right;
  const v_int16x8 t = MulAddPairs(ShuffleBytes(top, idx), wx);
  const v_int16x8 b = MulAddPairs(ShuffleBytes(bottom, idx), wx);
  // Vertical step with 64 ((32 - fy), fy) per 32-bit lane (pixel).
  const v_int32x4 fya = v_shr<kScanFrac - 6>(Ya) & k.m31x64;
  const v_int32x4 fyb = v_shr<kScanFrac - 6>(Yb) & k.m31x64;
  const v_int16x8 wya = v_reinterpret_as_s16((k.k32x64 - fya) | v_shl<16>(fya));
  const v_int16x8 wyb = v_reinterpret_as_s16((k.k32x64 - fyb) | v_shl<16>(fyb));
  v_int16x8 z0, z1;
  v_zip(t, b, z0, z1);
  const v_int32x4 h0 = v_dotprod(z0, wya) + k.half;
  const v_int32x4 h1 = v_dotprod(z1, wyb) + k.half;
  return ShuffleBytes(v_reinterpret_as_u8(h0), k.out0) |
         ShuffleBytes(v_reinterpret_as_u8(h1), k.out1);
}

}  // namespace

// The shuffle kernel, 1 channel, 8 output pixels per step: when the 8 read
// one source row pair and at most 15 adjacent columns (ix0..ix0+14 and
// their right neighbours), one 16-byte load per row holds them all. One
// shuffle per row makes each pixel's (left, right) byte pair, a byte-pair
// dot product with ((32 - fx), fx) the horizontal step, and the vertical
// step, the rounding and the byte pick-out are the 3-channel kernel's (the
// zipped registers hold pixels 0-3 and 4-7, the lanes of the coordinate
// vectors, so the vertical weights need no shuffle). Bit for bit cv::remap.
STEADIFACE_SHUFFLE_TARGET void Mono8SegmentShuffle(const ScanSegment& seg,
                                                   const cv::Mat& in,
                                                   uchar* out,
                                                   SampleStats* counts) {
  using namespace cv;
  constexpr int shift = kScanFrac + kInterBits;
  const uchar* base = in.ptr<uchar>(0);
  const size_t step = in.step[0];
  if (ShortSegment(seg, in, 1, 8, out, counts)) return;
  const int n = seg.u1 - seg.u0 + 1;
  const SegmentLanes L = Lanes(seg);
  const int32_t X0 = L.X0, Y0 = L.Y0, DX = L.DX, DY = L.DY;
  const int max_iy = in.rows - 2;
  // A 16-byte load at pixel ix0 stays in its row for ix0 <= cols - 16.
  const int max_ix_shuffle = in.cols - 16;
  // The whole segment within the margins and 0 <= 7 DX <= 14 px: only the
  // source row is checked per group.
  const bool whole = DX >= 0 && 7 * static_cast<int64_t>(DX) <= (14 << shift) &&
                     GroupInside(X0, Y0, DX, DY, n, max_ix_shuffle, max_iy);
  const v_int32x4 dx8 = v_setall_s32(8 * DX), dy8 = v_setall_s32(8 * DY);
  const Mono8Consts k = LoadMono8Consts();
  PathCounts c;
  int32_t X, Y;
  v_int32x4 Xa, Ya;  // pixels 0-3 (a; 4-7: b) of the group, stepped like X and Y
  MoveTo(L, 0, &X, &Y, &Xa, &Ya);
  for (int g = 0; g < n; g += 8, X += 8 * DX, Y += 8 * DY, Xa += dx8, Ya += dy8) {
    if (g + 8 > n) MoveTo(L, g = n - 8, &X, &Y, &Xa, &Ya);
    const int u = L.u0 + g;
    const int ix0 = X >> shift, iy0 = Y >> shift;
    const int iy7 = (Y + 7 * DY) >> shift;
    const v_int32x4 Xb = Xa + L.dx4, Yb = Ya + L.dy4;
    if (iy0 != iy7 ||
        (!whole &&
         (static_cast<unsigned>(((X + 7 * DX) >> shift) - ix0) > 14u ||
          ix0 < 0 || ix0 > max_ix_shuffle || iy0 < 0 || iy0 > max_iy))) {
      if (GroupInside(X, Y, DX, DY, 8, in.cols - 2, max_iy)) {
        Mono8(base, step, Xa, Xb, Ya, Yb, out + u);
        c.portable += 8;
      } else {
        SamplePixels(in, 1, X, Y, DX, DY, 8, out + u);
        c.scalar += 8;
      }
      continue;
    }
    const uchar* p = base + static_cast<size_t>(iy0) * step + ix0;
    v_store_low(out + u, Mono8Group(k, p, step, ix0, Xa, Xb, Ya, Yb));
    c.shuffled += 8;
  }
  c.AddTo(counts);
}
#endif  // STEADIFACE_SHUFFLE_KERNEL

}  // namespace mesh_sampler_internal
}  // namespace steadiface
