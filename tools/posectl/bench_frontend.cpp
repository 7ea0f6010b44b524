// posectl bench frontend: per frame pair on one core, the visual-thermal front end (issue 9) by
// step - enhancement, thermal preprocessing, fusion, quality, tracking, depth - and in total
// (target <= 15 ms), on a rendered night street seen by the default rig (M2DGR intrinsics and
// T_cam_thermal): a dark, noisy 640x480 colour frame, a 640x512 thermal frame (8-bit AGC video
// as the PLUG 617 streams it, and 16-bit counts as a second run), the camera's rotation between
// the two stamps, and a full VLP-32C sweep (~55k points) in the camera frame. Then the three
// modes side by side (features, match success, depth association), and the cost of LSD lines.
// Step times are the thread's CPU time (see thread_cpu_ms).

#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <string>
#include <vector>

#include "core/vision/pinhole_camera.hpp"
#include "core/vision/visual_frontend.hpp"
#include "daemon/config/config_loader.hpp"
#include "tools/posectl/bench.hpp"

namespace posed::posectl {
// A named namespace: posectl compiles as unity batches, beside bench_lio's helpers.
namespace frontend_bench {

using Clock = std::chrono::steady_clock;
constexpr int kFrames = 40;
constexpr double kDeg = std::numbers::pi / 180.0;

// --- The scene: a street 12 m wide between two building faces, ground, and a far wall. -------

/// Smooth value noise in [0, 1] on a unit lattice.
double value_noise(double x, double y, std::uint32_t seed) {
  const auto hash = [seed](std::int64_t i, std::int64_t j) {
    std::uint64_t h = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ull ^
                      static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4Full ^ seed;
    h ^= h >> 29;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 32;
    return static_cast<double>(h & 0xFFFFFF) / static_cast<double>(0xFFFFFF);
  };
  const double fx = std::floor(x), fy = std::floor(y);
  const auto i = static_cast<std::int64_t>(fx), j = static_cast<std::int64_t>(fy);
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const double a = hash(i, j), b = hash(i + 1, j), c = hash(i, j + 1), d = hash(i + 1, j + 1);
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

/// Facade-like texture: noise octaves plus window-sized tiles with hard edges [0, 1].
double surface(double u, double v, std::uint32_t seed) {
  const bool tile = (static_cast<std::int64_t>(std::floor(u / 1.1)) +
                     static_cast<std::int64_t>(std::floor(v / 0.9))) %
                        3 ==
                    0;
  return 0.35 * value_noise(u / 0.8, v / 0.8, seed) +
         0.3 * value_noise(u / 0.25, v / 0.25, seed + 1) +
         0.15 * value_noise(u / 0.06, v / 0.06, seed + 2) + (tile ? 0.2 : 0.0);
}

/// Camera frame convention of the world: x right, y down, z forward along the street.
struct Hit {
  double range = -1;       ///< along the unit ray [m]
  double visible = 0;      ///< reflectance [0, 1]
  double temperature = 0;  ///< thermal emission [0, 1]
};

Hit cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  Hit best;
  const auto consider = [&](double t, double u, double v, std::uint32_t seed, double warmth) {
    if (t <= 0.05 || (best.range > 0 && t >= best.range)) return;
    best.range = t;
    best.visible = surface(u, v, seed);
    // Thermal: a different, smoother structure (heated windows, pipes, people-sized blobs).
    best.temperature = 0.55 * value_noise(u / 1.7, v / 1.3, seed + 50) +
                       0.3 * value_noise(u / 0.4, v / 0.4, seed + 51) + warmth;
  };
  if (d.x() < -1e-9) {  // left facade x = -6
    const double t = (-6.0 - o.x()) / d.x();
    const Eigen::Vector3d p = o + t * d;
    consider(t, p.z(), p.y(), 11, 0.1);
  }
  if (d.x() > 1e-9) {  // right facade x = +6
    const double t = (6.0 - o.x()) / d.x();
    const Eigen::Vector3d p = o + t * d;
    consider(t, p.z(), p.y(), 23, 0.0);
  }
  if (d.y() > 1e-9) {  // ground y = +1.5 (camera 1.5 m up)
    const double t = (1.5 - o.y()) / d.y();
    const Eigen::Vector3d p = o + t * d;
    consider(t, p.x(), p.z(), 37, -0.1);
  }
  if (d.z() > 1e-9) {  // far wall z = 60
    const double t = (60.0 - o.z()) / d.z();
    const Eigen::Vector3d p = o + t * d;
    consider(t, p.x(), p.y(), 41, 0.05);
  }
  return best;
}

/// Normalised undistorted ray of every pixel of a camera.
std::vector<Eigen::Vector2d> rays_of(const vision::PinholeCamera& camera) {
  std::vector<Eigen::Vector2d> rays(static_cast<std::size_t>(camera.width * camera.height));
  for (int r = 0; r < camera.height; ++r) {
    for (int c = 0; c < camera.width; ++c) {
      Eigen::Vector2d xy(0, 0);
      camera.normalised_from_pixel(Eigen::Vector2d(c, r), xy);
      rays[static_cast<std::size_t>(r * camera.width + c)] = xy;
    }
  }
  return rays;
}

struct FramePair {
  cv::Mat visible;    ///< BGR, dark and noisy
  cv::Mat thermal8;   ///< 8-bit AGC video
  cv::Mat thermal16;  ///< 16-bit counts
  Eigen::Matrix3d R_camtv_camtt;
  std::vector<Eigen::Vector3f> p_cam_m;
  HostTime visible_stamp, thermal_stamp;
};

/// Renders the drive: 1.5 m/s forward, turning 8 deg/s, visible at 15 Hz and the thermal frame
/// up to 20 ms away (25 Hz, paired to the nearest).
std::vector<FramePair> render_drive(const vision::PinholeCamera& visible,
                                    const vision::PinholeCamera& thermal,
                                    const Eigen::Isometry3d& T_cam_thermal) {
  const auto visible_rays = rays_of(visible);
  const auto thermal_rays = rays_of(thermal);
  cv::RNG rng(2024);
  std::vector<FramePair> frames(kFrames);
  const double yaw_rate = 8.0 * kDeg, speed = 1.5;
  const auto pose_at = [&](double t) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(yaw_rate * t, -Eigen::Vector3d::UnitY()).matrix();
    T.translation() = Eigen::Vector3d(0.4 * std::sin(0.5 * t), 0, speed * t);
    return T;
  };
  for (int k = 0; k < kFrames; ++k) {
    FramePair& f = frames[static_cast<std::size_t>(k)];
    const double tv = k / 15.0;
    const double tt = tv + rng.uniform(-0.02, 0.02);
    f.visible_stamp = HostTime::from_ns(static_cast<std::int64_t>(std::llround(tv * 1e9)));
    f.thermal_stamp = HostTime::from_ns(static_cast<std::int64_t>(std::llround(tt * 1e9)));
    const Eigen::Isometry3d T_w_cv = pose_at(tv), T_w_ct = pose_at(tt);
    f.R_camtv_camtt = T_w_cv.linear().transpose() * T_w_ct.linear();

    cv::Mat grey(visible.height, visible.width, CV_32FC1);
    for (int r = 0; r < visible.height; ++r) {
      for (int c = 0; c < visible.width; ++c) {
        const Eigen::Vector2d& xy = visible_rays[static_cast<std::size_t>(r * visible.width + c)];
        const Eigen::Vector3d d = T_w_cv.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1).normalized();
        const Hit h = cast(T_w_cv.translation(), d);
        // Night: 4..26 grey, a street lamp's pool of light on the right.
        const double lamp =
            std::exp(-std::pow((c - 520.0) / 60.0, 2) - std::pow((r - 300.0) / 80.0, 2));
        grey.at<float>(r, c) = static_cast<float>(4.0 + (22.0 + 120.0 * lamp) * h.visible);
      }
    }
    cv::Mat noise(grey.size(), CV_32FC1);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 2.5);
    grey += noise;
    cv::Mat grey8;
    grey.convertTo(grey8, CV_8U);
    cv::Mat tint[3];
    grey8.convertTo(tint[0], CV_8U, 0.8);
    grey8.convertTo(tint[1], CV_8U, 0.95);
    tint[2] = grey8;
    cv::merge(tint, 3, f.visible);

