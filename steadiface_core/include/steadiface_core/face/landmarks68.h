#pragma once

namespace steadiface {

/// The iBUG 300-W 68-point layout that dlib's predictor gives, by name.
/// "Right" and "left" are the person's: their right eye is on the image's
/// left. Ranges are inclusive.
namespace landmarks68 {

constexpr int kCount = 68;

constexpr int kJawFirst = 0, kJawLast = 16;  ///< the jaw line, right end to left end
constexpr int kJawRightEnd = 0, kJawLeftEnd = 16;
constexpr int kChin = 8;
constexpr int kBrowFirst = 17, kBrowLast = 26;  ///< right brow 17-21, left 22-26
constexpr int kNoseBridgeTop = 27;              ///< the bridge 27-30
constexpr int kNoseTip = 30;
constexpr int kNostrilFirst = 31, kNostrilLast = 35;  ///< the nose's base, right to left
constexpr int kRightEyeFirst = 36, kRightEyeLast = 41;
constexpr int kLeftEyeFirst = 42, kLeftEyeLast = 47;
constexpr int kRightEyeOuter = 36, kLeftEyeOuter = 45;
constexpr int kMouthFirst = 48, kMouthLast = 59;  ///< the outer lip line
constexpr int kMouthRight = 48, kMouthLeft = 54;  ///< the mouth's corners
constexpr int kLowerLipBottom = 57;

}  // namespace landmarks68
}  // namespace steadiface
