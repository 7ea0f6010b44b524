#include "drivers/imu/a9_protocol.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "tests/common/realdata.hpp"

namespace posed::drivers::a9 {
namespace {

using Bytes = std::vector<std::uint8_t>;

// The values decoded by the vendor's reference procedure, from
// realdata/imu_a9/hfi_a9_frames_from_official_protocol_pdf.txt.
constexpr double kSensorFloats[9] = {
    0.0007034333539195359, -0.00032531702890992165, -0.0003665972617454827,
    0.012567436322569847,  -0.005658031441271305,   -1.0001224279403687,
    0.08434895426034927,   -0.035114582628011703,   0.790234386920929};
constexpr std::uint32_t kSensorCounter = 1802512704;
constexpr double kRpyFloats[3] = {0.6117326617240906, 8.191508293151855, -10.597005844116211};
constexpr std::uint32_t kRpyCounter = 2199820972;

std::filesystem::path a9_dir() {
  const auto dir = test::realdata_dir();
  return dir.empty() ? dir : dir / "imu_a9";
}

Bytes encode(const A9SensorFrame& f) {
  Bytes out(kSensorFrameSize);
  EXPECT_EQ(encode_a9_sensor_frame(f, out), kSensorFrameSize);
  return out;
}

A9SensorFrame make_frame(std::uint32_t counter) {
  A9SensorFrame f;
  f.counter_us = counter;
  f.frame_info = 0x0041ec29u + counter;
  for (std::size_t i = 0; i < 3; ++i) {
    f.gyro_radps[i] = 0.01f * static_cast<float>(counter % 97) + static_cast<float>(i);
    f.accel_g[i] = -0.5f * static_cast<float>(i) + 0.001f * static_cast<float>(counter % 13);
    f.mag[i] = 0.3f + 0.1f * static_cast<float>(i);
  }
  return f;
}

/// Frames with counters 1000, 1001, ... concatenated.
Bytes stream_of(int n, std::vector<A9SensorFrame>* frames = nullptr) {
  Bytes out;
  for (int i = 0; i < n; ++i) {
    const auto f = make_frame(1000u + static_cast<std::uint32_t>(i));
    if (frames != nullptr) frames->push_back(f);
    const auto b = encode(f);
    out.insert(out.end(), b.begin(), b.end());
  }
  return out;
}

/// Counters of the frames decoded from `bytes`; a null span means end of stream (finish()).
std::vector<std::uint32_t> decode_counters(A9Decoder& d, std::span<const std::uint8_t> bytes) {
  std::vector<std::uint32_t> counters;
  auto collect = [&](const A9Frame& f) {
    counters.push_back(f.kind == FrameKind::kSensor ? f.sensor.counter_us : f.attitude.counter_us);
  };
  if (bytes.data() == nullptr) {
    d.finish(collect);  // end of stream
  } else {
    d.feed(bytes, collect);
  }
  return counters;
}

std::vector<std::uint32_t> iota_counters(std::uint32_t first, int n) {
  std::vector<std::uint32_t> v;
  for (int i = 0; i < n; ++i) v.push_back(first + static_cast<std::uint32_t>(i));
  return v;
}

TEST(A9Crc, MatchesReferenceCheckValue) {
  // CRC-16/MODBUS check value for "123456789" (Greg Cook's CRC catalogue).
  const std::string s = "123456789";
  EXPECT_EQ(crc16_modbus({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}), 0x4B37);
}

TEST(A9Golden, RealSensorFrameDecodesToVendorValues) {
  const auto dir = a9_dir();
  if (dir.empty()) GTEST_SKIP() << "real data not found: set POSED_REALDATA or POSED_SOURCE_DIR";
  const Bytes raw = test::read_bytes(dir / "sensor_frame.bin");
  ASSERT_EQ(raw.size(), kSensorFrameSize) << dir / "sensor_frame.bin";
  EXPECT_EQ(crc16_modbus(std::span(raw).subspan(2, raw.size() - 4)), 0xfb5d);

  A9Decoder d;
  std::span<const std::uint8_t> in(raw);
  A9Frame f;
  ASSERT_EQ(d.next(in, f), DecodeStatus::kFrame);
  ASSERT_EQ(f.kind, FrameKind::kSensor);
  EXPECT_EQ(f.sensor.counter_us, kSensorCounter);
  EXPECT_EQ(f.sensor.frame_info, 0x0041ec29u);  // bytes 29 ec 41 00, little-endian
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(f.sensor.gyro_radps[i], static_cast<float>(kSensorFloats[i]));
    EXPECT_EQ(f.sensor.accel_g[i], static_cast<float>(kSensorFloats[3 + i]));
    EXPECT_EQ(f.sensor.mag[i], static_cast<float>(kSensorFloats[6 + i]));
  }
  EXPECT_EQ(d.next(in, f), DecodeStatus::kNeedMore);
  EXPECT_EQ(d.counters().frames_ok, 1u);
  EXPECT_EQ(d.counters().skipped_bytes, 0u);

