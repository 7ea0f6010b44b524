#include <utility>

#include "core/estimator/fusion_core.hpp"

namespace posed {
namespace {

class StrapdownCore final : public FusionCore {
 public:
  explicit StrapdownCore(const StrapdownConfig& config) : strapdown_(config) {}

  void add_imu(const ImuSample& sample, std::vector<NavState>& states) override {
    if (auto state = strapdown_.add(sample)) states.push_back(*state);
  }
  // Dead reckoning has no use for a scan; dropping it returns its buffer to the pool at once.
  void add_scan(LidarScan, std::vector<NavState>&) override {}
  EstimatorMode mode() const override { return strapdown_.mode(); }
  std::string_view description() const override {
    return "strapdown (IMU-only dead reckoning: drifts without aiding)";
  }
  FusionFigures figures() const override {
    FusionFigures f;
    f.gyro_bias_radps = strapdown_.gyro_bias();
    return f;
  }

 private:
  Strapdown strapdown_;
};

}  // namespace

std::unique_ptr<FusionCore> make_strapdown_core(const StrapdownConfig& config) {
  return std::make_unique<StrapdownCore>(config);
}

}  // namespace posed
