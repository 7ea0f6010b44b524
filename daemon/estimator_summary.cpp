#include "daemon/estimator_summary.hpp"

#include <cstdio>

namespace posed {

void print_visual_summary(const FusionFigures& f) {
  static constexpr const char* kStreams[] = {"visible", "thermal", "fused"};
  bool any = false;
  for (std::size_t i = 0; i < f.visual.size(); ++i) {
    const VisualStreamFigures& v = f.visual[i];
    if (!v.configured) continue;
    if (!any) {
      std::printf("  in the estimate     %s at the last state\n",
                  modality_names(f.modalities).c_str());
    }
    any = true;
    if (v.landmarks) {
      std::printf(
          "  %-7s factors     %llu landmark reprojections from %llu frames (%llu landmarks "
          "anchored, %llu in the window now; %llu dropped as holding still, %llu after a solve, "
          "%llu observations gated); gate %s (left %llu, rejoined %llu times, %llu intervals gated "
          "out); %llu without frames; last omega %.2f, confidence %.2f, window residual median "
          "%.2f sigma, residual scale %.1f\n",
          kStreams[i], static_cast<unsigned long long>(v.factors),
          static_cast<unsigned long long>(v.frames),
          static_cast<unsigned long long>(v.landmarks_anchored),
          static_cast<unsigned long long>(v.landmarks_tracked),
          static_cast<unsigned long long>(v.landmarks_still),
          static_cast<unsigned long long>(v.landmarks_outliers),
          static_cast<unsigned long long>(v.landmarks_gated), v.active ? "open" : "closed",
          static_cast<unsigned long long>(v.left), static_cast<unsigned long long>(v.rejoined),
          static_cast<unsigned long long>(v.gated_out),
          static_cast<unsigned long long>(v.no_frames), v.omega, v.confidence, v.residual_median,
          v.residual_scale);
      continue;
    }
    // A thermal stream on standby (estimator.camera_thermal_standby) says how long it waited.
    char standby[64] = "";
    if (v.standby > 0) {
      std::snprintf(standby, sizeof standby, ", %llu on standby",
                    static_cast<unsigned long long>(v.standby));
    }
    std::printf(
        "  %-7s factors     %llu between factors (%llu from a keyframe) from %llu frames; gate %s "
        "(left %llu, rejoined %llu times, %llu intervals gated out%s); %llu without frames, %llu "
        "failed, %llu implausible; last omega %.2f, confidence %.2f, %d inliers, %d still "
        "features left out, reprojection %.2f px, window residual median %.2f sigma, residual "
        "scale %.1f\n",
        kStreams[i], static_cast<unsigned long long>(v.factors),
        static_cast<unsigned long long>(v.keyframe_factors),
        static_cast<unsigned long long>(v.frames), v.active ? "open" : "closed",
        static_cast<unsigned long long>(v.left), static_cast<unsigned long long>(v.rejoined),
        static_cast<unsigned long long>(v.gated_out), standby,
        static_cast<unsigned long long>(v.no_frames), static_cast<unsigned long long>(v.failed),
        static_cast<unsigned long long>(v.implausible), v.omega, v.confidence, v.inliers, v.still,
        v.reprojection_rms_px, v.residual_median, v.residual_scale);
  }
  const PoseSelectionFigures& s = f.selection;
  const std::uint64_t chosen =
      s.lidar_visual_inertial + s.lidar_inertial + s.visual_inertial + s.imu_only;
  if (chosen > 0) {
    std::printf(
        "  pose selection      initial values: %llu lidar-visual-inertial, %llu lidar-inertial, "
        "%llu visual-inertial, %llu IMU only (last threshold S %.3f m)\n",
        static_cast<unsigned long long>(s.lidar_visual_inertial),
        static_cast<unsigned long long>(s.lidar_inertial),
        static_cast<unsigned long long>(s.visual_inertial),
        static_cast<unsigned long long>(s.imu_only), s.last_threshold_m);
  }
}

}  // namespace posed