  // Re-encoding reproduces the device's bytes exactly.
  EXPECT_EQ(encode(f.sensor), raw);

  // At rest the device reads −1 g on z; posed's specific force is +g on z.
  const ImuSample s = to_imu_sample(f.sensor, A9Mounting{}, HostTime::from_ns(5),
                                    DeviceTime::from_ns(kSensorCounter * 1000LL));
  EXPECT_NEAR(s.specific_force_mps2.z(), 1.0001224279403687 * kGravityMps2, 1e-5);
  EXPECT_GT(s.specific_force_mps2.z(), 9.8);
  EXPECT_NEAR(s.specific_force_mps2.x(), -0.012567436322569847 * kGravityMps2, 1e-6);
  EXPECT_NEAR(s.angular_velocity_radps.x(), 0.0007034333539195359, 1e-9);
  EXPECT_EQ(s.stamp, HostTime::from_ns(5));
}

TEST(A9Golden, RealAttitudeFrameDecodesToVendorValues) {
  const auto dir = a9_dir();
  if (dir.empty()) GTEST_SKIP() << "real data not found: set POSED_REALDATA or POSED_SOURCE_DIR";
  const Bytes raw = test::read_bytes(dir / "rpy_frame.bin");
  ASSERT_EQ(raw.size(), kAttitudeFrameSize) << dir / "rpy_frame.bin";
  EXPECT_EQ(crc16_modbus(std::span(raw).subspan(2, raw.size() - 4)), 0x0e17);

  A9Decoder d;
  std::span<const std::uint8_t> in(raw);
  A9Frame f;
  ASSERT_EQ(d.next(in, f), DecodeStatus::kFrame);
  ASSERT_EQ(f.kind, FrameKind::kAttitude);
  EXPECT_EQ(f.attitude.counter_us, kRpyCounter);
  EXPECT_EQ(f.attitude.frame_info, 0x0048e023u);
  EXPECT_EQ(f.attitude.roll_deg, static_cast<float>(kRpyFloats[0]));
  EXPECT_EQ(f.attitude.pitch_deg, static_cast<float>(kRpyFloats[1]));
  EXPECT_EQ(f.attitude.yaw_deg, static_cast<float>(kRpyFloats[2]));

  Bytes again(kAttitudeFrameSize);
  ASSERT_EQ(encode_a9_attitude_frame(f.attitude, again), kAttitudeFrameSize);
  EXPECT_EQ(again, raw);

  const A9Attitude att = to_attitude(f.attitude, HostTime{}, DeviceTime{});
  EXPECT_NEAR(att.roll_rad, kRpyFloats[0] * M_PI / 180.0, 1e-6);
  EXPECT_NEAR(att.pitch_rad, -kRpyFloats[1] * M_PI / 180.0, 1e-6);
  EXPECT_NEAR(att.yaw_rad, -kRpyFloats[2] * M_PI / 180.0, 1e-6);
}

TEST(A9Encode, RefusesTooSmallBuffer) {
  Bytes small(kSensorFrameSize - 1);
  EXPECT_EQ(encode_a9_sensor_frame(A9SensorFrame{}, small), 0u);
  Bytes small2(kAttitudeFrameSize - 1);
  EXPECT_EQ(encode_a9_attitude_frame(A9AttitudeFrame{}, small2), 0u);
}

TEST(A9Convert, SimEncodeDecodeRoundTripWithMounting) {
  // Mounted upside down and turned 90° about z: R = Rx(180°) · Rz(90°).
  A9Mounting m;
  m.R_imu_sensor = {{{0, -1, 0}, {-1, 0, 0}, {0, 0, -1}}};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  A9Decoder d;
  for (std::uint32_t i = 0; i < 200; ++i) {
    const Eigen::Vector3d w(u(rng), u(rng), u(rng));
    const Eigen::Vector3d f(u(rng), u(rng), u(rng));
    const Eigen::Vector3d mag(u(rng), u(rng), u(rng));
    const A9SensorFrame raw = a9_frame_from_si(w, f, mag, i * 6667u, m);
    const Bytes bytes = encode(raw);
    std::span<const std::uint8_t> in(bytes);
    A9Frame out;
    ASSERT_EQ(d.next(in, out), DecodeStatus::kFrame);
    EXPECT_EQ(out.sensor.counter_us, i * 6667u);
    const ImuSample s = to_imu_sample(out.sensor, m, HostTime{}, DeviceTime{});
    // float32 carries ~7 significant digits.
    EXPECT_TRUE(s.angular_velocity_radps.isApprox(w, 1e-6)) << s.angular_velocity_radps << "\n"
                                                            << w;
    EXPECT_TRUE(s.specific_force_mps2.isApprox(f, 1e-6)) << s.specific_force_mps2 << "\n" << f;
    EXPECT_TRUE(mag_in_imu_frame(out.sensor, m).isApprox(mag, 1e-6));
  }
}

TEST(A9Convert, AtRestSimulatedSampleMatchesDeviceSign) {
  const A9SensorFrame raw = a9_frame_from_si(
      Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, kGravityMps2), Eigen::Vector3d::Zero(), 0);
  EXPECT_FLOAT_EQ(raw.accel_g[2], -1.0f);  // what the real device reports at rest
}

