// libFuzzer: one or a few frames of stabilization and warp with random
// gyro, landmarks (NaN, off-image, degenerate) and options. Nothing may
// crash and every pose that comes out must be finite.
#include <cstdlib>

#include "fuzz_util.h"
#include "steadiface_core/stabilizer/stabilizer.h"
#include "steadiface_core/warp/warper.h"

using namespace steadiface;  // NOLINT (test harness)

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  const int w = 32 + in.Byte() % 200, h = 32 + in.Byte() % 150;
  CameraModel m;
  if (!CameraModel::Create(IntrinsicsFromHorizontalFov(w, h, 0.5 + (in.Byte() % 20) * 0.1),
                           CameraModelOptions(), &m).ok()) {
    return 0;
  }
  StabilizerOptions so;
  so.weights.fit = in.Double(0, 1e4);
  so.weights.follow = in.Double(0, 100);
  so.weights.rotation_c0 = in.Double(0, 100);
  so.weights.protrusion = in.Double(0, 10);
  so.terms.distortion_threshold_rad = in.Double(0, 1);
  so.gyro_only = in.Byte() % 4 == 0;
  so.solver.max_iterations = 1 + in.Byte() % 5;
  OutputOptions oo;
  oo.crop_ratio = (in.Byte() % 40) * 0.01;
  std::unique_ptr<Stabilizer> stab;
  if (!Stabilizer::Create(m, oo, so, &stab).ok()) return 0;  // invalid options are refused
  WarpOptions wo;
  wo.output = oo;
  wo.mesh_cols = 1 + in.Byte() % 8;
  wo.mesh_rows = 1 + in.Byte() % 8;
  std::unique_ptr<Warper> warper;
  if (!Warper::Create(m, wo, &warper).ok()) return 0;
  OrientationTimeline tl{OrientationTimelineOptions()};
  RollingShutterOptions rs;
  rs.readout_time_s = (in.Byte() % 30) * 0.001;
  const RowTiming timing(rs, h);
  double t = 0.0;
  for (int i = 0; i < 60; ++i) {
    tl.AddSample({Time(FromSeconds(t)), Eigen::Vector3d(in.Double(-3, 3), in.Double(-3, 3),
                                                        in.Double(-3, 3))});
    t += 0.005;
  }
  const int frames = 1 + in.Byte() % 4;
  for (int f = 0; f < frames && !in.done(); ++f) {
    FaceObservation face;
    face.valid = in.Byte() % 3 != 0;
    face.confidence = in.Double(0, 1);
    const int n = in.Byte() % 70;
    for (int i = 0; i < n; ++i) {
      face.landmarks.emplace_back(in.Double(-0.5, 1.5), in.Double(-0.5, 1.5));
      if (in.Byte() % 2) face.landmark_rows.push_back(in.Double(-10, h + 10));
    }
    ComputeCentreAndScale(&face);
    face.has_pose = in.Byte() % 2;
    face.yaw = in.Double(-3, 3);
    face.pitch = in.Double(-3, 3);
    StabilizerFrame out;
    const Time stamp = Time(FromSeconds(0.05 + 0.033 * f));
    if (stab->Process(stamp, tl, timing, &face, &out).ok()) {
      if (!out.R_v.coeffs().allFinite() || !out.t.allFinite()) abort();
      warper->ComputeMesh(out.R_v, out.t, out.rows);  // may refuse; must not crash
    }
  }
  return 0;
}