    const Eigen::Isometry3d T_w_th = T_w_ct * T_cam_thermal;
    f.thermal16.create(thermal.height, thermal.width, CV_16UC1);
    for (int r = 0; r < thermal.height; ++r) {
      for (int c = 0; c < thermal.width; ++c) {
        const Eigen::Vector2d& xy = thermal_rays[static_cast<std::size_t>(r * thermal.width + c)];
        const Eigen::Vector3d d = T_w_th.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1).normalized();
        const Hit h = cast(T_w_th.translation(), d);
        // ~60 counts of scene contrast, 2 counts of noise.
        f.thermal16.at<std::uint16_t>(r, c) = cv::saturate_cast<std::uint16_t>(
            7000.0 + 60.0 * (h.range > 0 ? h.temperature : 0.2) + rng.gaussian(2.0));
      }
    }
    double lo = 0, hi = 0;
    cv::minMaxLoc(f.thermal16, &lo, &hi);
    f.thermal16.convertTo(f.thermal8, CV_8U, 255.0 / std::max(1.0, hi - lo),
                          -255.0 * lo / std::max(1.0, hi - lo));

    // VLP-32C sweep from the camera (the lidar's offset on the rig does not matter here): 32
    // rings over -25..15 deg, 0.2 deg steps, returns to 100 m.
    f.p_cam_m.clear();
    for (int ring = 0; ring < 32; ++ring) {
      const double elevation = (-25.0 + 40.0 * ring / 31.0) * kDeg;
      for (int step = 0; step < 1800; ++step) {
        const double az = step * 0.2 * kDeg;
        const Eigen::Vector3d d_cam(std::cos(elevation) * std::sin(az), -std::sin(elevation),
                                    std::cos(elevation) * std::cos(az));
        const Hit h = cast(T_w_cv.translation(), T_w_cv.linear() * d_cam);
        if (h.range > 0 && h.range < 100) {
          f.p_cam_m.push_back(
              (h.range * d_cam + Eigen::Vector3d::Constant(rng.gaussian(0.01))).cast<float>());
        }
      }
    }
  }
  return frames;
}