TEST(A9Decoder, SplitAtEveryByte) {
  const Bytes stream = stream_of(4);
  for (std::size_t cut = 0; cut <= stream.size(); ++cut) {
    A9Decoder d;
    auto got = decode_counters(d, std::span(stream).first(cut));
    const auto rest = decode_counters(d, std::span(stream).subspan(cut));
    got.insert(got.end(), rest.begin(), rest.end());
    EXPECT_EQ(got, iota_counters(1000, 4)) << "cut at " << cut;
    EXPECT_EQ(d.counters().skipped_bytes, 0u) << "cut at " << cut;
    EXPECT_EQ(d.pending_bytes(), 0u);
  }
}

TEST(A9Decoder, ByteByByte) {
  const Bytes stream = stream_of(5);
  A9Decoder d;
  std::vector<std::uint32_t> got;
  for (const std::uint8_t b : stream) {
    const auto c = decode_counters(d, std::span(&b, 1));
    got.insert(got.end(), c.begin(), c.end());
  }
  EXPECT_EQ(got, iota_counters(1000, 5));
  EXPECT_EQ(d.counters().frames_ok, 5u);
  EXPECT_EQ(d.stream_position(), stream.size());
}

TEST(A9Decoder, ReportsStreamOffsets) {
  Bytes stream = {0x01, 0x02, 0x03};
  const Bytes frames = stream_of(2);
  stream.insert(stream.end(), frames.begin(), frames.end());
  A9Decoder d;
  std::vector<std::uint64_t> offsets;
  d.feed(stream, [&](const A9Frame& f) { offsets.push_back(f.stream_offset); });
  EXPECT_EQ(offsets, (std::vector<std::uint64_t>{3, 3 + kSensorFrameSize}));
  EXPECT_EQ(d.counters().skipped_bytes, 3u);
}

