// CameraClock: the D435i's frame metadata through ClockSync, and regularised arrivals for a
// camera without a clock, against a device clock and transport of the simulator's kind (offset,
// drift, least latency plus exponential jitter), so the true exposure time of every frame is
// known.

#include "daemon/pipeline/camera_clock.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "daemon/config/config_loader.hpp"
#include "drivers/camera/d4xx_metadata_writer.hpp"

namespace posed::pipeline {
namespace {

constexpr std::int64_t kHostEpochNs = 100'000'000'000;

/// A device clock and its transport: device time = offset + t (1 + drift), host arrival = host
/// epoch + t + latency + Exp(jitter mean), never reordered. t is true time.
struct DeviceLink {
  std::int64_t offset_ns = 0;
  double drift_ppm = 0;
  std::int64_t latency_ns = 0;
  std::int64_t jitter_mean_ns = 0;
};

class LinkModel {
 public:
  explicit LinkModel(DeviceLink link) : link_(link), rng_(7) {}
  /// The true time at which the device clock reads `device_ns`.
  std::int64_t true_at(std::int64_t device_ns) const {
    return std::llround(static_cast<double>(device_ns - link_.offset_ns) /
                        (1.0 + link_.drift_ppm * 1e-6));
  }
  std::int64_t device_at(std::int64_t t_ns) const {
    return link_.offset_ns +
           std::llround(static_cast<double>(t_ns) * (1.0 + link_.drift_ppm * 1e-6));
  }
  HostTime host_at(std::int64_t t_ns) const { return HostTime::from_ns(kHostEpochNs + t_ns); }
  HostTime arrival(std::int64_t t_ns) {
    std::exponential_distribution<double> jitter(
        1.0 / static_cast<double>(std::max<std::int64_t>(link_.jitter_mean_ns, 1)));
    const std::int64_t a = kHostEpochNs + t_ns + link_.latency_ns + std::llround(jitter(rng_));
    last_ = std::max(a, last_ + 1);
    return HostTime::from_ns(last_);
  }

 private:
  DeviceLink link_;
  std::mt19937_64 rng_;
  std::int64_t last_ = 0;
};

struct Worst {
  double after_lock_ms = 0;
  std::uint64_t frames = 0;
};

/// Frames at `rate_hz` for `seconds`, exposure midpoints regular on the device clock; returns the
/// largest |stamp - true exposure midpoint| once `settle_s` have passed.
Worst run_camera(const config::CameraSection& section, DeviceLink device, bool with_metadata,
                 double seconds, double settle_s, CameraClock& clock) {
  LinkModel model(device);
  const std::int64_t start_device_ns = model.device_at(0);
  std::vector<std::byte> metadata;
  Worst worst;
  for (std::uint64_t k = 0;; ++k) {
    const std::int64_t mid_device_ns =
        start_device_ns + std::llround(static_cast<double>(k + 1) * 1e9 / section.rate_hz);
    const std::int64_t t_mid = model.true_at(mid_device_ns);
    if (static_cast<double>(t_mid) * 1e-9 > seconds) break;
    const HostTime arrival = model.arrival(t_mid);
    if (with_metadata) {
      drivers::camera::D4xxFrameFacts f;
      f.frame_counter = static_cast<std::uint32_t>(k);
      f.sensor_timestamp_us = static_cast<std::uint32_t>(mid_device_ns / 1000);
      f.pts_us = f.sensor_timestamp_us - 4000;
      f.exposure_time_us = 8000;
      f.frame_interval_us = 66'667;
      drivers::camera::set_usb_arrival(f, arrival.ns);
      drivers::camera::encode_d4xx_metadata(f, metadata);
      EXPECT_TRUE(clock.on_metadata(metadata));
    }
    const HostTime stamp = clock.stamp(arrival);
    const double error_ms = std::abs(static_cast<double>((stamp - model.host_at(t_mid)).ns)) * 1e-6;
    if (static_cast<double>(t_mid) * 1e-9 > settle_s) {
      worst.after_lock_ms = std::max(worst.after_lock_ms, error_ms);
    }
    ++worst.frames;
  }
  return worst;
}

config::CameraSection visible_section() {
  config::CameraSection s = config::default_config().visible_camera;
  s.latency_s = 0.041;
  return s;
}

TEST(CameraClock, MetadataStampsFollowTheDeviceClockAcrossTheCounterWrap) {
  const config::CameraSection section = visible_section();
  CameraClock clock(section);
  // The D435i's µs counter 5 s before its 2^32 µs wrap, running 25 ppm fast; frames arrive at
  // least `latency_s` after their exposure midpoint, plus up to several ms of USB jitter.
  const std::int64_t before_wrap_ns = ((std::int64_t{1} << 32) - 5'000'000) * 1000;
  const DeviceLink device{before_wrap_ns, 25.0, static_cast<std::int64_t>(section.latency_s * 1e9),
                          2'000'000};
  const Worst w = run_camera(section, device, /*with_metadata=*/true, 40.0, 8.0, clock);
  EXPECT_GT(w.frames, 590u);
  EXPECT_EQ(clock.hardware_stamped(), w.frames);
  EXPECT_EQ(clock.status().state, SyncState::kLocked);
  // host = device * (1 + drift): a device 25 ppm fast reads as -25 ppm.
  EXPECT_NEAR(clock.status().drift_ppm, -25.0, 3.0);
  // USB jitter of ~2 ms (mean) never reaches the stamps.
  EXPECT_LT(w.after_lock_ms, 0.5) << "worst stamp error after lock";
}

TEST(CameraClock, WithoutMetadataArrivalsAreRegularisedToTheFramePeriod) {
  config::CameraSection section = config::default_config().thermal_camera;
  CameraClock clock(section);
  const DeviceLink device{0, -80.0, static_cast<std::int64_t>(section.latency_s * 1e9), 3'000'000};
  const Worst w = run_camera(section, device, /*with_metadata=*/false, 40.0, 8.0, clock);
  EXPECT_GT(w.frames, 990u);
  EXPECT_EQ(clock.hardware_stamped(), 0u);
  // Raw arrivals scatter by ~3 ms (exponential); the fitted period keeps stamps within 1 ms.
  EXPECT_LT(w.after_lock_ms, 1.0) << "worst stamp error after lock";
}

TEST(CameraClock, BadMetadataIsCountedAndTheFrameStillStamped) {
  CameraClock clock(visible_section());
  const std::byte garbage[5] = {};
  EXPECT_FALSE(clock.on_metadata(garbage));
  EXPECT_EQ(clock.bad_metadata(), 1u);
  const HostTime arrival = HostTime::from_ns(kHostEpochNs);
  const HostTime stamp = clock.stamp(arrival);
  EXPECT_LE(stamp.ns, arrival.ns);
  EXPECT_EQ(clock.hardware_stamped(), 0u);
}

}  // namespace
}  // namespace posed::pipeline
