#pragma once
// The camera front end's lidar depth against the truth, for recordings made by `posectl sim`
// (issue 9: "depth association error against ground truth"): the recording's `posed.sim`
// record rebuilds the simulator's world and drive; each feature with a lidar depth is cast as a
// ray from the true camera pose at its frame's stamp, and the depth of the surface it meets is
// compared with the associated one. Errors combine the association itself, the stacked scans'
// estimated poses and the clock sync, as a user of the depths sees them.

#include <array>
#include <memory>
#include <optional>
#include <string>
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
  /// "street_night seed 4, 8 s"
  const std::string& description() const { return description_; }

 private:
  struct World;
  FrontendDepthTruth() = default;
  std::unique_ptr<World> world_;
  std::string description_;
  std::array<std::vector<double>, 3> abs_errors_m_, relative_errors_, signed_relative_errors_;
  std::array<std::uint64_t, 3> missed_{};
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
