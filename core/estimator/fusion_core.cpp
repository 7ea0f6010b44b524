#include "core/estimator/fusion_core.hpp"

namespace posed {

std::string modality_names(std::uint8_t modalities) {
  static constexpr std::pair<Modality, const char*> kNames[] = {{kModalityImu, "imu"},
                                                                {kModalityLidar, "lidar"},
                                                                {kModalityVisible, "visible"},
                                                                {kModalityThermal, "thermal"},
                                                                {kModalityFused, "fused"}};
  std::string out;
  for (const auto& [bit, name] : kNames) {
    if ((modalities & bit) == 0) continue;
    if (!out.empty()) out += '+';
    out += name;
  }
  return out.empty() ? "none" : out;
}

}  // namespace posed