TEST(A9Decoder, GarbageIsSkippedAndCounted) {
  // Garbage holding lone sync bytes, a sync pair with a too-short LEN, and a false header whose
  // LEN (0xFF) swallows the following good frames: all of them must still come out.
  const Bytes garbage1 = {0x00, 0xAA, 0x13, 0xAA, 0xAA, 0x55, 0x02, 0x77};
  const Bytes garbage2 = {0xAA, 0x55, 0xFF, 0x10, 0x20};
  Bytes stream = garbage1;
  Bytes frames = stream_of(3);
  stream.insert(stream.end(), frames.begin(), frames.begin() + kSensorFrameSize);
  stream.insert(stream.end(), garbage2.begin(), garbage2.end());
  stream.insert(stream.end(), frames.begin() + kSensorFrameSize, frames.end());

  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, stream.size()}) {
    A9Decoder d;
    std::vector<std::uint32_t> got;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      const auto c =
          decode_counters(d, std::span(stream).subspan(at, std::min(chunk, stream.size() - at)));
      got.insert(got.end(), c.begin(), c.end());
    }
    // The false header still waits for its 260 bytes; end of stream releases the frames inside.
    EXPECT_EQ(got, iota_counters(1000, 1)) << "chunk " << chunk;
    const auto rest = decode_counters(d, {});
    got.insert(got.end(), rest.begin(), rest.end());
    EXPECT_EQ(got, iota_counters(1000, 3)) << "chunk " << chunk;
    EXPECT_EQ(d.counters().skipped_bytes, garbage1.size() + garbage2.size()) << "chunk " << chunk;
    EXPECT_EQ(d.counters().frames_ok, 3u);
    // The false 0xFF header spans the good frames after it, so its CRC fails; the frames inside
    // make it count as truncated, not corrupted.
    EXPECT_EQ(d.counters().truncated, 1u) << "chunk " << chunk;
    EXPECT_EQ(d.counters().bad_crc, 0u);
  }
}

TEST(A9Decoder, CorruptedCrcIsCountedAndNextFrameKept) {
  Bytes stream = stream_of(3);
  stream[kSensorFrameSize + 20] ^= 0x01;  // a bit flip in frame 2's accel
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{50}, stream.size()}) {
    A9Decoder d;
    std::vector<std::uint32_t> got;
    std::vector<DecodeStatus> events;
    for (std::size_t at = 0; at < stream.size(); at += chunk) {
      std::span<const std::uint8_t> in =
          std::span(stream).subspan(at, std::min(chunk, stream.size() - at));
      A9Frame f;
      for (DecodeStatus s; (s = d.next(in, f)) != DecodeStatus::kNeedMore;) {
        events.push_back(s);
        if (s == DecodeStatus::kFrame) got.push_back(f.sensor.counter_us);
      }
    }
    EXPECT_EQ(got, (std::vector<std::uint32_t>{1000, 1002})) << "chunk " << chunk;
    EXPECT_EQ(events, (std::vector<DecodeStatus>{DecodeStatus::kFrame, DecodeStatus::kBadCrc,
                                                 DecodeStatus::kFrame}));
    EXPECT_EQ(d.counters().bad_crc, 1u);
    EXPECT_EQ(d.counters().skipped_bytes, kSensorFrameSize);
    EXPECT_EQ(d.last_error().stream_offset, kSensorFrameSize);
    EXPECT_EQ(d.last_error().len, kSensorLen);
    EXPECT_NE(d.last_error().crc_stored, d.last_error().crc_computed);
  }
}

TEST(A9Decoder, TruncatedFrameDoesNotCostTheNextOne) {
  const Bytes frames = stream_of(3);
  Bytes stream(frames.begin(), frames.begin() + kSensorFrameSize);  // frame 1000
  stream.insert(stream.end(), frames.begin() + kSensorFrameSize,
                frames.begin() + kSensorFrameSize + 30);  // 30 bytes of frame 1001
  stream.insert(stream.end(), frames.begin() + 2 * kSensorFrameSize, frames.end());  // 1002
  A9Decoder d;
  EXPECT_EQ(decode_counters(d, stream), (std::vector<std::uint32_t>{1000, 1002}));
  EXPECT_EQ(d.counters().truncated, 1u);
  EXPECT_EQ(d.counters().bad_crc, 0u);
  EXPECT_EQ(d.counters().skipped_bytes, 30u);
}

