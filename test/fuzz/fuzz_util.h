#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

// Reads typed values from the fuzzer's bytes; past the end everything is 0.
class FuzzInput {
 public:
  FuzzInput(const uint8_t* data, size_t size) : d_(data), n_(size) {}
  template <typename T>
  T Get() {
    T v{};
    if (p_ + sizeof(T) <= n_) {
      std::memcpy(&v, d_ + p_, sizeof(T));
      p_ += sizeof(T);
    } else {
      p_ = n_;
    }
    return v;
  }
  uint8_t Byte() { return Get<uint8_t>(); }
  // A double that is usually in [lo, hi] but sometimes NaN, Inf, huge.
  double Double(double lo, double hi) {
    const uint8_t kind = Byte();
    const double u = static_cast<double>(Get<uint16_t>()) / 65535.0;
    switch (kind % 16) {
      case 0: return std::numeric_limits<double>::quiet_NaN();
      case 1: return std::numeric_limits<double>::infinity();
      case 2: return -1e300;
      case 3: return Get<double>();
      default: return lo + (hi - lo) * u;
    }
  }
  bool done() const { return p_ >= n_; }
  size_t remaining() const { return n_ - p_; }
  const uint8_t* data() const { return d_ + p_; }

 private:
  const uint8_t* d_;
  size_t n_;
  size_t p_ = 0;
};
