#pragma once
// The camera front end's lidar depth against the truth, for recordings made by `posectl sim`
// (issue 9: "depth association error against ground truth"): the recording's `posed.sim`
// record rebuilds the simulator's world and drive; each feature with a lidar depth is cast as a
// ray from the true camera pose at its frame's stamp, and the depth of the surface it meets is
// compared with the associated one. Errors combine the association itself, the stacked scans'
// estimated poses and the clock sync, as a user of the depths sees them.
//
// The same rays say whether the tracks follow the world: the point a feature's ray meets in one
// frame, projected from the true camera pose of the track's next frame, is where the feature
// should be seen there. A track that lands elsewhere follows something that does not move with
// the world (a corner of sensor noise, of the robot's own lamp's shading, a depth edge's
// occlusion line), and a camera motion measured on it is wrong however many such tracks agree.

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/fusion/camera_front_end.hpp"
#include "daemon/config/posed_config.hpp"

namespace posed::posectl {

struct DepthErrorStats {
  std::uint64_t features = 0;  ///< features with a lidar depth [1]
  std::uint64_t missed = 0;    ///< of those, whose true ray meets nothing within 200 m [1]
  double median_abs_m = 0;     ///< median |associated - true| [m]
  double p90_abs_m = 0;        ///< 90th percentile [m]
  double median_relative = 0;  ///< median |error| / true depth [-]
  /// median (associated - true) / true depth: a bias here scales every camera motion [-]
  double median_signed_relative = 0;
  double within_10_percent = 0;  ///< share of features within 10 % of the true depth [0..1]
};

/// Track steps (a feature seen in consecutive frames) whose world point moved by at least
/// `kMinTrueFlowPx` in the image under the true motion: smaller flows cannot tell a feature that
/// moves with the world from one that holds still.
struct TrackTruthStats {
  std::uint64_t steps = 0;           ///< track steps measured [1]
  std::uint64_t verified_steps = 0;  ///< of those, on tracks the front end had verified [1]
  double median_error_px = 0;        ///< median |observed - true| in the new frame [px]
  /// share within max(1 px, 20 % of the true flow) of where the world point went [0..1]
  double with_world = 0;
  /// share that moved less than 30 % of the true flow along it: held still in the image [0..1]
  double held_still = 0;
  double verified_with_world = 0;  ///< with_world among verified tracks [0..1]
  double verified_held_still = 0;  ///< held_still among verified tracks [0..1]
};

class FrontendDepthTruth final : public fusion::FrontendObserver {
 public:
  /// Null (and `why` set) when the recording was not made by posectl sim or the scenario
  /// cannot be rebuilt.
  static std::unique_ptr<FrontendDepthTruth> for_recording(const std::string& path,
                                                           const config::PosedConfig& config,
                                                           std::string& why);
  ~FrontendDepthTruth() override;
  void on_frame(const vision::FrontendFrame& frame,
                const vision::VisualFrontend& frontend) override;
  /// Per mode (visible, thermal, fused: vision::FrontendMode order).
  DepthErrorStats stats(vision::FrontendMode mode) const;
  /// Per mode: how well the tracks follow the world (see the file comment).
  TrackTruthStats track_stats(vision::FrontendMode mode) const;
  /// the least true image motion a track step needs to be judged [px]
  static constexpr double kMinTrueFlowPx = 2.0;
  /// "street_night seed 4, 8 s"
  const std::string& description() const { return description_; }

 private:
  struct World;
  FrontendDepthTruth() = default;
  std::unique_ptr<World> world_;
  std::string description_;
  std::array<std::vector<double>, 3> abs_errors_m_, relative_errors_, signed_relative_errors_;
  std::array<std::uint64_t, 3> missed_{};
  /// per mode: each live track's last observation and the world point its ray met then [m]
  struct LastSeen {
    Eigen::Vector2d normalised;
    Eigen::Vector3d p_map_m;
  };
  std::array<std::unordered_map<std::uint64_t, LastSeen>, 3> last_seen_;
  struct TrackStep {
    float error_px;
    bool with_world, held_still, verified;
  };
  std::array<std::vector<TrackStep>, 3> track_steps_;
  /// the visible camera's fx: normalised coordinates to pixels (the thermal and fused modes'
  /// features are rays on the visible camera's grid too) [px]
  double focal_px_ = 0;

  void add_track_step(std::size_t mode, const vision::FrontendFeature& f, const LastSeen& last,
                      const Eigen::Isometry3d& T_cam_map);
};

/// Calls each observer in turn.
class FrontendObservers final : public fusion::FrontendObserver {
 public:
  void add(fusion::FrontendObserver* observer) {
    if (observer != nullptr) observers_.push_back(observer);
  }
  void on_frame(const vision::FrontendFrame& frame,
                const vision::VisualFrontend& frontend) override {
    for (auto* o : observers_) o->on_frame(frame, frontend);
  }

 private:
  std::vector<fusion::FrontendObserver*> observers_;
};

}  // namespace posed::posectl