// --- Timing ---------------------------------------------------------------------------------

/// This thread's CPU time [ms]: with cv::setNumThreads(1) all of the front end's work runs on
/// the calling thread, so this is its cost on one core, whatever else loads the machine (the
/// development machine is shared; wall time is reported for the total as well).
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

class StepTimer final : public vision::FrontendStepProbe {
 public:
  void begin(vision::FrontendStep step) override {
    if (!in_frame_) {
      frame_start_ = Clock::now();
      in_frame_ = true;
    }
    start_[index(step)] = thread_cpu_ms();
  }
  void end(vision::FrontendStep step) override {
    const std::size_t i = index(step);
    current_[i] += thread_cpu_ms() - start_[i];
  }
  void finish_frame() {
    double total = 0;
    for (std::size_t i = 0; i < current_.size(); ++i) {
      per_step_[i].push_back(current_[i]);
      total += current_[i];
      current_[i] = 0;
    }
    totals_.push_back(total);
    walls_.push_back(
        std::chrono::duration<double, std::milli>(Clock::now() - frame_start_).count());
    in_frame_ = false;
  }
  const std::vector<double>& step(std::size_t i) const { return per_step_[i]; }
  const std::vector<double>& totals() const { return totals_; }
  const std::vector<double>& walls() const { return walls_; }

 private:
  static std::size_t index(vision::FrontendStep s) { return static_cast<std::size_t>(s); }
  std::array<double, 6> start_{};
  std::array<double, 6> current_{};
  std::array<std::vector<double>, 6> per_step_;
  std::vector<double> totals_, walls_;
  Clock::time_point frame_start_;
  bool in_frame_ = false;
};

double quantile_ms(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5)];
}

struct RunFigures {
  StepTimer timer;
  /// a fresh front end's first frame (its buffers allocated, OpenCV's internals set up) [ms]
  double first_frame_ms = 0;
  double features = 0, tracked = 0, inliers = 0, previous = 0, depth = 0, lines = 0;
  double confidence = 0;
};

/// The frames a front end runs before it is timed: its first frame allocates its buffers and
/// sets up OpenCV's internals, a cost a front end pays once in a run of hours (reported apart,
/// as first_frame).
constexpr std::size_t kWarmUpFrames = 3;

