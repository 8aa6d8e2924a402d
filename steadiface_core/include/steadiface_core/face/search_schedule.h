#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "steadiface_core/common/time.h"

namespace steadiface {

/// One face search: the region of the frame the detector sees, and the
/// scale of its copy (0: the detector's own downscale to max_side_px).
struct SearchStep {
  cv::Rect roi;
  double scale = 0.0;
};

/// Where and when the face search looks while no face is locked, so that
/// a frame with nobody in view never costs more than one detector pass of
/// about max_side_px x 3/4 max_side_px.
///
/// The whole frame, at the detector's own downscale, is searched once per
/// `interval_s`, as it always was; it finds faces from window_px / s0 wide
/// (s0 = max_side_px / the longer side: 160 px at 1280x720 with dlib's
/// 75 px window). Smaller faces, down to min_face_px, are searched for in
/// tiles of the frame upsampled by levels, each at most 2.5x the one above
/// so that their ranges overlap, the tiles of a level overlapping by more
/// than the largest face it is responsible for: one tile half an interval
/// after each whole-frame search, coarse levels first and, within a level,
/// the tile nearest the image centre first. A 640x480 frame with dlib and
/// min_face_px 30 has one level (x2.5, 16 tiles), so a face at the centre
/// is found within the first interval and one anywhere within 16. With
/// interval_s 0 the whole frame and the tiles alternate frame by frame.
class SearchSchedule {
 public:
  SearchSchedule(const cv::Size& image, int max_side_px, double window_px,
                 int min_face_px, double interval_s);

  /// Whether a search runs on the frame at `stamp`, and if so, `step`.
  bool Due(Time stamp, SearchStep* step);
  /// The next search is the whole frame, at once (after a reset).
  void Restart() { have_whole_ = false; }

  const SearchStep& whole() const { return whole_; }
  const std::vector<SearchStep>& tiles() const { return tiles_; }

 private:
  SearchStep whole_;
  std::vector<SearchStep> tiles_;
  double interval_s_ = 0.0;
  size_t next_tile_ = 0;
  bool have_whole_ = false;  // a whole-frame search since Restart()
  bool last_was_whole_ = false;
  Time last_whole_, last_step_;
};

}  // namespace steadiface
