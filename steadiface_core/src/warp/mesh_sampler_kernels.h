#pragma once

// The portable warp kernels (internal to mesh_sampler*.cc; not API): one pixel at a
// time, and 8 mono8 or 4 colour pixels in OpenCV's universal intrinsics.
// The shuffle kernels (mesh_sampler_shuffle.cc) fall back to these.

#include <cstdint>
#include <cstring>

#include <opencv2/core.hpp>
#include <opencv2/core/hal/intrin.hpp>

#include "warp/mesh_scanline.h"

namespace steadiface {
namespace mesh_sampler_internal {

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

// `count` pixels of a stepped segment from (X, Y) (1/32 px, kScanFrac guard
// bits; step DX, DY per pixel), one at a time: groups that run off the
// input and segments too short for a group.
inline void SamplePixels(const cv::Mat& in, int cn, int32_t X, int32_t Y,
                         int32_t DX, int32_t DY, int count, uchar* out) {
  for (int k = 0; k < count; ++k, X += DX, Y += DY) {
    SamplePixel(in, cn, X >> kScanFrac, Y >> kScanFrac, out + k * cn);
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
  const cv::v_int32x4 m31 = cv::v_setall_s32(kInterTabSize - 1);
  const cv::v_int32x4 k32 = cv::v_setall_s32(kInterTabSize);
  int ix[8], iy[8];
  cv::v_store(ix, cv::v_shr<kScanFrac + kInterBits>(Xa));
  cv::v_store(ix + 4, cv::v_shr<kScanFrac + kInterBits>(Xb));
  cv::v_store(iy, cv::v_shr<kScanFrac + kInterBits>(Ya));
  cv::v_store(iy + 4, cv::v_shr<kScanFrac + kInterBits>(Yb));
  // Vectors built from registers (no store-to-load round trip).
  const uchar* p[8];
  for (int k = 0; k < 8; ++k)
    p[k] = base + static_cast<size_t>(iy[k]) * step + ix[k];
  const cv::v_uint16x8 T(Load16(p[0]), Load16(p[1]), Load16(p[2]), Load16(p[3]),
                         Load16(p[4]), Load16(p[5]), Load16(p[6]),
                         Load16(p[7]));
  const cv::v_uint16x8 B(Load16(p[0] + step), Load16(p[1] + step),
                         Load16(p[2] + step), Load16(p[3] + step),
                         Load16(p[4] + step), Load16(p[5] + step),
                         Load16(p[6] + step), Load16(p[7] + step));
  const cv::v_uint16x8 lo8 = cv::v_setall_u16(0xFF);
  const cv::v_int32x4 fxa = cv::v_shr<kScanFrac>(Xa) & m31,
                      fxb = cv::v_shr<kScanFrac>(Xb) & m31;
  const cv::v_int32x4 fya = cv::v_shr<kScanFrac>(Ya) & m31,
                      fyb = cv::v_shr<kScanFrac>(Yb) & m31;
  const cv::v_uint16x8 fx = cv::v_reinterpret_as_u16(cv::v_pack(fxa, fxb));
  const cv::v_uint16x8 gx = cv::v_setall_u16(kInterTabSize) - fx;
  // Horizontal step, exact in 16 bits (<= 255 * 32).
  const cv::v_uint16x8 ht =
      cv::v_mul_wrap(T & lo8, gx) + cv::v_mul_wrap(cv::v_shr<8>(T), fx);
  const cv::v_uint16x8 hb =
      cv::v_mul_wrap(B & lo8, gx) + cv::v_mul_wrap(cv::v_shr<8>(B), fx);
  cv::v_int16x8 z0, z1;
  cv::v_zip(cv::v_reinterpret_as_s16(ht), cv::v_reinterpret_as_s16(hb), z0, z1);
  const cv::v_int32x4 wya = (k32 - fya) | cv::v_shl<16>(fya);
  const cv::v_int32x4 wyb = (k32 - fyb) | cv::v_shl<16>(fyb);
  const cv::v_int16x8 r =
      cv::v_rshr_pack<kWeightShift>(Vertical(z0, wya), Vertical(z1, wyb));
  cv::v_pack_u_store(out, r);
}

// 3 or 4 channels: 4 pixels of a stepped segment. `wide`: 3 channels may
// store 16 bytes (the 4 bytes past the group are the next pixels', which
// the row's later groups or segments write afterwards).
template <int CN>
inline void Color4(const uchar* base, size_t step, const cv::v_int32x4& X,
                   const cv::v_int32x4& Y, bool wide, uchar* out) {
  const cv::v_int32x4 m31 = cv::v_setall_s32(kInterTabSize - 1);
  const cv::v_int32x4 k32 = cv::v_setall_s32(kInterTabSize);
  int ix[4], iy[4];
  cv::v_store(ix, cv::v_shr<kScanFrac + kInterBits>(X));
  cv::v_store(iy, cv::v_shr<kScanFrac + kInterBits>(Y));
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
  cv::v_uint16x8 a0, a1, b0, b1, c0, c1, d0,
      d1;  // [pixel 0 | pixel 1], [2 | 3]
  cv::v_expand(cv::v_reinterpret_as_u8(
                   cv::v_uint32x4(lo(t[0]), lo(t[1]), lo(t[2]), lo(t[3]))),
               a0, a1);
  cv::v_expand(cv::v_reinterpret_as_u8(
                   cv::v_uint32x4(hi(t[0]), hi(t[1]), hi(t[2]), hi(t[3]))),
               b0, b1);
  cv::v_expand(cv::v_reinterpret_as_u8(
                   cv::v_uint32x4(lo(b[0]), lo(b[1]), lo(b[2]), lo(b[3]))),
               c0, c1);
  cv::v_expand(cv::v_reinterpret_as_u8(
                   cv::v_uint32x4(hi(b[0]), hi(b[1]), hi(b[2]), hi(b[3]))),
               d0, d1);
  // fx of each pixel in all 4 of its 16-bit lanes.
  const cv::v_int32x4 fx = cv::v_shr<kScanFrac>(X) & m31;
  const cv::v_uint32x4 fx2 = cv::v_reinterpret_as_u32(fx | cv::v_shl<16>(fx));
  cv::v_uint32x4 f01, f23;
  cv::v_zip(fx2, fx2, f01, f23);
  const cv::v_uint16x8 fx0 = cv::v_reinterpret_as_u16(f01),
                       fx1 = cv::v_reinterpret_as_u16(f23);
  const cv::v_uint16x8 gx0 = cv::v_setall_u16(kInterTabSize) - fx0;
  const cv::v_uint16x8 gx1 = cv::v_setall_u16(kInterTabSize) - fx1;
  // Horizontal step, exact in 16 bits (<= 255 * 32).
  const cv::v_uint16x8 ht0 = cv::v_mul_wrap(a0, gx0) + cv::v_mul_wrap(b0, fx0);
  const cv::v_uint16x8 ht1 = cv::v_mul_wrap(a1, gx1) + cv::v_mul_wrap(b1, fx1);
  const cv::v_uint16x8 hb0 = cv::v_mul_wrap(c0, gx0) + cv::v_mul_wrap(d0, fx0);
  const cv::v_uint16x8 hb1 = cv::v_mul_wrap(c1, gx1) + cv::v_mul_wrap(d1, fx1);
  cv::v_int16x8 p0, p1, p2, p3;  // per pixel: (top, bottom) per channel
  cv::v_zip(cv::v_reinterpret_as_s16(ht0), cv::v_reinterpret_as_s16(hb0), p0,
            p1);
  cv::v_zip(cv::v_reinterpret_as_s16(ht1), cv::v_reinterpret_as_s16(hb1), p2,
            p3);
  const cv::v_int32x4 fy = cv::v_shr<kScanFrac>(Y) & m31;
  const cv::v_int32x4 wy = (k32 - fy) | cv::v_shl<16>(fy);
  const cv::v_int16x8 r01 = cv::v_rshr_pack<kWeightShift>(
      Vertical(p0, cv::v_broadcast_element<0>(wy)),
      Vertical(p1, cv::v_broadcast_element<1>(wy)));
  const cv::v_int16x8 r23 = cv::v_rshr_pack<kWeightShift>(
      Vertical(p2, cv::v_broadcast_element<2>(wy)),
      Vertical(p3, cv::v_broadcast_element<3>(wy)));
  const cv::v_uint8x16 r = cv::v_pack_u(r01, r23);
  if (CN == 4) {
    cv::v_store(out, r);
  } else if (wide) {
    cv::v_store(out, cv::v_pack_triplets(r));
  } else {
    // 12 bytes, straight from the register (no round trip through memory).
    const cv::v_uint8x16 packed = cv::v_pack_triplets(r);
    cv::v_store_low(out, packed);
    const unsigned tail = cv::v_extract_n<2>(cv::v_reinterpret_as_u32(packed));
    std::memcpy(out + 8, &tail, 4);
  }
}
#endif  // CV_SIMD128

}  // namespace mesh_sampler_internal
}  // namespace steadiface