/// Runs the drive through one front end: the first frames warm it (the first is timed on its
/// own), every later one is timed by step.
void run(const vision::FrontendConfig& config, const std::vector<FramePair>& frames, bool raw16,
         RunFigures& out) {
  const auto input = [&](const FramePair& f) {
    vision::FrontendInput in;
    in.visible_stamp = f.visible_stamp;
    in.thermal_stamp = f.thermal_stamp;
    in.visible = f.visible;
    in.thermal = raw16 ? f.thermal16 : f.thermal8;
    in.R_camtv_camtt = f.R_camtv_camtt;
    in.p_cam_m = f.p_cam_m;
    return in;
  };
  vision::FrontendFrame frame;
  vision::VisualFrontend frontend(config);
  StepTimer first;
  frontend.set_probe(&first);
  for (std::size_t k = 0; k < kWarmUpFrames && k < frames.size(); ++k) {
    frontend.process(input(frames[k]), frame);
    first.finish_frame();
  }
  if (!first.totals().empty()) out.first_frame_ms = first.totals().front();
  frontend.set_probe(&out.timer);
  for (std::size_t k = kWarmUpFrames; k < frames.size(); ++k) {
    frontend.process(input(frames[k]), frame);
    out.timer.finish_frame();
    out.features += frame.counts.features;
    out.tracked += frame.counts.tracked;
    out.inliers += frame.counts.ransac_inliers;
    out.previous += frame.counts.previous;
    out.depth += frame.counts.depth_associated;
    out.lines += frame.counts.lines;
    const vision::ImageQuality& q =
        config.mode == vision::FrontendMode::kFused     ? frame.quality.fused
        : config.mode == vision::FrontendMode::kVisible ? frame.quality.visible
                                                        : frame.quality.thermal;
    out.confidence += q.confidence;
  }
  const double n =
      static_cast<double>(frames.size() > kWarmUpFrames ? frames.size() - kWarmUpFrames : 1);
  out.features /= n;
  out.tracked /= n;
  out.depth /= n;
  out.lines /= n;
  out.confidence /= n;
}

vision::PinholeCamera camera_of(const config::CameraSection& c) {
  vision::PinholeCamera p;
  p.width = c.width;
  p.height = c.height;
  p.fx = c.fx;
  p.fy = c.fy;
  p.cx = c.cx;
  p.cy = c.cy;
  p.k1 = c.k1;
  p.k2 = c.k2;
  p.p1 = c.p1;
  p.p2 = c.p2;
  return p;
}

}  // namespace frontend_bench

