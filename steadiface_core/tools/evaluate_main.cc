// steadiface_evaluate: renders simulator presets, runs the methods and
// scores them against ground truth. Prints a markdown table, writes
// report.json and per-(preset, method) trajectory CSVs for the plots.
//
//   steadiface_evaluate --data test/data --out out/eval
//       [--presets walk,run] [--methods none,gyro-only,steadiface,...]
//       [--duration S] [--size 640x360] [--seed 1] [--render]
// Without --duration every preset runs 3 s, except that a preset replaying
// a recorded gyro trace (run) runs the whole trace once.
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "steadiface_core/common/command_line.h"
#include "steadiface_core/eval/evaluation.h"
#include "steadiface_core/sim/simulator.h"

namespace {

using steadiface::CommandLine;
using steadiface::eval::EvaluationOptions;

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

// clang-format off
const char kUsage[] =
    "usage: steadiface_evaluate --data DIR --out DIR [--presets a,b]\n"
    "       [--methods none,gyro-only,steadiface,steadiface-layered,none/video,\n"
    "        steadiface/video,ffmpeg-vidstab,ffmpeg-deshake,ffmpeg-vidstab/aligned,\n"
    "        ffmpeg-deshake/aligned] [--duration S]\n"
    "       (/video: scored from the output video; /aligned: a peer's frames\n"
    "        aligned to the input's, the truth scored through them exactly)\n"
    "       [--size WxH] [--seed N] [--render] [--crop R]\n"
    "       [--band W] [--band-inside F] [--outline-margin CELLS] [--max-offset C] [--offset-lowpass HZ]\n"
    "       [--yield-to-background] (the layered warp's warp/layered/* options,\n"
    "         for sweeps; the last sets yield_to_subject false)\n"
    "       [--offset-error S] [--readout-error S] (misconfigure the IMU timing)\n"
    "       [--gyro-scale K] [--gyro-speed K] (presets with the recorded gyro\n"
    "         trace: scale its rotation, or play it K times as fast)\n"
    "       [--search-interval S] (face.search_interval: full-frame face search\n"
    "         at most once per S while no face is locked; 0 = every frame)\n"
    "       [--head-model relief|mean-face|flat] (the simulated head: the photo\n"
    "         on an ellipsoid with a nose that turns about its skull, the\n"
    "         default; that relief with the mean 3D face's depths at the\n"
    "         photo's landmarks, 1.1 face widths broad; or the flat photo)\n"
    "       [--head-breadth B] (the relief's breadth where its sides reach the\n"
    "         pivot's depth, in face widths; default the portrait's outline, 1.62)\n"
    "       [--pivot-depth D] (dynamic.pose_pivot_depth: the pose-invariant head\n"
    "         centre, D face scales behind the landmarks; 0 = the paper's centre)\n"
    "       [--true-head] (diagnostic: the stabilizer is handed the simulator's\n"
    "         true head centre in place of the tracker's pose-invariant centre\n"
    "         on every frame with a face; what a perfect tracker would give)\n"
    "       [--head-distance M] (the subject's distance [m]: robot at 2.75 m\n"
    "         shows a 30 px face)\n"
    "       [--head-motion K] (the head's own motion against the scene, K times\n"
    "         the preset's: bob, sway, yaw, pitch, lean, drift)\n"
    "       [--head-jitter K] (the head's 2-8 Hz jitter, K times the preset's)\n"
    "       [--head-yaw RAD] [--head-turn-speed K] (the head's yaw amplitude\n"
    "         instead of the preset's, and its turns K times as fast: turn_away\n"
    "         with --head-yaw 0.8 --head-turn-speed 3 shakes the head \"no\")\n"
    "       [--crop-mode fixed|dynamic] (output.crop: the fixed crop ratio, or the\n"
    "         dynamic crop between --widest R and it; default: the package's)\n"
    "       [--horizon off|level|lock] (output.horizon: the roll against the\n"
    "         accelerometer's gravity) [--level-tolerance DEG] (horizon.level_tolerance:\n"
    "         level leaves a roll within DEG alone; 0 pulls every roll)\n"
    "       [--rotation-source auto|imu|visual] (visual: the camera's rotation\n"
    "         from the video, the IMU unused; auto, the default: the video for\n"
    "         the frames the gyro does not cover)\n"
    "       [--window S,E] (also score seconds S to E on their own: the window_*\n"
    "         figures; default: a preset's IMU dropout)\n"
    "       [--subject-reach R] (stabilizer.subject_reach, layered: H within R jaw\n"
    "         widths of where the background layer shows the face)\n"
    "       [--reach-lowpass HZ] [--reach-hold F] (stabilizer.subject_reach_lowpass,\n"
    "         subject_reach_hold: H follows the slow part of that position)\n"
    "       [--head-w-stay W] [--head-d-ref D] (head.w_stay, head.d_ref: the\n"
    "         head target's smoothing, Eq. 1)\n"
    "       [--vidstab-zoom P] [--vidstab-smoothing N] (the vid.stab peer's\n"
    "         vidstabtransform zoom, optzoom off: it shows 1 - P/100 of the\n"
    "         width, so 30 is the default 0.70 crop's view; and its smoothing;\n"
    "         default its own)\n"
    "       [--intentional-window S] (stabilizer.intentional_window: E_r C0\n"
    "         follows the mean rotation rate over the last S; 0 = the paper)\n"
    "       [--protrusion-alpha-face A] (terms.protrusion_alpha_face: E_p's\n"
    "         tolerance while a face is fitted; 0.002 is the stiff no-face wall)\n"
    "       [--feasible-set] (per stabilizer method also feasible_<preset>_<method>.csv:\n"
    "         per frame, the crop-window shifts the margin allows, rolling shutter\n"
    "         included, in 72 directions [input px], for scripts/analysis/crop_bound.py)\n"
    "       [--face-core CELLS] (warp/layered/face_core)\n"
    "       [--reach-tube] (layered: also reach_<preset>_<method>.csv: per frame,\n"
    "         the true head through the background layer's pose and the radius\n"
    "         H was held within there, both in output px; for\n"
    "         scripts/analysis/reach_bound.py)\n"
    "       [--feasible-roll MAX] (with --feasible-set, also\n"
    "         feasible_<preset>_<method>_roll.csv: the same for a window that also\n"
    "         rolls, every 0.025 rad within +-MAX, and the true head's move when it\n"
    "         does; for crop_bound.py --feasible-roll)\n";
// clang-format on


// What runs: the presets, methods, sequence and extra outputs.
void AddRunFlags(CommandLine* cl, EvaluationOptions* o) {
  cl->String("--data", &o->data_dir).String("--out", &o->out_dir);
  cl->Value("--presets", "a comma-separated list",
            [o](const std::string& v) { return !(o->presets = Split(v)).empty(); });
  cl->Value("--methods", "a comma-separated list",
            [o](const std::string& v) { return !(o->methods = Split(v)).empty(); });
  cl->Double("--duration", &o->duration_s).UInt64("--seed", &o->seed).Flag("--render", &o->render);
  cl->Value("--size", "WxH", [o](const std::string& v) {
    return std::sscanf(v.c_str(), "%dx%d", &o->width, &o->height) == 2;
  });
  cl->Double("--gyro-scale", &o->gyro_scale).Double("--gyro-speed", &o->gyro_speed);
  cl->Double("--head-distance", &o->head_distance_m);
  cl->Double("--head-motion", &o->head_motion_scale).Double("--head-jitter", &o->head_jitter_scale);
  cl->Double("--head-yaw", &o->head_yaw_rad).Double("--head-turn-speed", &o->head_turn_speed);
  cl->Value("--head-model", "relief, mean-face or flat", [o](const std::string& v) {
    o->head_model = v;
    return v == "relief" || v == "mean-face" || v == "flat";
  });
  cl->Double("--head-breadth", &o->head_breadth);
  cl->Flag("--feasible-set", &o->feasible_set).Double("--feasible-roll", &o->feasible_roll);
  cl->Flag("--reach-tube", &o->reach_tube).Flag("--composite-frames", &o->composite_frames);
  cl->Flag("--true-head", &o->true_head);
  cl->Int("--average15", &o->average_at);
}

// The options each method's defaults are changed by.
void AddPipelineFlags(CommandLine* cl, EvaluationOptions* o) {
  cl->Double("--crop", &o->crop).Double("--offset-error", &o->offset_error_s);
  cl->Double("--readout-error", &o->readout_error_s);
  cl->Double("--search-interval", &o->search_interval_s);
  cl->Value("--rotation-source", "auto, imu or visual", [o](const std::string& v) {
    o->rotation_source = v == "visual" ? steadiface::RotationSource::kVisual
                         : v == "imu"  ? steadiface::RotationSource::kImu
                                       : steadiface::RotationSource::kAuto;
    return v == "auto" || v == "imu" || v == "visual";
  });
  cl->Value("--window", "S,E (seconds)", [o](const std::string& v) {
    return std::sscanf(v.c_str(), "%lf,%lf", &o->window_s.x(), &o->window_s.y()) == 2 &&
           o->window_s.y() > o->window_s.x();
  });
  cl->Double("--pivot-depth", &o->pose_pivot_depth);
  cl->Double("--head-w-stay", &o->head_w_stay).Double("--head-d-ref", &o->head_d_ref);
  cl->Double("--protrusion-alpha-face", &o->protrusion_alpha_face);
  cl->Double("--intentional-window", &o->intentional_window_s);
  cl->Double("--vidstab-zoom", &o->peer.vidstab_zoom_percent);
  cl->Int("--vidstab-smoothing", &o->peer.vidstab_smoothing);
  cl->Double("--subject-reach", &o->subject_reach).Double("--reach-lowpass", &o->reach_lowpass_hz);
  cl->Double("--reach-hold", &o->reach_hold);
  steadiface::LayerBlendOptions* b = &o->blend;
  cl->Double("--band", &b->band_width).Double("--band-inside", &b->band_inside);
  cl->Double("--outline-margin", &b->outline_margin_cells).Double("--face-core", &b->face_core_cells);
  cl->Double("--max-offset", &b->max_offset).Double("--offset-lowpass", &b->offset_lowpass_hz);
  cl->ClearFlag("--yield-to-background", &b->yield_to_subject);
}

// The composite warp's matte and plate.
void AddCompositeFlags(CommandLine* cl, steadiface::CompositeOptions* c) {
  cl->Double("--matte-softness", &c->matte.prior_softness);
  cl->Double("--matte-colour", &c->matte.colour_weight);
  cl->Double("--matte-temporal", &c->matte.temporal);
  cl->Double("--matte-plate-level", &c->matte.plate_level);
  cl->Double("--matte-motion-level", &c->matte.motion_level);
  cl->Double("--matte-search", &c->matte.search_jaw_widths);
  cl->Double("--matte-motion-memory", &c->matte.motion_memory);
  cl->Double("--plate-max-age", &c->plate.max_age_s);
  cl->Int("--plate-distance", &c->plate_distance_px);
  cl->Double("--plate-below", &c->plate_below);
  cl->Int("--plate-row-step", &c->plate_row_step);
  cl->Double("--plate-confidence", &c->matte.plate_confidence);
  cl->Int("--matte-absent", &c->matte.absent_frames);
  cl->Int("--matte-scale", &c->matte.scale);
  cl->Double("--plate-outlier", &c->plate.outlier_level);
  cl->Int("--plate-confirm", &c->plate.confirm_frames);
}

// The view: the crop mode and the horizon, and their tuning.
void AddViewFlags(CommandLine* cl, steadiface::eval::ViewOverrides* v) {
  cl->Value("--crop-mode", "fixed or dynamic", [v](const std::string& s) {
    v->crop_mode = s == "dynamic" ? 1 : 0;
    return s == "fixed" || s == "dynamic";
  });
  cl->Value("--horizon", "off, level or lock", [v](const std::string& s) {
    v->horizon = s;
    steadiface::HorizonMode m;
    return steadiface::ParseHorizonMode(s, &m).ok();
  });
  cl->Double("--level-weight", &v->level_weight).Double("--lock-weight", &v->lock_weight);
  cl->Double("--level-tolerance", &v->level_tolerance_deg);
  cl->Double("--gravity-warmup", &v->gravity_warmup_s).Double("--gravity-tau", &v->gravity_tau_s);
  cl->Double("--widest", &v->widest).Flag("--start-tight", &v->start_tight);
  cl->Double("--shake-hz", &v->shake_hz).Double("--headroom", &v->headroom);
  cl->Double("--widen-rate", &v->widen_rate).Double("--tighten-rate", &v->tighten_rate);
  cl->Double("--zoom-accel", &v->zoom_accel);
}

}  // namespace

int main(int argc, char** argv) {
  EvaluationOptions o;
  o.presets = steadiface::sim::PresetNames();
  CommandLine cl;
  AddRunFlags(&cl, &o);
  AddPipelineFlags(&cl, &o);
  AddCompositeFlags(&cl, &o.composite);
  AddViewFlags(&cl, &o.view);
  int status = 0;
  if (!cl.Start(argc, argv, "steadiface_evaluate", kUsage,
                [&o] { return !o.data_dir.empty() && !o.out_dir.empty(); }, std::cout, std::cerr,
                &status)) {
    return status;
  }
  return steadiface::eval::RunEvaluation(o, std::cout, std::cerr);
}
