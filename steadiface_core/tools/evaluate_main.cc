// steadiface_evaluate: renders simulator presets, runs the methods and
// scores them against ground truth. Prints a markdown table, writes
// report.json and per-(preset, method) trajectory CSVs for the plots.
//
//   steadiface_evaluate --data test/data --out out/eval
//       [--presets walk,run] [--methods none,gyro-only,steadiface]
//       [--duration 3] [--size 640x360] [--seed 1] [--render]
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <vector>

#include "steadiface_core/eval/run_methods.h"

namespace {

using steadiface::eval::Method;

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

int Usage() {
  std::cerr << "usage: steadiface_evaluate --data DIR --out DIR [--presets a,b]\n"
               "       [--methods none,gyro-only,steadiface] [--duration S]\n"
               "       [--size WxH] [--seed N] [--render]\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data, out_dir;
  std::vector<std::string> presets = steadiface::sim::PresetNames();
  std::vector<std::string> methods = {"none", "gyro-only", "steadiface"};
  double duration = 3.0;
  int width = 640, height = 360;
  uint64_t seed = 1;
  bool render = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--data") data = next();
    else if (a == "--out") out_dir = next();
    else if (a == "--presets") presets = Split(next());
    else if (a == "--methods") methods = Split(next());
    else if (a == "--duration") duration = std::atof(next().c_str());
    else if (a == "--seed") seed = std::strtoull(next().c_str(), nullptr, 10);
    else if (a == "--render") render = true;
    else if (a == "--size") {
      if (std::sscanf(next().c_str(), "%dx%d", &width, &height) != 2) return Usage();
    } else {
      return Usage();
    }
  }
  if (data.empty() || out_dir.empty()) return Usage();
  mkdir(out_dir.c_str(), 0755);
  std::ofstream json(out_dir + "/report.json");
  json << "{\n  \"duration_s\": " << duration << ",\n  \"size\": [" << width << ", "
       << height << "],\n  \"seed\": " << seed << ",\n  \"results\": [\n";
  std::cout << "| preset | method | head jitter px | head jitter %diag | background jitter px"
               " | head stability | bg stability | cropping | distortion | undefined frames |"
               " solver p50 ms | face p50 ms |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  bool first = true;
  int failures = 0;
  for (const std::string& preset : presets) {
    steadiface::sim::SimulatorOptions so;
    so.data_dir = data;
    so.duration_s = duration;
    so.width = width;
    so.height = height;
    so.seed = seed;
    steadiface::Status s = steadiface::sim::ApplyPreset(preset, &so);
    std::unique_ptr<steadiface::sim::Simulator> sim;
    if (s.ok()) s = steadiface::sim::Simulator::Create(so, &sim);
    if (!s.ok()) {
      std::cerr << "preset " << preset << ": " << s.message() << "\n";
      ++failures;
      continue;
    }
    for (const std::string& name : methods) {
      Method m;
      if (name == "none") m = Method::kNone;
      else if (name == "gyro-only") m = Method::kGyroOnly;
      else if (name == "steadiface") m = Method::kSteadiface;
      else {
        std::cerr << "unknown method " << name << "\n";
        return 2;
      }
      const steadiface::PipelineOptions po = steadiface::eval::OptionsFor(*sim, m);
      steadiface::CameraModel model;
      steadiface::CameraModel::Create(sim->intrinsics(), po.camera, &model);
      steadiface::OutputGeometry og;
      steadiface::OutputGeometry::Create(model, po.warp.output, &og);
      steadiface::eval::Scorecard card(*sim, model, og, steadiface::eval::ScorecardOptions());
      s = steadiface::eval::RunMethod(*sim, m, po, render, &card, nullptr);
      if (!s.ok()) {
        std::cerr << preset << "/" << name << ": " << s.message() << "\n";
        ++failures;
        continue;
      }
      const steadiface::eval::Score sc = card.Compute();
      double solver = 0, face = 0;
      for (const auto& st : sc.stage_ms) {
        if (st.first == "solver") solver = st.second.first;
        if (st.first == "face") face = st.second.first;
      }
      char line[512];
      std::snprintf(line, sizeof(line),
                    "| %s | %s | %.2f | %.3f | %.2f | %.2f | %.2f | %.2f | %.3f | %.1f%% | %.3f | %.2f |\n",
                    preset.c_str(), name.c_str(), sc.head_jitter_px, 100 * sc.head_jitter_frac,
                    sc.background_jitter_px, sc.head_stability, sc.background_stability,
                    sc.cropping, sc.distortion, 100 * sc.undefined_fraction, solver, face);
      std::cout << line << std::flush;
      json << (first ? "" : ",\n") << "    {\"preset\": \"" << preset << "\", \"method\": \""
           << name << "\", \"frames\": " << sc.frames
           << ", \"head_jitter_px\": " << sc.head_jitter_px
           << ", \"head_jitter_frac\": " << sc.head_jitter_frac
           << ", \"background_jitter_px\": " << sc.background_jitter_px
           << ", \"background_jitter_frac\": " << sc.background_jitter_frac
           << ", \"head_stability\": " << sc.head_stability
           << ", \"background_stability\": " << sc.background_stability
           << ", \"cropping\": " << sc.cropping << ", \"distortion\": " << sc.distortion
           << ", \"undefined_fraction\": " << sc.undefined_fraction << ", \"stage_ms\": {";
      for (size_t k = 0; k < sc.stage_ms.size(); ++k) {
        json << (k ? ", " : "") << "\"" << sc.stage_ms[k].first << "\": ["
             << sc.stage_ms[k].second.first << ", " << sc.stage_ms[k].second.second << "]";
      }
      json << "}}";
      first = false;
      std::ofstream csv(out_dir + "/traj_" + preset + "_" + name + ".csv");
      csv << "t,head_in_x,head_in_y,head_out_x,head_out_y,head_valid,bg_out_x,bg_out_y,"
             "virt_rx,virt_ry,virt_rz,real_rx,real_ry,real_rz,tx,ty\n";
      for (const auto& p : card.samples()) {
        csv << p.t << "," << p.head_in.x() << "," << p.head_in.y() << "," << p.head_out.x()
            << "," << p.head_out.y() << "," << p.head_valid << "," << p.background_out.x()
            << "," << p.background_out.y() << "," << p.virtual_angle[0] << ","
            << p.virtual_angle[1] << "," << p.virtual_angle[2] << "," << p.real_angle[0] << ","
            << p.real_angle[1] << "," << p.real_angle[2] << "," << p.offset.x() << ","
            << p.offset.y() << "\n";
      }
    }
  }
  json << "\n  ]\n}\n";
  return failures == 0 ? 0 : 1;
}
