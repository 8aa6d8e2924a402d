#include "steadiface_core/sim/truth_file.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "steadiface_core/common/command_line.h"

namespace steadiface {
namespace sim {
namespace {

constexpr char kMagic[] = "# steadiface truth v1";
constexpr int kRows = 16;

// "key=value" words after the magic; values hold no spaces (paths with
// spaces are written with %20).
std::string Escape(const std::string& s) {
  std::string out;
  for (char c : s) out += c == ' ' ? std::string("%20") : std::string(1, c);
  return out;
}
std::string Unescape(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s.compare(i, 3, "%20") == 0) {
      out += ' ';
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

Status ParseSettings(const std::string& line, SimulationSettings* s) {
  std::istringstream words(line.substr(sizeof(kMagic) - 1));
  std::string word;
  SimulatorOptions& b = s->base;
  while (words >> word) {
    const size_t eq = word.find('=');
    if (eq == std::string::npos) return Status::Error("truth file: bad setting '" + word + "'");
    const std::string k = word.substr(0, eq), v = Unescape(word.substr(eq + 1));
    bool ok = true;
    int face = 1;
    if (k == "preset") s->preset = v;
    else if (k == "data") s->data_dir = v;
    else if (k == "background") b.background_photo = v;
    else if (k == "width") ok = ParseInt(v, &b.width);
    else if (k == "height") ok = ParseInt(v, &b.height);
    else if (k == "fps") ok = ParseDouble(v, &b.fps);
    else if (k == "duration") ok = ParseDouble(v, &b.duration_s);
    else if (k == "hfov") ok = ParseDouble(v, &b.hfov_rad);
    else if (k == "imu_rate") ok = ParseDouble(v, &b.imu_rate_hz);
    else if (k == "clock_offset") ok = ParseDouble(v, &b.imu_clock_offset_s);
    else if (k == "seed") ok = ParseUInt64(v, &b.seed);
    else if (k == "face") ok = ParseInt(v, &face), b.render_face = face != 0;
    else if (k == "readout") ok = ParseDouble(v, &s->readout_s);
    else if (k == "epoch") ok = ParseDouble(v, &s->epoch_s);
    // Unknown keys are a newer writer's: ignored.
    if (!ok) return Status::Error("truth file: bad value in '" + word + "'");
  }
  return Status::Ok();
}

bool ParseRow(const std::string& line, TruthRow* row) {
  std::vector<double> v;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    double x = 0.0;
    if (!ParseDouble(cell, &x)) return false;
    v.push_back(x);
  }
  if (v.size() != 9 + 4 * kRows) return false;
  row->frame = static_cast<int>(v[0]);
  row->stamp_s = v[1];
  SimTruth& t = row->truth;
  t.head_px = Eigen::Vector2d(v[2], v[3]);
  t.head_in_view = v[4] != 0;
  t.face_scale_px = v[5];
  t.occluded = v[6] != 0;
  t.face_out = v[7] != 0;
  t.second_face = v[8] != 0;
  t.R_r.clear();
  for (int r = 0; r < kRows; ++r) {
    const double* q = &v[9 + 4 * r];
    t.R_r.emplace_back(q[3], q[0], q[1], q[2]);
  }
  return true;
}

}  // namespace

Status MakeSimulatorOptions(const SimulationSettings& settings, SimulatorOptions* options) {
  SimulatorOptions o = settings.base;
  o.data_dir = settings.data_dir;
  const double duration = o.duration_s;
  const Status s = ApplyPreset(settings.preset, &o);
  if (!s.ok()) return s;
  // The given duration, or the preset's least (dropout's 7 s) if longer.
  o.duration_s = std::max(duration, o.duration_s);
  if (settings.readout_s >= 0) o.readout_s = settings.readout_s;
  *options = o;
  return Status::Ok();
}

TruthFileWriter::TruthFileWriter(std::ostream* out, const SimulationSettings& settings)
    : out_(out) {
  const SimulatorOptions& b = settings.base;
  std::ostream& o = *out_;
  o.precision(17);
  o << kMagic << " preset=" << Escape(settings.preset) << " data=" << Escape(settings.data_dir)
    << " background=" << Escape(b.background_photo) << " width=" << b.width
    << " height=" << b.height << " fps=" << b.fps << " duration=" << b.duration_s
    << " hfov=" << b.hfov_rad << " imu_rate=" << b.imu_rate_hz
    << " clock_offset=" << b.imu_clock_offset_s << " seed=" << b.seed
    << " face=" << (b.render_face ? 1 : 0) << " readout=" << settings.readout_s
    << " epoch=" << settings.epoch_s << "\n";
  o << "frame,stamp,head_x,head_y,head_in_view,face_scale_px,occluded,face_out,second_face";
  for (int r = 0; r < kRows; ++r) {
    o << ",row" << r << "_qx,row" << r << "_qy,row" << r << "_qz,row" << r << "_qw";
  }
  o << "\n";
}

void TruthFileWriter::Add(int frame, double stamp_s, const SimTruth& truth) {
  std::ostream& o = *out_;
  o << frame << "," << stamp_s << "," << truth.head_px.x() << "," << truth.head_px.y() << ","
    << truth.head_in_view << "," << truth.face_scale_px << "," << truth.occluded << ","
    << truth.face_out << "," << truth.second_face;
  for (const auto& q : truth.R_r) o << "," << q.x() << "," << q.y() << "," << q.z() << "," << q.w();
  o << "\n";
}

Status ReadTruthFile(const std::string& path, SimulationSettings* settings, bool* has_settings,
                     std::vector<TruthRow>* rows) {
  std::ifstream f(path);
  if (!f) return Status::Error("cannot read truth file '" + path + "'");
  *has_settings = false;
  rows->clear();
  std::string line;
  bool header = false;
  int line_no = 0;
  while (std::getline(f, line)) {
    ++line_no;
    if (line.compare(0, sizeof(kMagic) - 1, kMagic) == 0) {
      const Status s = ParseSettings(line, settings);
      if (!s.ok()) return s;
      *has_settings = true;
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      if (line.compare(0, 12, "frame,stamp,") != 0) {
        return Status::Error("'" + path + "' is not a steadiface truth file");
      }
      header = true;
      continue;
    }
    TruthRow row;
    if (!ParseRow(line, &row)) {
      return Status::Error("'" + path + "' line " + std::to_string(line_no) + ": bad row");
    }
    rows->push_back(row);
  }
  if (!header) return Status::Error("'" + path + "' has no column names");
  return Status::Ok();
}

std::map<int64_t, int> FramesByStampMs(const std::vector<TruthRow>& rows) {
  std::map<int64_t, int> out;
  for (const TruthRow& r : rows) out[std::llround(r.stamp_s * 1000.0)] = r.frame;
  return out;
}

}  // namespace sim
}  // namespace steadiface