int bench_frontend() {
  using namespace frontend_bench;
  cv::setNumThreads(1);  // one core, as the runner gives the front end one thread
  const config::PosedConfig rig = config::default_config();  // the M2DGR rig
  vision::FrontendConfig config;
  config.visible_camera = camera_of(rig.visible_camera);
  config.thermal_camera = camera_of(rig.thermal_camera);
  Eigen::Matrix4d T;
  for (int i = 0; i < 16; ++i)
    T(i / 4, i % 4) = rig.extrinsics.T_cam_thermal[static_cast<std::size_t>(i)];
  config.T_cam_thermal.matrix() = T;

  std::fprintf(stderr, "posectl bench frontend: rendering %d frame pairs and lidar sweeps...\n",
               kFrames);
  const std::vector<FramePair> frames =
      render_drive(config.visible_camera, config.thermal_camera, config.T_cam_thermal);
  double points = 0;
  for (const FramePair& f : frames) points += static_cast<double>(f.p_cam_m.size());
  report("frontend", "frame_pairs", kFrames, "count");
  report("frontend", "frame_pairs_timed", kFrames - static_cast<int>(kWarmUpFrames), "count");
  report("frontend", "lidar_points_mean", points / kFrames, "points");

  // The default: fused, 8-bit thermal video, per step.
  RunFigures fused;
  run(config, frames, false, fused);
  for (std::size_t i = 0; i < vision::kFrontendStepNames.size(); ++i) {
    const std::string name(vision::kFrontendStepNames[i]);
    report("frontend", name + "_median", quantile_ms(fused.timer.step(i), 0.5), "ms");
    report("frontend", name + "_p99", quantile_ms(fused.timer.step(i), 0.99), "ms");
  }
  report("frontend", "total_median", quantile_ms(fused.timer.totals(), 0.5), "ms");
  report("frontend", "total_p99", quantile_ms(fused.timer.totals(), 0.99), "ms");
  report("frontend", "total_max", quantile_ms(fused.timer.totals(), 1.0), "ms");
  report("frontend", "first_frame_total", fused.first_frame_ms, "ms");
  report("frontend", "total_wall_median", quantile_ms(fused.timer.walls(), 0.5), "ms");

  // 16-bit counts instead of 8-bit video: the thermal step adds the normalisation.
  RunFigures raw;
  run(config, frames, true, raw);
  report("frontend", "thermal16_median", quantile_ms(raw.timer.step(1), 0.5), "ms");
  report("frontend", "total16_median", quantile_ms(raw.timer.totals(), 0.5), "ms");

  // The three modes side by side (seed 000's comparison, on this synthetic night street).
  for (const vision::FrontendMode mode :
       {vision::FrontendMode::kVisible, vision::FrontendMode::kThermal,
        vision::FrontendMode::kFused}) {
    vision::FrontendConfig c = config;
    c.mode = mode;
    RunFigures r;
    if (mode == vision::FrontendMode::kFused) {
      r = fused;
    } else {
      run(c, frames, false, r);
    }
    const std::string m(vision::to_string(mode));
    report("frontend", m + "_total_median", quantile_ms(r.timer.totals(), 0.5), "ms");
    report("frontend", m + "_total_p99", quantile_ms(r.timer.totals(), 0.99), "ms");
    report("frontend", m + "_features_mean", r.features, "features");
    report("frontend", m + "_match_success", r.previous > 0 ? r.inliers / r.previous : 0, "ratio");
    report("frontend", m + "_depth_associated_mean", r.depth, "features");
    report("frontend", m + "_confidence_mean", r.confidence, "ratio");
  }

  // The wavelet of the fusion (seed 000 does not name one): cost and what tracking makes of it.
  for (const vision::Wavelet w :
       {vision::Wavelet::kHaar, vision::Wavelet::kLeGall53, vision::Wavelet::kCdf97}) {
    vision::FrontendConfig c = config;
    c.fusion.wavelet = w;
    RunFigures r;
    run(c, frames, false, r);
    const std::string name(vision::to_string(w));
    report("frontend", "fusion_" + name + "_median", quantile_ms(r.timer.step(2), 0.5), "ms");
    report("frontend", "fusion_" + name + "_match_success",
           r.previous > 0 ? r.inliers / r.previous : 0, "ratio");
    report("frontend", "fusion_" + name + "_depth_associated_mean", r.depth, "features");
  }

  // Seed 000's eq. (8) as published instead of the noise-aware detail rule.
  {
    vision::FrontendConfig c = config;
    c.fusion.noise_weighted = false;
    RunFigures r;
    run(c, frames, false, r);
    report("frontend", "fusion_published_match_success",
           r.previous > 0 ? r.inliers / r.previous : 0, "ratio");
    report("frontend", "fusion_published_confidence_mean", r.confidence, "ratio");
  }

  // Without the noise-adaptive pre-smoothing of the fusion inputs.
  {
    vision::FrontendConfig c = config;
    c.fusion.denoise = false;
    RunFigures r;
    run(c, frames, false, r);
    report("frontend", "fusion_no_denoise_median", quantile_ms(r.timer.step(2), 0.5), "ms");
    report("frontend", "fusion_no_denoise_match_success",
           r.previous > 0 ? r.inliers / r.previous : 0, "ratio");
    report("frontend", "fusion_no_denoise_confidence_mean", r.confidence, "ratio");
  }

  // Option: the thermal image registered at the lidar's depth instead of at infinity.
  {
    vision::FrontendConfig c = config;
    c.thermal_align.mode = vision::AlignMode::kLidarDepth;
    RunFigures r;
    run(c, frames, false, r);
    report("frontend", "lidar_depth_thermal_median", quantile_ms(r.timer.step(1), 0.5), "ms");
    report("frontend", "lidar_depth_total_median", quantile_ms(r.timer.totals(), 0.5), "ms");
    report("frontend", "lidar_depth_total_p99", quantile_ms(r.timer.totals(), 0.99), "ms");
    report("frontend", "lidar_depth_match_success", r.previous > 0 ? r.inliers / r.previous : 0,
           "ratio");
    report("frontend", "lidar_depth_depth_associated_mean", r.depth, "features");
  }

  // Option: the thermal camera's fixed pattern learnt and subtracted (scene-based NUC), in the
  // thermal step; thermal-only, where the thermal stream alone is tracked.
  {
    vision::FrontendConfig c = config;
    c.mode = vision::FrontendMode::kThermal;
    c.thermal_nuc.enabled = true;
    RunFigures r;
    run(c, frames, false, r);
    report("frontend", "thermal_nuc_thermal_median", quantile_ms(r.timer.step(1), 0.5), "ms");
    report("frontend", "thermal_nuc_total_median", quantile_ms(r.timer.totals(), 0.5), "ms");
    report("frontend", "thermal_nuc_match_success", r.previous > 0 ? r.inliers / r.previous : 0,
           "ratio");
  }

  // Option: LSD line features.
  vision::FrontendConfig with_lines = config;
  with_lines.lines = true;
  RunFigures lines;
  run(with_lines, frames, false, lines);
  report("frontend", "lines_tracking_median", quantile_ms(lines.timer.step(4), 0.5), "ms");
  report("frontend", "lines_mean", lines.lines, "lines");
  return 0;
}

}  // namespace posed::posectl
