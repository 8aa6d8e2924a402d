#include "steadiface_core/stabilizer/face_in_camera.h"

namespace steadiface {

bool FaceInCamera(const CameraModel& model, const FaceObservation& face,
                  const RowRotations& rows, const Eigen::Quaterniond& R_r_middle,
                  const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                  FaceObservation* out) {
  *out = face;
  bool ok = !face.landmarks.empty();
  for (size_t i = 0; i < face.landmarks.size(); ++i) {
    const Eigen::Quaterniond& R_row =
        face.landmark_rows.empty() ? R_r_middle : rows.At(face.landmark_rows[i]);
    ok = model.Project(face.landmarks[i], R_v, t, R_row, &out->landmarks[i]) && ok;
  }
  ComputeCentreAndScale(out);
  return ok;
}

}  // namespace steadiface
