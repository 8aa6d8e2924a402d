#include "steadiface_core/face/search_schedule.h"

#include <algorithm>
#include <cmath>

namespace steadiface {
namespace {

// Start positions of `n` windows of `win` covering [0, len), evenly spaced.
std::vector<double> Starts(double len, double win, double overlap) {
  if (len <= win) return {0.0};
  const double stride = std::max(win - overlap, 0.5 * win);
  const int n = static_cast<int>(std::ceil((len - win) / stride)) + 1;
  std::vector<double> s(n);
  for (int i = 0; i < n; ++i) s[i] = (len - win) * i / (n - 1);
  return s;
}

// The tiles of the frame at `scale`: windows of tile_w x tile_h copy pixels
// overlapping by `overlap`, as source rectangles, centre first.
std::vector<SearchStep> Level(const cv::Size& image, double scale,
                              double tile_w, double tile_h, double overlap) {
  std::vector<SearchStep> level;
  const cv::Rect full(0, 0, image.width, image.height);
  for (double y : Starts(image.height * scale, tile_h, overlap)) {
    for (double x : Starts(image.width * scale, tile_w, overlap)) {
      const int x0 = static_cast<int>(std::floor(x / scale));
      const int y0 = static_cast<int>(std::floor(y / scale));
      const int x1 = static_cast<int>(std::ceil((x + tile_w) / scale));
      const int y1 = static_cast<int>(std::ceil((y + tile_h) / scale));
      SearchStep t;
      t.roi = cv::Rect(x0, y0, x1 - x0, y1 - y0) & full;
      t.scale = scale;
      if (t.roi.area() > 0) level.push_back(t);
    }
  }
  const cv::Point2d c(0.5 * image.width, 0.5 * image.height);
  auto dist = [&](const SearchStep& t) {
    const cv::Point2d d(t.roi.x + 0.5 * t.roi.width - c.x,
                        t.roi.y + 0.5 * t.roi.height - c.y);
    return d.dot(d);
  };
  std::stable_sort(level.begin(), level.end(),
                   [&](const SearchStep& a, const SearchStep& b) {
                     return dist(a) < dist(b);
                   });
  return level;
}

}  // namespace

SearchSchedule::SearchSchedule(const cv::Size& image, int max_side_px,
                               double window_px, int min_face_px,
                               double interval_s)
    : interval_s_(std::max(0.0, interval_s)) {
  whole_.roi = cv::Rect(0, 0, image.width, image.height);
  whole_.scale = 0.0;
  const int longest = std::max(image.width, image.height);
  if (longest <= 0 || max_side_px <= 0 || !(window_px > 0.0) ||
      min_face_px <= 0)
    return;
  // Each level is at most kStep x the one above; a face at the upper end of
  // a level's range (the level above's smallest) is then at most
  // kStep x window_px wide in its copy, and the tiles overlap by more.
  constexpr double kStep = 2.5;
  const double overlap = 1.1 * kStep * window_px;
  const double tile_w = max_side_px;
  const double tile_h = 0.75 * max_side_px;
  double s = std::min(1.0, static_cast<double>(max_side_px) / longest);
  const double s_max = window_px / min_face_px;
  while (s < s_max - 1e-9) {
    s = std::min(kStep * s, s_max);
    const std::vector<SearchStep> level =
        Level(image, s, tile_w, tile_h, overlap);
    tiles_.insert(tiles_.end(), level.begin(), level.end());
  }
}

bool SearchSchedule::Due(Time stamp, SearchStep* step) {
  // 1 ms of slack for frame-time jitter; a time jump backwards searches the
  // whole frame at once.
  constexpr double kSlack = 1e-3;
  const bool whole_due = !have_whole_ || stamp < last_whole_ ||
                         ToSeconds(stamp - last_whole_) >= interval_s_ - kSlack;
  bool tile_due = false;
  if (!tiles_.empty() && have_whole_ && stamp >= last_step_) {
    tile_due = interval_s_ > 0.0
                   ? ToSeconds(stamp - last_step_) >= 0.5 * interval_s_ - kSlack
                   : last_was_whole_;
  }
  if (whole_due && !(interval_s_ == 0.0 && tile_due)) {
    *step = whole_;
    have_whole_ = true;
    last_whole_ = last_step_ = stamp;
    last_was_whole_ = true;
    return true;
  }
  if (!tile_due) return false;
  *step = tiles_[next_tile_++ % tiles_.size()];
  last_step_ = stamp;
  last_was_whole_ = false;
  return true;
}

}  // namespace steadiface
