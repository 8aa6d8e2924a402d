#pragma once

// jpeg/png decoding for FromCompressedImage, in a module
// (libsteadiface_image_decoder.so, beside libsteadiface_ros.so) loaded on
// first use. OpenCV's imgcodecs links GDAL and ~110 other libraries; linked
// into steadiface_ros they loaded at the start of every program that uses
// it, compressed images or not (~65 ms of each steadiface_bag run here).

#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace steadiface_ros {

/// Loads the module now (a node that subscribes to compressed images does
/// so at start-up, not on its first frame). False, with `why`, if it cannot
/// be loaded. Thread-safe; the module is loaded once per process.
bool LoadImageDecoder(std::string* why);

/// Decodes a jpeg or png payload as cv::imdecode(..., IMREAD_UNCHANGED)
/// does. False, with `why`, when the module cannot be loaded or the payload
/// does not decode. Thread-safe.
bool DecodeImage(const uint8_t* data, size_t size, cv::Mat* out,
                 std::string* why);

}  // namespace steadiface_ros
