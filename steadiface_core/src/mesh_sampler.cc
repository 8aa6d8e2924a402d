#include "steadiface_core/mesh_sampler.h"

#include <atomic>
#include <cstdint>
#include <cstring>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/core/utility.hpp>
#if CV_SIMD128 && defined(__GNUC__) && \
    (defined(__x86_64__) || defined(__i386__))
#include <tmmintrin.h>
#endif

#include "steadiface_core/mesh_scanline.h"
#include "steadiface_core/warper.h"

namespace steadiface {
namespace {

// Bilinear weights of fractions fx, fy (1/32 px): (32 - f) f products,
// summing to 1024; cv::remap's table holds the same values times 32 and
// rounds (sum + 2^14) >> 15, which is (sum' + 512) >> 10 here.
constexpr int kWeightShift = 2 * kInterBits;

// One pixel at 1/32 px coordinates (X, Y), any channel count, black outside
// the input (cv::remap's BORDER_CONSTANT 0).
inline void SamplePixel(const cv::Mat& in, int cn, int32_t X, int32_t Y,
                        uchar* out) {
  const int ix = X >> kInterBits, iy = Y >> kInterBits;
  const int fx = X & (kInterTabSize - 1), fy = Y & (kInterTabSize - 1);
  const int w[4] = {(kInterTabSize - fx) * (kInterTabSize - fy),
                    fx * (kInterTabSize - fy), (kInterTabSize - fx) * fy,
                    fx * fy};
  const bool inside =
      ix >= 0 && iy >= 0 && ix + 1 < in.cols && iy + 1 < in.rows;
  for (int c = 0; c < cn; ++c) {
    int sum = 0;
    if (inside) {
      const uchar* p0 = in.ptr<uchar>(iy) + ix * cn + c;
      const uchar* p1 = p0 + in.step[0];
      sum = p0[0] * w[0] + p0[cn] * w[1] + p1[0] * w[2] + p1[cn] * w[3];
    } else {
      for (int k = 0; k < 4; ++k) {
        const int x = ix + (k & 1), y = iy + (k >> 1);
        if (x >= 0 && y >= 0 && x < in.cols && y < in.rows) {
          sum += in.ptr<uchar>(y)[x * cn + c] * w[k];
        }
      }
    }
    out[c] =
        static_cast<uchar>((sum + (1 << (kWeightShift - 1))) >> kWeightShift);
  }
}

inline uint64_t Load64(const uchar* p) {
  uint64_t v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}
inline uint16_t Load16(const uchar* p) {
  uint16_t v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

#if CV_SIMD128
// Group sizes: 8 pixels for mono8, 4 for 3 and 4 channels.
// The rows the group's pixels read lie within the input when the group's
// first and last pixels' do (the coordinates are linear in u), i.e. ix in
// [0, max_ix] and iy in [0, rows - 2].
inline bool GroupInside(int32_t X, int32_t Y, int32_t DX, int32_t DY, int n,
                        int max_ix, int max_iy) {
  const int shift = kScanFrac + kInterBits;
  const int32_t Xe = X + (n - 1) * DX, Ye = Y + (n - 1) * DY;
  const int a = X >> shift, b = Xe >> shift, c = Y >> shift, d = Ye >> shift;
  return a >= 0 && b >= 0 && a <= max_ix && b <= max_ix && c >= 0 && d >= 0 &&
         c <= max_iy && d <= max_iy;
}

// Vertical step of the bilinear sum, exact in 32 bits: per lane pair
// (top, bottom) times ((32 - fy), fy), rounded and shifted.
inline cv::v_int32x4 Vertical(const cv::v_int16x8& top_bottom,
                              const cv::v_int32x4& wy) {
  return cv::v_dotprod(top_bottom, cv::v_reinterpret_as_s16(wy));
}

// Mono8: 8 pixels of a stepped segment starting at (X, Y).
inline void Mono8(const uchar* base, size_t step, const cv::v_int32x4& Xa,
                  const cv::v_int32x4& Xb, const cv::v_int32x4& Ya,
                  const cv::v_int32x4& Yb, uchar* out) {
  using namespace cv;
  const v_int32x4 m31 = v_setall_s32(kInterTabSize - 1);
  const v_int32x4 k32 = v_setall_s32(kInterTabSize);
  int ix[8], iy[8];
  v_store(ix, v_shr<kScanFrac + kInterBits>(Xa));
  v_store(ix + 4, v_shr<kScanFrac + kInterBits>(Xb));
  v_store(iy, v_shr<kScanFrac + kInterBits>(Ya));
  v_store(iy + 4, v_shr<kScanFrac + kInterBits>(Yb));
  // Vectors built from registers (no store-to-load round trip).
  const uchar* p[8];
  for (int k = 0; k < 8; ++k)
    p[k] = base + static_cast<size_t>(iy[k]) * step + ix[k];
  const v_uint16x8 T(Load16(p[0]), Load16(p[1]), Load16(p[2]), Load16(p[3]),
                     Load16(p[4]), Load16(p[5]), Load16(p[6]), Load16(p[7]));
  const v_uint16x8 B(Load16(p[0] + step), Load16(p[1] + step),
                     Load16(p[2] + step), Load16(p[3] + step),
                     Load16(p[4] + step), Load16(p[5] + step),
                     Load16(p[6] + step), Load16(p[7] + step));
  const v_uint16x8 lo8 = v_setall_u16(0xFF);
  const v_int32x4 fxa = v_shr<kScanFrac>(Xa) & m31,
                  fxb = v_shr<kScanFrac>(Xb) & m31;
  const v_int32x4 fya = v_shr<kScanFrac>(Ya) & m31,
                  fyb = v_shr<kScanFrac>(Yb) & m31;
  const v_uint16x8 fx = v_reinterpret_as_u16(v_pack(fxa, fxb));
  const v_uint16x8 gx = v_setall_u16(kInterTabSize) - fx;
  // Horizontal step, exact in 16 bits (<= 255 * 32).
  const v_uint16x8 ht = v_mul_wrap(T & lo8, gx) + v_mul_wrap(v_shr<8>(T), fx);
  const v_uint16x8 hb = v_mul_wrap(B & lo8, gx) + v_mul_wrap(v_shr<8>(B), fx);
  v_int16x8 z0, z1;
  v_zip(v_reinterpret_as_s16(ht), v_reinterpret_as_s16(hb), z0, z1);
  const v_int32x4 wya = (k32 - fya) | v_shl<16>(fya);
  const v_int32x4 wyb = (k32 - fyb) | v_shl<16>(fyb);
  const v_int16x8 r =
      v_rshr_pack<kWeightShift>(Vertical(z0, wya), Vertical(z1, wyb));
  v_pack_u_store(out, r);
}

// 3 or 4 channels: 4 pixels of a stepped segment. `wide`: 3 channels may
// store 16 bytes (the 4 bytes past the group are the next pixels', which
// the row's later groups or segments write afterwards).
template <int CN>
inline void Color4(const uchar* base, size_t step, const cv::v_int32x4& X,
                   const cv::v_int32x4& Y, bool wide, uchar* out) {
  using namespace cv;
  const v_int32x4 m31 = v_setall_s32(kInterTabSize - 1);
  const v_int32x4 k32 = v_setall_s32(kInterTabSize);
  int ix[4], iy[4];
  v_store(ix, v_shr<kScanFrac + kInterBits>(X));
  v_store(iy, v_shr<kScanFrac + kInterBits>(Y));
  // One 8-byte read per pixel and row holds both columns: 4 bytes at the
  // pixel (BGR + the next byte, or BGRA) and, CN bytes on, 4 at its right
  // neighbour. Vectors are built from registers (no store-to-load trip).
  uint64_t t[4], b[4];
  for (int k = 0; k < 4; ++k) {
    const uchar* p = base + static_cast<size_t>(iy[k]) * step + ix[k] * CN;
    t[k] = Load64(p);
    b[k] = Load64(p + step);
  }
  auto lo = [](uint64_t v) { return static_cast<unsigned>(v); };
  auto hi = [](uint64_t v) { return static_cast<unsigned>(v >> (8 * CN)); };
  v_uint16x8 a0, a1, b0, b1, c0, c1, d0, d1;  // [pixel 0 | pixel 1], [2 | 3]
  v_expand(
      v_reinterpret_as_u8(v_uint32x4(lo(t[0]), lo(t[1]), lo(t[2]), lo(t[3]))),
      a0, a1);
  v_expand(
      v_reinterpret_as_u8(v_uint32x4(hi(t[0]), hi(t[1]), hi(t[2]), hi(t[3]))),
      b0, b1);
  v_expand(
      v_reinterpret_as_u8(v_uint32x4(lo(b[0]), lo(b[1]), lo(b[2]), lo(b[3]))),
      c0, c1);
  v_expand(
      v_reinterpret_as_u8(v_uint32x4(hi(b[0]), hi(b[1]), hi(b[2]), hi(b[3]))),
      d0, d1);
  // fx of each pixel in all 4 of its 16-bit lanes.
  const v_int32x4 fx = v_shr<kScanFrac>(X) & m31;
  const v_uint32x4 fx2 = v_reinterpret_as_u32(fx | v_shl<16>(fx));
  v_uint32x4 f01, f23;
  v_zip(fx2, fx2, f01, f23);
  const v_uint16x8 fx0 = v_reinterpret_as_u16(f01),
                   fx1 = v_reinterpret_as_u16(f23);
  const v_uint16x8 gx0 = v_setall_u16(kInterTabSize) - fx0;
  const v_uint16x8 gx1 = v_setall_u16(kInterTabSize) - fx1;
  // Horizontal step, exact in 16 bits (<= 255 * 32).
  const v_uint16x8 ht0 = v_mul_wrap(a0, gx0) + v_mul_wrap(b0, fx0);
  const v_uint16x8 ht1 = v_mul_wrap(a1, gx1) + v_mul_wrap(b1, fx1);
  const v_uint16x8 hb0 = v_mul_wrap(c0, gx0) + v_mul_wrap(d0, fx0);
  const v_uint16x8 hb1 = v_mul_wrap(c1, gx1) + v_mul_wrap(d1, fx1);
  v_int16x8 p0, p1, p2, p3;  // per pixel: (top, bottom) per channel
  v_zip(v_reinterpret_as_s16(ht0), v_reinterpret_as_s16(hb0), p0, p1);
  v_zip(v_reinterpret_as_s16(ht1), v_reinterpret_as_s16(hb1), p2, p3);
  const v_int32x4 fy = v_shr<kScanFrac>(Y) & m31;
  const v_int32x4 wy = (k32 - fy) | v_shl<16>(fy);
  const v_int16x8 r01 =
      v_rshr_pack<kWeightShift>(Vertical(p0, v_broadcast_element<0>(wy)),
                                Vertical(p1, v_broadcast_element<1>(wy)));
  const v_int16x8 r23 =
      v_rshr_pack<kWeightShift>(Vertical(p2, v_broadcast_element<2>(wy)),
                                Vertical(p3, v_broadcast_element<3>(wy)));
  const v_uint8x16 r = v_pack_u(r01, r23);
  if (CN == 4) {
    v_store(out, r);
  } else if (wide) {
    v_store(out, v_pack_triplets(r));
  } else {
    // 12 bytes, straight from the register (no round trip through memory).
    const v_uint8x16 packed = v_pack_triplets(r);
    v_store_low(out, packed);
    const unsigned tail = v_extract_n<2>(v_reinterpret_as_u32(packed));
    std::memcpy(out + 8, &tail, 4);
  }
}
#endif  // CV_SIMD128

// The two byte operations the shuffle kernel needs, which OpenCV's
// universal intrinsics do not offer outside OpenCV's own build:
// ShuffleBytes: r[i] = a[idx[i]] for idx[i] < 16, 0 for idx[i] >= 0x80;
// MulAddPairs: 16-bit r[i] = a[2i] w[2i] + a[2i+1] w[2i+1], bytes unsigned,
// w[] <= 127 (here <= 32, so no sum saturates).
// SSSE3's pshufb and pmaddubsw on x86 (chosen at run time: the functions
// carrying them are compiled for SSSE3, the rest of the file for the
// baseline); tbl and umull + addp on AArch64. Elsewhere the portable kernel
// runs.
#if CV_SIMD128 && defined(__GNUC__) && \
    (defined(__x86_64__) || defined(__i386__))
#define STEADIFACE_SHUFFLE_KERNEL 1
#define STEADIFACE_SHUFFLE_TARGET __attribute__((target("ssse3")))
STEADIFACE_SHUFFLE_TARGET inline cv::v_uint8x16 ShuffleBytes(
    const cv::v_uint8x16& a, const cv::v_uint8x16& idx) {
  return cv::v_uint8x16(_mm_shuffle_epi8(a.val, idx.val));
}
STEADIFACE_SHUFFLE_TARGET inline cv::v_int16x8 MulAddPairs(
    const cv::v_uint8x16& a, const cv::v_uint8x16& w) {
  return cv::v_int16x8(_mm_maddubs_epi16(a.val, w.val));
}
bool ShuffleSupported() { return cv::checkHardwareSupport(CV_CPU_SSSE3); }
#elif CV_SIMD128 && CV_NEON && defined(__aarch64__)
#define STEADIFACE_SHUFFLE_KERNEL 1
#define STEADIFACE_SHUFFLE_TARGET
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
bool ShuffleSupported() { return true; }
#else
bool ShuffleSupported() { return false; }
#endif

#ifdef STEADIFACE_SHUFFLE_KERNEL
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
  const int n = seg.u1 - seg.u0 + 1;
  if (n < 4) {
    int32_t X = seg.X, Y = seg.Y;
    for (int u = seg.u0; u <= seg.u1; ++u, X += seg.DX, Y += seg.DY) {
      SamplePixel(in, 3, X >> kScanFrac, Y >> kScanFrac, out + u * 3);
    }
    counts->scalar_px += n;
    return;
  }
  // Locals, not seg's fields: the output stores (uchar) may alias seg, so
  // the compiler would reload them after each one.
  const int32_t X0 = seg.X, Y0 = seg.Y, DX = seg.DX, DY = seg.DY;
  const int u0 = seg.u0;
  const int max_iy = in.rows - 2;
  // A 16-byte load at pixel ix0 stays in its row for ix0 <= cols - 6.
  const int max_ix_shuffle = in.cols - 6;
  const int max_ix_portable = in.cols - 3;
  // The whole segment within the shuffle's margins and 0 <= DX <= 1 px (so
  // 4 pixels span at most ix0..ix0+3): only the source row can still differ
  // within a group, and only that is checked per group.
  const bool whole = DX >= 0 && DX <= (1 << shift) &&
                     GroupInside(X0, Y0, DX, DY, n, max_ix_shuffle, max_iy);
  const v_int32x4 ramp(0, DX, 2 * DX, 3 * DX);
  const v_int32x4 rampy(0, DY, 2 * DY, 3 * DY);
  const v_int32x4 dx4 = v_setall_s32(4 * DX), dy4 = v_setall_s32(4 * DY);
  const v_int32x4 m31 = v_setall_s32(kInterTabSize - 1);
  // fy, 64 times, from Y in one shift: Y >> (kScanFrac - 6), masked.
  const v_int32x4 m31x64 = v_setall_s32((kInterTabSize - 1) << 6);
  const v_int32x4 k32 = v_setall_s32(kInterTabSize);
  const v_int32x4 k32x64 = v_setall_s32(kInterTabSize << 6);
  const v_uint16x8 k255 = v_setall_u16(255);
  const v_int32x4 half = v_setall_s32(1 << 15);
  const v_uint8x16 pix_a = v_load(kColor3Shuffle.pair_pixel_byte[0]);
  const v_uint8x16 pix_b = v_load(kColor3Shuffle.pair_pixel_byte[1]);
  const v_uint8x16 off_a = v_load(kColor3Shuffle.pair_offset[0]);
  const v_uint8x16 off_b = v_load(kColor3Shuffle.pair_offset[1]);
  const v_uint8x16 wsel_a = v_load(kColor3Shuffle.pair_weight_byte[0]);
  const v_uint8x16 wsel_b = v_load(kColor3Shuffle.pair_weight_byte[1]);
  const v_uint8x16 word0 = v_load(kColor3Shuffle.pixel_word[0]);
  const v_uint8x16 word1 = v_load(kColor3Shuffle.pixel_word[1]);
  const v_uint8x16 word2 = v_load(kColor3Shuffle.pixel_word[2]);
  const v_uint8x16 out0 = v_load(kColor3Shuffle.output_byte[0]);
  const v_uint8x16 out1 = v_load(kColor3Shuffle.output_byte[1]);
  const v_uint8x16 out2 = v_load(kColor3Shuffle.output_byte[2]);
  int64_t shuffled = 0, portable = 0, scalar = 0;
  int32_t X = X0, Y = Y0;
  // The group's 4 coordinates, stepped like X and Y.
  v_int32x4 Xv = v_setall_s32(X0) + ramp, Yv = v_setall_s32(Y0) + rampy;
  for (int g = 0; g < n;
       g += 4, X += 4 * DX, Y += 4 * DY, Xv += dx4, Yv += dy4) {
    if (g + 4 > n) {  // overlapping last group, as in SampleRow
      g = n - 4;
      X = X0 + g * DX;
      Y = Y0 + g * DY;
      Xv = v_setall_s32(X) + ramp;
      Yv = v_setall_s32(Y) + rampy;
    }
    const int u = u0 + g;
    const int ix0 = X >> shift, iy0 = Y >> shift;
    const int iy3 = (Y + 3 * DY) >> shift;
    uchar* dst = out + u * 3;
    if (iy0 != iy3 ||
        (!whole &&
         (static_cast<unsigned>(((X + 3 * DX) >> shift) - ix0) > 3u ||
          ix0 < 0 || ix0 > max_ix_shuffle || iy0 < 0 || iy0 > max_iy))) {
      if (GroupInside(X, Y, DX, DY, 4, max_ix_portable, max_iy)) {
        Color4<3>(base, step, Xv, Yv, u + 6 <= width, dst);
        portable += 4;
      } else {
        for (int k = 0; k < 4; ++k) {
          SamplePixel(in, 3, (X + k * DX) >> kScanFrac,
                      (Y + k * DY) >> kScanFrac, dst + 3 * k);
        }
        scalar += 4;
      }
      continue;
    }
    const uchar* p = base + static_cast<size_t>(iy0) * step + ix0 * 3;
    const v_uint8x16 top = v_load(p);
    const v_uint8x16 bottom = v_load(p + step);
    // Each pixel's byte offset from pixel ix0 (0..9), and its weights, one
    // 32-bit lane per pixel (adds and 16-bit multiplies rather than shifts:
    // shifts share the shuffles' ports).
    const v_int32x4 rel = v_shr<shift>(Xv) - v_setall_s32(ix0);
    const v_uint8x16 off = v_reinterpret_as_u8(rel + rel + rel);
    const v_int32x4 fx = v_shr<kScanFrac>(Xv) & m31;
    // Bytes (32 - fx, fx): 32 + 255 fx (fx < 32: the high 16 bits stay 0).
    const v_uint8x16 wx = v_reinterpret_as_u8(
        k32 + v_reinterpret_as_s32(v_mul_wrap(v_reinterpret_as_u16(fx), k255)));
    const v_int32x4 fy64 = v_shr<kScanFrac - 6>(Yv) & m31x64;
    // 16-bit halves (64 (32 - fy), 64 fy).
    const v_uint8x16 wy =
        v_reinterpret_as_u8((k32x64 - fy64) | v_shl<16>(fy64));
    // Horizontal step, per row and pair.
    const v_uint8x16 idx_a = ShuffleBytes(off, pix_a) + off_a;
    const v_uint8x16 idx_b = ShuffleBytes(off, pix_b) + off_b;
    const v_uint8x16 w_a = ShuffleBytes(wx, wsel_a);
    const v_uint8x16 w_b = ShuffleBytes(wx, wsel_b);
    const v_int16x8 top_a = MulAddPairs(ShuffleBytes(top, idx_a), w_a);
    const v_int16x8 top_b = MulAddPairs(ShuffleBytes(top, idx_b), w_b);
    const v_int16x8 bot_a = MulAddPairs(ShuffleBytes(bottom, idx_a), w_a);
    const v_int16x8 bot_b = MulAddPairs(ShuffleBytes(bottom, idx_b), w_b);
    // Vertical step: (top, bottom) per pair, P = 0-3, 4-7, 8-11; rounded,
    // and the result byte picked out.
    v_int16x8 z0, z1, z2, unused;
    v_zip(top_a, bot_a, z0, z1);
    v_zip(top_b, bot_b, z2, unused);
    const v_int32x4 h0 =
        v_dotprod(z0, v_reinterpret_as_s16(ShuffleBytes(wy, word0))) + half;
    const v_int32x4 h1 =
        v_dotprod(z1, v_reinterpret_as_s16(ShuffleBytes(wy, word1))) + half;
    const v_int32x4 h2 =
        v_dotprod(z2, v_reinterpret_as_s16(ShuffleBytes(wy, word2))) + half;
    const v_uint8x16 r = ShuffleBytes(v_reinterpret_as_u8(h0), out0) |
                         ShuffleBytes(v_reinterpret_as_u8(h1), out1) |
                         ShuffleBytes(v_reinterpret_as_u8(h2), out2);
    if (u + 6 <= width) {
      v_store(dst, r);  // bytes 12-15 (zero): the next pixels', written later
    } else {
      v_store_low(dst, r);
      const unsigned tail = v_extract_n<2>(v_reinterpret_as_u32(r));
      std::memcpy(dst + 8, &tail, 4);
    }
    shuffled += 4;
  }
  counts->shuffle_px += shuffled;
  counts->portable_simd_px += portable;
  counts->scalar_px += scalar;
}
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
  const int n = seg.u1 - seg.u0 + 1;
  if (n < 8) {
    int32_t X = seg.X, Y = seg.Y;
    for (int u = seg.u0; u <= seg.u1; ++u, X += seg.DX, Y += seg.DY) {
      SamplePixel(in, 1, X >> kScanFrac, Y >> kScanFrac, out + u);
    }
    counts->scalar_px += n;
    return;
  }
  // Locals, not seg's fields (the output stores may alias seg).
  const int32_t X0 = seg.X, Y0 = seg.Y, DX = seg.DX, DY = seg.DY;
  const int u0 = seg.u0;
  const int max_iy = in.rows - 2;
  // A 16-byte load at pixel ix0 stays in its row for ix0 <= cols - 16.
  const int max_ix_shuffle = in.cols - 16;
  // The whole segment within the margins and 0 <= 7 DX <= 14 px: only the
  // source row is checked per group.
  const bool whole = DX >= 0 && 7 * static_cast<int64_t>(DX) <= (14 << shift) &&
                     GroupInside(X0, Y0, DX, DY, n, max_ix_shuffle, max_iy);
  const v_int32x4 ramp(0, DX, 2 * DX, 3 * DX);
  const v_int32x4 rampy(0, DY, 2 * DY, 3 * DY);
  const v_int32x4 dx4 = v_setall_s32(4 * DX), dy4 = v_setall_s32(4 * DY);
  const v_int32x4 dx8 = v_setall_s32(8 * DX), dy8 = v_setall_s32(8 * DY);
  const v_int32x4 m31 = v_setall_s32(kInterTabSize - 1);
  const v_int32x4 m31x64 = v_setall_s32((kInterTabSize - 1) << 6);
  const v_int32x4 k32 = v_setall_s32(kInterTabSize);
  const v_int32x4 k32x64 = v_setall_s32(kInterTabSize << 6);
  const v_uint16x8 k255 = v_setall_u16(255);
  const v_int32x4 half = v_setall_s32(1 << 15);
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
  const v_uint8x16 pair_low = v_load(kPairLow);
  const v_uint8x16 left_right = v_load(kLeftRight);
  const v_uint8x16 out0 = v_load(kOut0), out1 = v_load(kOut1);
  int64_t shuffled = 0, portable = 0, scalar = 0;
  int32_t X = X0, Y = Y0;
  v_int32x4 Xa = v_setall_s32(X0) + ramp, Ya = v_setall_s32(Y0) + rampy;
  for (int g = 0; g < n;
       g += 8, X += 8 * DX, Y += 8 * DY, Xa += dx8, Ya += dy8) {
    if (g + 8 > n) {  // overlapping last group, as in SampleRow
      g = n - 8;
      X = X0 + g * DX;
      Y = Y0 + g * DY;
      Xa = v_setall_s32(X) + ramp;
      Ya = v_setall_s32(Y) + rampy;
    }
    const int u = u0 + g;
    const int ix0 = X >> shift, iy0 = Y >> shift;
    const int iy7 = (Y + 7 * DY) >> shift;
    const v_int32x4 Xb = Xa + dx4, Yb = Ya + dy4;
    if (iy0 != iy7 ||
        (!whole &&
         (static_cast<unsigned>(((X + 7 * DX) >> shift) - ix0) > 14u ||
          ix0 < 0 || ix0 > max_ix_shuffle || iy0 < 0 || iy0 > max_iy))) {
      if (GroupInside(X, Y, DX, DY, 8, in.cols - 2, max_iy)) {
        Mono8(base, step, Xa, Xb, Ya, Yb, out + u);
        portable += 8;
      } else {
        for (int k = 0; k < 8; ++k) {
          SamplePixel(in, 1, (X + k * DX) >> kScanFrac,
                      (Y + k * DY) >> kScanFrac, out + u + k);
        }
        scalar += 8;
      }
      continue;
    }
    const uchar* p = base + static_cast<size_t>(iy0) * step + ix0;
    const v_uint8x16 top = v_load(p);
    const v_uint8x16 bottom = v_load(p + step);
    // Offsets from ix0 (0..14) and horizontal weight bytes (32 - fx, fx)
    // = 32 + 255 fx, one 16-bit lane per pixel.
    const v_int32x4 col0 = v_setall_s32(ix0);
    const v_uint8x16 rel = v_reinterpret_as_u8(
        v_pack(v_shr<shift>(Xa) - col0, v_shr<shift>(Xb) - col0));
    const v_int32x4 fxa = v_shr<kScanFrac>(Xa) & m31;
    const v_int32x4 fxb = v_shr<kScanFrac>(Xb) & m31;
    const v_uint8x16 wx = v_reinterpret_as_u8(v_pack(
        k32 + v_reinterpret_as_s32(v_mul_wrap(v_reinterpret_as_u16(fxa), k255)),
        k32 +
            v_reinterpret_as_s32(v_mul_wrap(v_reinterpret_as_u16(fxb), k255))));
    const v_uint8x16 idx = ShuffleBytes(rel, pair_low) + left_right;
    const v_int16x8 t = MulAddPairs(ShuffleBytes(top, idx), wx);
    const v_int16x8 b = MulAddPairs(ShuffleBytes(bottom, idx), wx);
    // Vertical step with 64 ((32 - fy), fy) per 32-bit lane (pixel).
    const v_int32x4 fya = v_shr<kScanFrac - 6>(Ya) & m31x64;
    const v_int32x4 fyb = v_shr<kScanFrac - 6>(Yb) & m31x64;
    const v_int16x8 wya = v_reinterpret_as_s16((k32x64 - fya) | v_shl<16>(fya));
    const v_int16x8 wyb = v_reinterpret_as_s16((k32x64 - fyb) | v_shl<16>(fyb));
    v_int16x8 z0, z1;
    v_zip(t, b, z0, z1);
    const v_int32x4 h0 = v_dotprod(z0, wya) + half;
    const v_int32x4 h1 = v_dotprod(z1, wyb) + half;
    v_store_low(out + u, ShuffleBytes(v_reinterpret_as_u8(h0), out0) |
                             ShuffleBytes(v_reinterpret_as_u8(h1), out1));
    shuffled += 8;
  }
  counts->shuffle_px += shuffled;
  counts->portable_simd_px += portable;
  counts->scalar_px += scalar;
}
#endif  // STEADIFACE_SHUFFLE_KERNEL

// One output row. `shuffle`: 3-channel stepped segments go through the
// shuffle kernel (only where ShuffleSupported()).
void SampleRow(const WarpMesh& m, const cv::Mat& in, int width, int v,
               bool shuffle, std::vector<Eigen::Vector2f>* line, uchar* out,
               SampleStats* counts) {
  const int cn = in.channels();
  const uchar* base = in.ptr<uchar>(0);
  const size_t step = in.step[0];
  (void)shuffle;
  ForEachScanSegment(m, width, v, line, [&](const ScanSegment& seg) {
    int u = seg.u0;
    if (!seg.stepped) {
      for (; u <= seg.u1; ++u) {
        int32_t X, Y;
        ClampedScanCoordinates(seg, u, &X, &Y);
        SamplePixel(in, cn, X, Y, out + u * cn);
      }
      counts->scalar_px += seg.u1 - seg.u0 + 1;
      return;
    }
#ifdef STEADIFACE_SHUFFLE_KERNEL
    if (shuffle && cn == 3) {
      Color3SegmentShuffle(seg, in, width, out, counts);
      return;
    }
    if (shuffle && cn == 1) {
      Mono8SegmentShuffle(seg, in, out, counts);
      return;
    }
#endif
    int32_t X = seg.X, Y = seg.Y;
#if CV_SIMD128
    const int max_iy = in.rows - 2;
    if (cn == 1) {
      const cv::v_int32x4 ramp(0, seg.DX, 2 * seg.DX, 3 * seg.DX);
      const cv::v_int32x4 rampy(0, seg.DY, 2 * seg.DY, 3 * seg.DY);
      const cv::v_int32x4 dx4 = cv::v_setall_s32(4 * seg.DX);
      const cv::v_int32x4 dy4 = cv::v_setall_s32(4 * seg.DY);
      const int n = seg.u1 - seg.u0 + 1;
      // The whole segment inside: no per-group check.
      const bool inside =
          GroupInside(seg.X, seg.Y, seg.DX, seg.DY, n, in.cols - 2, max_iy);
      for (int g = 0; n >= 8 && g < n; g += 8) {
        // The last group overlaps the previous one rather than leave a
        // scalar tail (it rewrites the same values).
        if (g + 8 > n) g = n - 8;
        u = seg.u0 + g;
        X = seg.X + g * seg.DX;
        Y = seg.Y + g * seg.DY;
        if (!inside &&
            !GroupInside(X, Y, seg.DX, seg.DY, 8, in.cols - 2, max_iy)) {
          for (int k = 0; k < 8; ++k) {
            SamplePixel(in, 1, (X + k * seg.DX) >> kScanFrac,
                        (Y + k * seg.DY) >> kScanFrac, out + u + k);
          }
          counts->scalar_px += 8;
          continue;
        }
        const cv::v_int32x4 Xa = cv::v_setall_s32(X) + ramp;
        const cv::v_int32x4 Ya = cv::v_setall_s32(Y) + rampy;
        Mono8(base, step, Xa, Xa + dx4, Ya, Ya + dy4, out + u);
        counts->portable_simd_px += 8;
      }
      if (n >= 8) return;
    } else if (cn == 3 || cn == 4) {
      const cv::v_int32x4 ramp(0, seg.DX, 2 * seg.DX, 3 * seg.DX);
      const cv::v_int32x4 rampy(0, seg.DY, 2 * seg.DY, 3 * seg.DY);
      // The 8-byte read of a 3-channel pixel ends two bytes past its right
      // neighbour: keep one more column of margin there.
      const int max_ix = cn == 3 ? in.cols - 3 : in.cols - 2;
      const int n = seg.u1 - seg.u0 + 1;
      const bool inside =
          GroupInside(seg.X, seg.Y, seg.DX, seg.DY, n, max_ix, max_iy);
      for (int g = 0; n >= 4 && g < n; g += 4) {
        if (g + 4 > n) g = n - 4;  // overlapping last group, as above
        u = seg.u0 + g;
        X = seg.X + g * seg.DX;
        Y = seg.Y + g * seg.DY;
        if (!inside && !GroupInside(X, Y, seg.DX, seg.DY, 4, max_ix, max_iy)) {
          for (int k = 0; k < 4; ++k) {
            SamplePixel(in, cn, (X + k * seg.DX) >> kScanFrac,
                        (Y + k * seg.DY) >> kScanFrac, out + (u + k) * cn);
          }
          counts->scalar_px += 4;
          continue;
        }
        counts->portable_simd_px += 4;
        const cv::v_int32x4 Xv = cv::v_setall_s32(X) + ramp;
        const cv::v_int32x4 Yv = cv::v_setall_s32(Y) + rampy;
        if (cn == 3) {
          Color4<3>(base, step, Xv, Yv, u + 6 <= width, out + u * 3);
        } else {
          Color4<4>(base, step, Xv, Yv, false, out + u * 4);
        }
      }
      if (n >= 4) return;
    }
#endif  // CV_SIMD128
    counts->scalar_px += seg.u1 - u + 1;
    for (; u <= seg.u1; ++u, X += seg.DX, Y += seg.DY) {
      SamplePixel(in, cn, X >> kScanFrac, Y >> kScanFrac, out + u * cn);
    }
  });
}

}  // namespace

bool ShuffleKernelAvailable() {
  // Asked once: the answer does not change while the process runs.
  static const bool available = ShuffleSupported();
  return available;
}

void SampleMesh(const WarpMesh& mesh, const cv::Mat& input, int width,
                int height, cv::Mat* output, SampleKernel kernel,
                SampleStats* stats) {
  output->create(height, width, input.type());
  cv::Mat& out = *output;
  const bool shuffle =
      kernel == SampleKernel::kAuto && ShuffleKernelAvailable();
  std::atomic<int64_t> shuffle_px{0}, simd_px{0}, scalar_px{0};
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    std::vector<Eigen::Vector2f> line;
    SampleStats counts;
    for (int v = range.start; v < range.end; ++v) {
      SampleRow(mesh, input, width, v, shuffle, &line, out.ptr<uchar>(v),
                &counts);
    }
    shuffle_px += counts.shuffle_px;
    simd_px += counts.portable_simd_px;
    scalar_px += counts.scalar_px;
  });
  if (stats != nullptr) {
    stats->shuffle_px = shuffle_px;
    stats->portable_simd_px = simd_px;
    stats->scalar_px = scalar_px;
  }
}

}  // namespace steadiface
