#include "steadiface_core/warp/warper.h"

#include <cstdint>

#include <chrono>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "steadiface_core/common/stopwatch.h"
#include "steadiface_core/warp/mesh_sampler.h"
#include "steadiface_core/warp/warp_geometry.h"
#include "warp/mesh_scanline.h"

namespace steadiface {

Status ParseWarpMode(const std::string& name, WarpMode* mode) {
  if (name == "global") {
    *mode = WarpMode::kGlobal;
  } else if (name == "layered") {
    *mode = WarpMode::kLayered;
  } else if (name == "composite") {
    *mode = WarpMode::kComposite;
  } else {
    return Status::Error("warp.mode must be 'global', 'layered' or 'composite', got '" + name +
                         "'");
  }
  return Status::Ok();
}

const char* WarpModeName(WarpMode mode) {
  switch (mode) {
    case WarpMode::kLayered:
      return "layered";
    case WarpMode::kComposite:
      return "composite";
    case WarpMode::kGlobal:
      break;
  }
  return "global";
}

Status ValidateWarpOptions(const WarpOptions& o) {
  Status s = ValidateOutputOptions(o.output);
  if (!s.ok()) return s;
  if (o.mode != WarpMode::kGlobal) {  // the subject region (layered and composite)
    s = ValidateSubjectRegionOptions(o.layered.region);
    if (!s.ok()) return s;
  }
  if (o.mode == WarpMode::kLayered) {
    s = ValidateLayerBlendOptions(o.layered.blend);
    if (!s.ok()) return s;
    if (o.layered.mesh_cols < 2 || o.layered.mesh_cols > 512 || o.layered.mesh_rows < 2 ||
        o.layered.mesh_rows > 512) {
      return Status::Error("warp.layered.mesh_cols/mesh_rows must be in [2, 512]");
    }
  }
  std::ostringstream err;
  if (o.mesh_cols < 1 || o.mesh_cols > 512 || o.mesh_rows < 1 ||
      o.mesh_rows > 512) {
    err << "warp.mesh_cols/mesh_rows must be in [1, 512], got "
        << o.mesh_cols << "x" << o.mesh_rows;
  } else if (o.distortion_cell_px < 2 || o.distortion_cell_px > 1024) {
    err << "warp.distortion_cell_px must be in [2, 1024], got "
        << o.distortion_cell_px;
  } else if (o.fixed_point_iterations < 1 || o.fixed_point_iterations > 50) {
    err << "warp.fixed_point_iterations must be in [1, 50], got "
        << o.fixed_point_iterations;
  } else if (o.num_threads < 0 || o.num_threads > 256) {
    err << "warp.num_threads must be in [0, 256], got " << o.num_threads;
  } else if (o.protrusion_samples_per_edge < 2 ||
             o.protrusion_samples_per_edge > 1024) {
    err << "warp.protrusion_samples_per_edge must be in [2, 1024], got "
        << o.protrusion_samples_per_edge;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

bool SameLayering(WarpMode mode, const LayeredWarpOptions& a, const WarpOptions& options) {
  const LayeredWarpOptions& b = options.layered;
  const SubjectRegionOptions &ra = a.region, &rb = b.region;
  const LayerBlendOptions &ba = a.blend, &bb = b.blend;
  return mode == options.mode && a.mesh_cols == b.mesh_cols &&
         a.mesh_rows == b.mesh_rows &&
         ra.head_width_scale == rb.head_width_scale &&
         ra.head_top_scale == rb.head_top_scale && ra.torso == rb.torso &&
         ra.shoulder_width_scale == rb.shoulder_width_scale &&
         ra.neck_width_scale == rb.neck_width_scale &&
         ra.smoothing_s == rb.smoothing_s && ra.ramp_s == rb.ramp_s &&
         ba.band_width == bb.band_width && ba.band_inside == bb.band_inside &&
         ba.outline_margin_cells == bb.outline_margin_cells &&
         ba.max_offset == bb.max_offset &&
         ba.offset_lowpass_hz == bb.offset_lowpass_hz &&
         ba.band_data_weight == bb.band_data_weight &&
         ba.shape_weight == bb.shape_weight &&
         ba.temporal_weight == bb.temporal_weight &&
         ba.min_cell_ratio == bb.min_cell_ratio &&
         ba.yield_to_subject == bb.yield_to_subject;
}

Status Warper::Create(const CameraModel& model, const WarpOptions& options,
                      std::unique_ptr<Warper>* out) {
  Status s = ValidateWarpOptions(options);
  if (!s.ok()) return s;
  OutputGeometry output;
  s = OutputGeometry::Create(model, options.output, &output);
  if (!s.ok()) return s;
  if (options.num_threads > 0) cv::setNumThreads(options.num_threads);
  out->reset(new Warper(model, options, output));
  return Status::Ok();
}

Warper::Warper(const CameraModel& model, const WarpOptions& options,
               const OutputGeometry& output)
    : model_(model),
      options_(options),
      output_(output),
      protrusion_(model, output, options.protrusion_samples_per_edge) {
  const bool layered = options.mode == WarpMode::kLayered;
  int cols = layered ? options.layered.mesh_cols : options.mesh_cols;
  int rows = layered ? options.layered.mesh_rows : options.mesh_rows;
  if (model.intrinsics().HasDistortion()) {
    const int cell = options.distortion_cell_px;
    cols = std::max(cols, (output.width() + cell - 1) / cell);
    rows = std::max(rows, (output.height() + cell - 1) / cell);
  }
  mesh_.cols = cols + 1;
  mesh_.rows = rows + 1;
  mesh_.u.resize(mesh_.cols);
  mesh_.v.resize(mesh_.rows);
  for (int i = 0; i < mesh_.cols; ++i) {
    mesh_.u[i] = static_cast<double>(i) * (output.width() - 1) / cols;
  }
  for (int j = 0; j < mesh_.rows; ++j) {
    mesh_.v[j] = static_cast<double>(j) * (output.height() - 1) / rows;
  }
  mesh_.source.resize(mesh_.cols * mesh_.rows);
  mesh_.source_row.resize(mesh_.cols * mesh_.rows);
  if (layered) blend_.reset(new LayerBlend(mesh_.u, mesh_.v, options.layered.blend));
}

void Warper::SetCropRatio(double r) {
  if (r == output_.crop_ratio()) return;
  output_ = output_.WithCropRatio(r);
  protrusion_ = ProtrusionGeometry(model_, output_, options_.protrusion_samples_per_edge);
}

Status Warper::MeshForPose(const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                           const RowRotations& rows, std::vector<Eigen::Vector2f>* source,
                           std::vector<float>* source_row) const {
  if (!R_v.coeffs().allFinite() || std::abs(R_v.norm() - 1.0) > 1e-6 ||
      !t.allFinite()) {
    return Status::Error("warp: non-finite or non-unit virtual pose refused");
  }
  if (rows.empty() || rows.height() != model_.intrinsics().height) {
    return Status::Error("warp: row rotations missing or for another size");
  }
  source->resize(static_cast<size_t>(mesh_.cols) * mesh_.rows);
  source_row->resize(source->size());
  double row = 0.5 * (rows.height() - 1);
  for (int j = 0; j < mesh_.rows; ++j) {
    for (int i = 0; i < mesh_.cols; ++i) {
      const Eigen::Vector2d V =
          output_.OutputPixelToVirtual({mesh_.u[i], mesh_.v[j]});
      Eigen::Vector2d p;
      // Start from the previous vertex's row: neighbours land on nearby rows.
      if (!VirtualToRealPixelRS(model_, R_v, t, rows, V,
                                options_.fixed_point_iterations, 1e-3, &p,
                                &row)) {
        return Status::Error(
            "warp: degenerate pose, part of the output maps behind the "
            "camera");
      }
      const size_t k = static_cast<size_t>(j) * mesh_.cols + i;
      (*source)[k] = p.cast<float>();
      (*source_row)[k] = static_cast<float>(row);
    }
    // Next mesh row starts from this row's first vertex.
    row = (*source_row)[static_cast<size_t>(j) * mesh_.cols];
  }
  return Status::Ok();
}

Status Warper::ComputeMesh(const Eigen::Quaterniond& R_v,
                           const Eigen::Vector2d& t,
                           const RowRotations& rows) {
  const auto start = std::chrono::steady_clock::now();
  Status s = MeshForPose(R_v, t, rows, &mesh_.source, &mesh_.source_row);
  timings_.mesh_ms = MsSince(start);
  return s;
}

Status Warper::ComputeLayeredMesh(const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                                  const Eigen::Quaterniond& R_b, const Eigen::Vector2d& t_b,
                                  const RowRotations& rows, const SubjectRegion& region,
                                  double dt) {
  if (blend_ == nullptr) return Status::Error("warp: layered mesh needs warp.mode layered");
  const auto start = std::chrono::steady_clock::now();
  Status s = MeshForPose(R_b, t_b, rows, &background_source_, &mesh_.source_row);
  if (!s.ok()) return s;
  s = MeshForPose(R_v, t, rows, &subject_source_, &row_scratch_);
  if (!s.ok()) return s;
  const CameraIntrinsics& k = model_.intrinsics();
  blend_->Blend(subject_source_, background_source_, region, dt, k.width, k.height, &mesh_.source,
                &blend_report_);
  timings_.mesh_ms = MsSince(start);
  return Status::Ok();
}

void Warper::BuildMaps() {
  const auto start = std::chrono::steady_clock::now();
  const int W = output_.width(), H = output_.height();
  if (options_.fixed_point_maps) {
    map1_.create(H, W, CV_16SC2);
    map2_.create(H, W, CV_16UC1);
  } else {
    map1_.create(H, W, CV_32FC1);
    map2_.create(H, W, CV_32FC1);
  }
  const WarpMesh& m = mesh_;
  const bool fixed = options_.fixed_point_maps;
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& range) {
    std::vector<Eigen::Vector2f> line;
    for (int v = range.start; v < range.end; ++v) {
      short* out1 = fixed ? map1_.ptr<short>(v) : nullptr;
      ushort* out2 = fixed ? map2_.ptr<ushort>(v) : nullptr;
      float* fx = fixed ? nullptr : map1_.ptr<float>(v);
      float* fy = fixed ? nullptr : map2_.ptr<float>(v);
      // As cv::convertMaps: 1/32 px fixed point, integer part in map1,
      // interpolation-table index in map2. Far-out coordinates clamp (they
      // sample the black border either way).
      auto store = [out1, out2](int u, int32_t ix, int32_t iy) {
        out1[2 * u] = static_cast<short>(ix >> kInterBits);
        out1[2 * u + 1] = static_cast<short>(iy >> kInterBits);
        out2[u] = static_cast<ushort>((iy & (kInterTabSize - 1)) * kInterTabSize +
                                      (ix & (kInterTabSize - 1)));
      };
      ForEachScanSegment(m, W, v, &line, [&](const ScanSegment& seg) {
        if (!fixed) {
          for (int u = seg.u0; u <= seg.u1; ++u) {
            const float k = static_cast<float>(u - seg.u0);
            fx[u] = seg.x0 + seg.dx * k;
            fy[u] = seg.y0 + seg.dy * k;
          }
        } else if (seg.stepped) {
          int32_t X = seg.X, Y = seg.Y;
          for (int u = seg.u0; u <= seg.u1; ++u) {
            store(u, X >> kScanFrac, Y >> kScanFrac);
            X += seg.DX;
            Y += seg.DY;
          }
        } else {
          for (int u = seg.u0; u <= seg.u1; ++u) {
            int32_t X, Y;
            ClampedScanCoordinates(seg, u, &X, &Y);
            store(u, X, Y);
          }
        }
      });
    }
  });
  timings_.maps_ms = MsSince(start);
}

namespace {

Status CheckInput(const CameraIntrinsics& k, const cv::Mat& input) {
  if (input.empty() || input.cols != k.width || input.rows != k.height) {
    std::ostringstream err;
    err << "warp: input is " << input.cols << "x" << input.rows
        << ", expected " << k.width << "x" << k.height;
    return Status::Error(err.str());
  }
  if (input.depth() != CV_8U || input.channels() < 1 || input.channels() > 4) {
    return Status::Error("warp: input must be 8-bit with 1-4 channels");
  }
  return Status::Ok();
}

}  // namespace

Status Warper::Render(const cv::Mat& input, cv::Mat* output) {
  if (!options_.direct_sampling) {
    BuildMaps();
    return Remap(input, output);
  }
  Status s = CheckInput(model_.intrinsics(), input);
  if (!s.ok()) return s;
  if (mesh_.source.empty()) return Status::Error("warp: no mesh computed yet");
  const auto start = std::chrono::steady_clock::now();
  SampleMesh(mesh_, input, output_.width(), output_.height(), output);
  timings_.maps_ms = 0.0;
  timings_.remap_ms = MsSince(start);
  return Status::Ok();
}

Status Warper::Remap(const cv::Mat& input, cv::Mat* output) {
  Status s = CheckInput(model_.intrinsics(), input);
  if (!s.ok()) return s;
  if (map1_.empty()) return Status::Error("warp: no maps built yet");
  const auto start = std::chrono::steady_clock::now();
  cv::remap(input, *output, map1_, map2_, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar::all(0));
  timings_.remap_ms = MsSince(start);
  return Status::Ok();
}

Status Warper::Warp(const cv::Mat& input, const Eigen::Quaterniond& R_v,
                    const Eigen::Vector2d& t, const RowRotations& rows,
                    cv::Mat* output) {
  Status s = ComputeMesh(R_v, t, rows);
  if (!s.ok()) return s;
  return Render(input, output);
}

void Warper::FloatMaps(cv::Mat* map_x, cv::Mat* map_y) {
  BuildMaps();
  if (options_.fixed_point_maps) {
    cv::Mat xy;
    cv::convertMaps(map1_, map2_, xy, cv::noArray(), CV_32FC2);
    std::vector<cv::Mat> ch;
    cv::split(xy, ch);
    *map_x = ch[0];
    *map_y = ch[1];
  } else {
    *map_x = map1_.clone();
    *map_y = map2_.clone();
  }
}

}  // namespace steadiface
