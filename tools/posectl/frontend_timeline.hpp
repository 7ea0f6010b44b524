#pragma once
// The camera front end frame by frame (`posectl inspect frontend`): with --timeline FILE, one
// CSV line per frame and mode (its time, features, image quality per stream); and for a
// recording whose colour view was degraded for a while (posectl sim's `smoke` scenario writes
// when into its posed.sim record: visible_degraded_from_s ...), each mode's figures before the
// smoke, while it was dense and after it cleared, so a person sees how each stream's confidence
// reacted. The whole-run means of the main table mix the three.

#include <array>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

#include "core/fusion/camera_front_end.hpp"

namespace posed::posectl {

/// When a simulated recording's colour view was degraded, from its posed.sim record [s, true
/// time since the start].
struct DegradedInterval {
  double from_s = 0, dense_from_s = 0, dense_to_s = 0, to_s = 0;
};
/// What a posectl sim recording's posed.sim record says about time.
struct SimTiming {
  /// host time of true time 0 [ns]
  std::int64_t host_epoch_ns = 0;
  /// when the colour view was degraded, if it was
  std::optional<DegradedInterval> degraded;
};
/// nullopt when the recording has no (complete) posed.sim record: not made by posectl sim.
std::optional<SimTiming> sim_timing(const std::string& path);

class FrontendTimeline final : public fusion::FrontendObserver {
 public:
  /// `csv_path` empty: no file. `timing`: a simulated recording's (times from its start; the
  /// phase table when it names a degraded interval).
  FrontendTimeline(std::string csv_path, std::optional<SimTiming> timing);
  ~FrontendTimeline() override;
  FrontendTimeline(const FrontendTimeline&) = delete;
  FrontendTimeline& operator=(const FrontendTimeline&) = delete;
  /// Creates the CSV file; false + `error` when it cannot.
  bool open(std::string& error);
  void on_frame(const vision::FrontendFrame& frame,
                const vision::VisualFrontend& frontend) override;
  /// The phase table (nothing without an interval); false when the CSV could not be written.
  bool finish();

 private:
  /// Sums over the frames of one mode in one phase.
  struct Sums {
    std::uint64_t frames = 0, features = 0, inliers = 0, carried_in = 0;
    std::array<double, 3> confidence{};       ///< visible, thermal, fused
    std::array<std::uint64_t, 3> assessed{};  ///< frames in which each stream was assessed
  };
  std::string csv_path_;
  std::optional<SimTiming> timing_;
  std::FILE* csv_ = nullptr;
  bool write_failed_ = false;
  std::array<std::array<Sums, 3>, 3> sums_{};  ///< [mode][before, dense, after]
};

}  // namespace posed::posectl