TEST(A9Decoder, FinishCountsPartialFrameAtEndOfStream) {
  const Bytes frames = stream_of(2);
  A9Decoder d;
  EXPECT_EQ(decode_counters(d, std::span(frames).first(kSensorFrameSize + 10)).size(), 1u);
  EXPECT_EQ(d.pending_bytes(), 10u);
  A9Frame f;
  EXPECT_EQ(d.finish(f), DecodeStatus::kTruncated);
  EXPECT_EQ(d.finish(f), DecodeStatus::kNeedMore);
  EXPECT_EQ(d.counters().truncated, 1u);
  EXPECT_EQ(d.counters().skipped_bytes, 10u);
  EXPECT_EQ(d.last_error().stream_offset, kSensorFrameSize);
}

TEST(A9Decoder, UnknownKindWithValidCrcIsSkippedWhole) {
  // A CRC-valid frame of an unknown LEN (0x10): skipped as one unit, the next frame kept.
  Bytes unknown = {0xAA, 0x55, 0x10};
  for (int i = 0; i < 0x10; ++i) unknown.push_back(static_cast<std::uint8_t>(0xAA));
  const std::uint16_t crc = crc16_modbus(std::span(unknown).subspan(2));
  unknown.push_back(static_cast<std::uint8_t>(crc));
  unknown.push_back(static_cast<std::uint8_t>(crc >> 8));
  const Bytes good = stream_of(1);
  unknown.insert(unknown.end(), good.begin(), good.end());
  A9Decoder d;
  EXPECT_EQ(decode_counters(d, unknown), (std::vector<std::uint32_t>{1000}));
  EXPECT_EQ(d.counters().unknown_kind, 1u);
  EXPECT_EQ(d.counters().skipped_bytes, 0x10u + kFrameOverhead);
}

TEST(A9Decoder, MixedKindsInterleaved) {
  Bytes stream;
  for (std::uint32_t i = 0; i < 6; ++i) {
    Bytes b(kSensorFrameSize);
    if (i % 2 == 0) {
      b.resize(encode_a9_sensor_frame(make_frame(i), b));
    } else {
      A9AttitudeFrame a;
      a.counter_us = i;
      a.yaw_deg = 12.5f;
      b.resize(encode_a9_attitude_frame(a, b));
    }
    stream.insert(stream.end(), b.begin(), b.end());
  }
  A9Decoder d;
  EXPECT_EQ(decode_counters(d, stream), iota_counters(0, 6));
  EXPECT_EQ(d.counters().sensor_frames, 3u);
  EXPECT_EQ(d.counters().frames_ok, 6u);
}

TEST(A9Decoder, RandomCorruptionNeverLosesUntouchedFrames) {
  // Property: every frame whose bytes were not touched is decoded, in order.
  std::mt19937 rng(1234);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 20;
    Bytes stream = stream_of(n);
    std::vector<bool> touched(static_cast<std::size_t>(n), false);
    for (int k = 0; k < 3; ++k) {
      const std::size_t at = rng() % stream.size();
      stream[at] = static_cast<std::uint8_t>(rng());
      touched[at / kSensorFrameSize] = true;
    }
    A9Decoder d;
    std::vector<std::uint32_t> got;
    for (std::size_t at = 0; at < stream.size();) {
      const std::size_t len = std::min<std::size_t>(1 + rng() % 64, stream.size() - at);
      const auto c = decode_counters(d, std::span(stream).subspan(at, len));
      got.insert(got.end(), c.begin(), c.end());
      at += len;
    }
    const auto rest = decode_counters(d, {});
    got.insert(got.end(), rest.begin(), rest.end());
    std::vector<std::uint32_t> expected;
    for (int i = 0; i < n; ++i) {
      if (!touched[static_cast<std::size_t>(i)])
        expected.push_back(1000u + static_cast<std::uint32_t>(i));
    }
    // Touched frames may still decode (a byte overwritten with its own value).
    std::vector<std::uint32_t> got_untouched;
    for (const auto c : got) {
      if (!touched[c - 1000u]) got_untouched.push_back(c);
    }
    EXPECT_EQ(got_untouched, expected) << "trial " << trial;
  }
}

}  // namespace
}  // namespace posed::drivers::a9
