// Every IDL type serialized to CDR by Cyclone and back, and the bytes of a PoseStamped_ checked
// against a hand-computed little-endian layout: the wire format must be ROS 2's, since CDR is
// positional and a ROS 2 reader decodes it without any type negotiation.

#include "daemon/dds/cdr.hpp"

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "daemon/dds/convert.hpp"
#include "daemon/dds/generated_types.hpp"
#include "daemon/dds/participant.hpp"
#include "drivers/recording/ros2_messages.hpp"
#include "tests/unit/dds/test_domain.hpp"

namespace posed::dds {
namespace {

/// A writer and a reader of one type in one participant: Cyclone serializes at dds_write and the
/// reader hands back the serialized form (dds_takecdr), which is then decoded from raw bytes.
class CdrLoop : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    participant_ = detail::Participant::open(test::loopback_config(), error);
    ASSERT_NE(participant_, nullptr) << error;
  }

  /// Serializes `in`, returns the CDR bytes (encapsulation header included) and decodes those
  /// bytes into `out` (zero-initialised by the caller, freed with free_sample).
  template <class T>
  std::vector<unsigned char> round_trip(const dds_topic_descriptor_t& desc, const T& in, T& out) {
    const dds_entity_t pp = participant_->handle();
    std::string name = std::string("posed_test/") + desc.m_typename;
    std::replace(name.begin(), name.end(), ':', '_');  // ':' is not allowed in topic names
    dds_qos_t* qos = detail::make_topic_qos(Topic::kOdom);
    const dds_entity_t topic = dds_create_topic(pp, &desc, name.c_str(), qos, nullptr);
    EXPECT_GT(topic, 0) << name << ": " << dds_strretcode(topic);
    if (topic <= 0) return {};
    const dds_entity_t reader = dds_create_reader(pp, topic, qos, nullptr);
    const dds_entity_t writer = dds_create_writer(pp, topic, qos, nullptr);
    dds_delete_qos(qos);
    EXPECT_GT(reader, 0);
    EXPECT_GT(writer, 0);
    EXPECT_EQ(dds_write(writer, &in), DDS_RETCODE_OK);

    ddsi_serdata* written = nullptr;
    dds_sample_info_t info{};
    const bool got = test::eventually(
        [&] { return dds_takecdr(reader, &written, 1, &info, DDS_ANY_STATE) == 1; });
    EXPECT_TRUE(got) << name << ": nothing came back";
    if (!got) return {};

    std::vector<unsigned char> bytes(ddsi_serdata_size(written));
    ddsi_serdata_to_ser(written, 0, bytes.size(), bytes.data());
    // Decode from the bytes alone, as a remote reader would.
    ddsrt_iovec_t iov{};
    iov.iov_base = bytes.data();
    iov.iov_len = static_cast<decltype(iov.iov_len)>(bytes.size());
    ddsi_serdata* parsed =
        ddsi_serdata_from_ser_iov(written->type, SDK_DATA, 1, &iov, bytes.size());
    EXPECT_NE(parsed, nullptr);
    if (parsed != nullptr) {
      EXPECT_TRUE(ddsi_serdata_to_sample(parsed, &out, nullptr, nullptr));
      ddsi_serdata_unref(parsed);
    }
    ddsi_serdata_unref(written);
    dds_delete(writer);
    dds_delete(reader);
    dds_delete(topic);
    return bytes;
  }

  template <class T>
  static void free_sample(const dds_topic_descriptor_t& desc, T& sample) {
    dds_sample_free(&sample, &desc, DDS_FREE_CONTENTS);
  }

  std::unique_ptr<detail::Participant> participant_;
};

/// Little-endian CDR writer for the expected bytes; alignment is relative to the payload start
/// (after the 4-byte encapsulation header), as in XCDR1.
struct CdrBuilder {
  std::vector<unsigned char> bytes{0x00, 0x01, 0x00, 0x00};  // CDR_LE, options 0
  void align(std::size_t n) {
    while ((bytes.size() - 4) % n != 0) bytes.push_back(0);
  }
  template <class T>
  void put(T value) {
    align(sizeof(T));
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));  // the test host is little-endian (x86-64, arm64)
    bytes.insert(bytes.end(), raw, raw + sizeof(T));
  }
  void put_string(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size() + 1));  // length counts the terminating NUL
    bytes.insert(bytes.end(), s.begin(), s.end());
    bytes.push_back(0);
  }
};

TEST_F(CdrLoop, PoseStampedBytesMatchRos2Layout) {
  char frame[] = "world";  // 6 bytes with NUL: forces 2 bytes of padding before the doubles
  geometry_msgs_msg_dds__PoseStamped_ in{};
  in.header.stamp = {1'700'000'000, 123'456'789};
  in.header.frame_id = frame;
  in.pose.position = {1.5, -2.25, 3.125};
  in.pose.orientation = {0.1, 0.2, 0.3, 0.9};
  geometry_msgs_msg_dds__PoseStamped_ out{};
  const auto bytes = round_trip(geometry_msgs_msg_dds__PoseStamped__desc, in, out);

  CdrBuilder expected;
  expected.put<std::int32_t>(1'700'000'000);
  expected.put<std::uint32_t>(123'456'789);
  expected.put_string("world");
  for (double v : {1.5, -2.25, 3.125, 0.1, 0.2, 0.3, 0.9}) expected.put(v);
  ASSERT_EQ(expected.bytes.size(), 4u + 80u);  // 4 + 4 + 4 + 6 + 2 pad + 7 * 8
  EXPECT_EQ(bytes, expected.bytes);

  EXPECT_EQ(out.header.stamp.sec, 1'700'000'000);
  EXPECT_EQ(out.header.stamp.nanosec, 123'456'789u);
  EXPECT_STREQ(out.header.frame_id, "world");
  EXPECT_EQ(out.pose.position.y, -2.25);
  EXPECT_EQ(out.pose.orientation.w, 0.9);
  free_sample(geometry_msgs_msg_dds__PoseStamped__desc, out);
}

TEST_F(CdrLoop, PoseWithCovarianceStampedBytesMatchRos2Layout) {
  // What RViz's 2D Pose Estimate sends on /initialpose: header, pose, then 36 doubles.
  char frame[] = "map";  // 4 bytes with NUL: the doubles need no padding
  geometry_msgs_msg_dds__PoseWithCovarianceStamped_ in{};
  in.header.stamp = {1'700'000'000, 5};
  in.header.frame_id = frame;
  in.pose.pose.position = {1.5, -2.25, 0.0};
  in.pose.pose.orientation = {0.0, 0.0, 0.6, 0.8};
  for (int i = 0; i < 36; ++i) in.pose.covariance[i] = 0.5 * i;
  geometry_msgs_msg_dds__PoseWithCovarianceStamped_ out{};
  const auto bytes = round_trip(geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc, in, out);

  CdrBuilder expected;
  expected.put<std::int32_t>(1'700'000'000);
  expected.put<std::uint32_t>(5);
  expected.put_string("map");
  for (double v : {1.5, -2.25, 0.0, 0.0, 0.0, 0.6, 0.8}) expected.put(v);
  for (int i = 0; i < 36; ++i) expected.put(0.5 * i);
  ASSERT_EQ(expected.bytes.size(), 4u + 360u);  // 4 + 4 + 4 + 4 + 7 * 8 + 36 * 8
  EXPECT_EQ(bytes, expected.bytes);

  EXPECT_STREQ(out.header.frame_id, "map");
  EXPECT_EQ(out.pose.pose.orientation.z, 0.6);
  EXPECT_EQ(out.pose.covariance[35], 17.5);
  free_sample(geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc, out);
}

TEST_F(CdrLoop, TimeBytesAreSecThenNanosec) {
  builtin_interfaces_msg_dds__Time_ in{-5, 999'999'999};
  builtin_interfaces_msg_dds__Time_ out{};
  const auto bytes = round_trip(builtin_interfaces_msg_dds__Time__desc, in, out);
  CdrBuilder expected;
  expected.put<std::int32_t>(-5);
  expected.put<std::uint32_t>(999'999'999);
  EXPECT_EQ(bytes, expected.bytes);
  EXPECT_EQ(out.sec, -5);
  EXPECT_EQ(out.nanosec, 999'999'999u);
}

TEST_F(CdrLoop, HeaderRoundTrips) {
  char frame[] = "map";
  std_msgs_msg_dds__Header_ in{{7, 8}, frame};
  std_msgs_msg_dds__Header_ out{};
  const auto bytes = round_trip(std_msgs_msg_dds__Header__desc, in, out);
  CdrBuilder expected;
  expected.put<std::int32_t>(7);
  expected.put<std::uint32_t>(8);
  expected.put_string("map");
  EXPECT_EQ(bytes, expected.bytes);
  EXPECT_EQ(out.stamp.sec, 7);
  EXPECT_EQ(out.stamp.nanosec, 8u);
  EXPECT_STREQ(out.frame_id, "map");
  free_sample(std_msgs_msg_dds__Header__desc, out);
}

/// Types without strings or sequences round-trip bit for bit (memcmp is exact: no padding
/// inside these all-double structs).
template <class T>
void expect_same_bits(const T& a, const T& b) {
  EXPECT_EQ(std::memcmp(&a, &b, sizeof(T)), 0);
}

TEST_F(CdrLoop, GeometryTypesRoundTrip) {
  {
    geometry_msgs_msg_dds__Point_ in{1.0, -2.0, 1e-300}, out{};
    const auto bytes = round_trip(geometry_msgs_msg_dds__Point__desc, in, out);
    EXPECT_EQ(bytes.size(), 4u + 24u);
    expect_same_bits(in, out);
  }
  {
    geometry_msgs_msg_dds__Quaternion_ in{0.5, -0.5, 0.5, -0.5}, out{};
    const auto bytes = round_trip(geometry_msgs_msg_dds__Quaternion__desc, in, out);
    EXPECT_EQ(bytes.size(), 4u + 32u);
    expect_same_bits(in, out);
  }
  {
    geometry_msgs_msg_dds__Pose_ in{{1, 2, 3}, {4, 5, 6, 7}}, out{};
    const auto bytes = round_trip(geometry_msgs_msg_dds__Pose__desc, in, out);
    CdrBuilder expected;
    for (double v : {1, 2, 3, 4, 5, 6, 7}) expected.put(v);  // position then x y z w
    EXPECT_EQ(bytes, expected.bytes);
    expect_same_bits(in, out);
  }
  {
    geometry_msgs_msg_dds__PoseWithCovariance_ in{}, out{};
    in.pose = {{1, 2, 3}, {0, 0, 0, 1}};
    for (int i = 0; i < 36; ++i) in.covariance[i] = 0.01 * i;
    const auto bytes = round_trip(geometry_msgs_msg_dds__PoseWithCovariance__desc, in, out);
    EXPECT_EQ(bytes.size(), 4u + (7u + 36u) * 8u);
    expect_same_bits(in, out);
  }
  {
    geometry_msgs_msg_dds__Vector3_ in{-1, 0.25, 9}, out{};
    round_trip(geometry_msgs_msg_dds__Vector3__desc, in, out);
    expect_same_bits(in, out);
  }
  {
    geometry_msgs_msg_dds__Twist_ in{{1, 2, 3}, {-4, -5, -6}}, out{};
    const auto bytes = round_trip(geometry_msgs_msg_dds__Twist__desc, in, out);
    EXPECT_EQ(bytes.size(), 4u + 48u);
    expect_same_bits(in, out);
  }
  {
    geometry_msgs_msg_dds__TwistWithCovariance_ in{}, out{};
    in.twist = {{1, 2, 3}, {4, 5, 6}};
    for (int i = 0; i < 36; ++i) in.covariance[i] = -0.5 * i;
    const auto bytes = round_trip(geometry_msgs_msg_dds__TwistWithCovariance__desc, in, out);
    EXPECT_EQ(bytes.size(), 4u + (6u + 36u) * 8u);
    expect_same_bits(in, out);
  }
}

TEST_F(CdrLoop, OdometryRoundTripsWithRos2FieldOrder) {
  char frame[] = "map";
  char child[] = "base_link";
  nav_msgs_msg_dds__Odometry_ in{};
  in.header = {{100, 200}, frame};
  in.child_frame_id = child;
  in.pose.pose = {{1, 2, 3}, {0, 0, 0.6, 0.8}};
  in.twist.twist = {{0.5, 0, 0}, {0, 0, 0.1}};
  for (int i = 0; i < 36; ++i) {
    in.pose.covariance[i] = i;
    in.twist.covariance[i] = 100 + i;
  }
  nav_msgs_msg_dds__Odometry_ out{};
  const auto bytes = round_trip(nav_msgs_msg_dds__Odometry__desc, in, out);

  CdrBuilder expected;  // header, child_frame_id, pose (+cov), twist (+cov)
  expected.put<std::int32_t>(100);
  expected.put<std::uint32_t>(200);
  expected.put_string("map");
  expected.put_string("base_link");
  for (double v : {1.0, 2.0, 3.0, 0.0, 0.0, 0.6, 0.8}) expected.put(v);
  for (int i = 0; i < 36; ++i) expected.put(static_cast<double>(i));
  for (double v : {0.5, 0.0, 0.0, 0.0, 0.0, 0.1}) expected.put(v);
  for (int i = 0; i < 36; ++i) expected.put(static_cast<double>(100 + i));
  EXPECT_EQ(bytes, expected.bytes);

  EXPECT_STREQ(out.header.frame_id, "map");
  EXPECT_STREQ(out.child_frame_id, "base_link");
  EXPECT_EQ(out.pose.pose.orientation.z, 0.6);
  EXPECT_EQ(out.twist.twist.angular.z, 0.1);
  EXPECT_EQ(out.pose.covariance[35], 35.0);
  EXPECT_EQ(out.twist.covariance[0], 100.0);
  free_sample(nav_msgs_msg_dds__Odometry__desc, out);
}

posed_msgs_msg_dds__StreamStatus_ make_stream(char* name, char* state, char* health, double k) {
  posed_msgs_msg_dds__StreamStatus_ s{};
  s.name = name;
  s.rate_hz = 400.0 * k;
  s.received = 1000 + static_cast<std::uint64_t>(k);
  s.decoded = 999;
  s.dropped = 1;
  s.malformed = 2;
  s.clock_offset_ns = -123'456'789'012;
  s.clock_drift_ppm = 12.5;
  s.clock_jitter_ns = 3000.0;
  s.clock_uncertainty_ns = 150.0;
  s.clock_state = state;
  s.health = health;
  return s;
}

void expect_stream_eq(const posed_msgs_msg_dds__StreamStatus_& a,
                      const posed_msgs_msg_dds__StreamStatus_& b) {
  EXPECT_STREQ(a.name, b.name);
  EXPECT_EQ(a.rate_hz, b.rate_hz);
  EXPECT_EQ(a.received, b.received);
  EXPECT_EQ(a.decoded, b.decoded);
  EXPECT_EQ(a.dropped, b.dropped);
  EXPECT_EQ(a.malformed, b.malformed);
  EXPECT_EQ(a.clock_offset_ns, b.clock_offset_ns);
  EXPECT_EQ(a.clock_drift_ppm, b.clock_drift_ppm);
  EXPECT_EQ(a.clock_jitter_ns, b.clock_jitter_ns);
  EXPECT_EQ(a.clock_uncertainty_ns, b.clock_uncertainty_ns);
  EXPECT_STREQ(a.clock_state, b.clock_state);
  EXPECT_STREQ(a.health, b.health);
}

TEST_F(CdrLoop, StreamStatusRoundTrips) {
  char name[] = "imu", state[] = "locked", health[] = "ok";
  auto in = make_stream(name, state, health, 1.0);
  posed_msgs_msg_dds__StreamStatus_ out{};
  round_trip(posed_msgs_msg_dds__StreamStatus__desc, in, out);
  expect_stream_eq(in, out);
  free_sample(posed_msgs_msg_dds__StreamStatus__desc, out);
}

TEST_F(CdrLoop, StatusRoundTripsWithStreams) {
  char frame[] = "map", version[] = "posed 0.1.0", mode[] = "strapdown", summary[] = "2 streams";
  char imu[] = "imu", lidar[] = "lidar", locked[] = "locked", conv[] = "converging";
  char ok[] = "ok", degraded[] = "degraded";
  posed_msgs_msg_dds__StreamStatus_ streams[2] = {make_stream(imu, locked, ok, 1.0),
                                                  make_stream(lidar, conv, degraded, 2.0)};
  posed_msgs_msg_dds__Status_ in{};
  in.header = {{1, 2}, frame};
  in.version = version;
  in.estimator_mode = mode;
  char fused[] = "fused";
  in.camera.mode = fused;
  in.camera.frames = 42;
  in.camera.features = 250;
  in.camera.confidence[2] = 0.75;
  in.camera.omega[0] = 80.5;
  in.uptime_s = 3600.25;
  in.summary = summary;
  char lost[] = "lost";
  in.mapping = {lost, 0, 0, 21, 0.5, 7};
  in.streams._buffer = streams;
  in.streams._length = 2;
  in.streams._maximum = 2;
  in.streams._release = false;
  posed_msgs_msg_dds__Status_ out{};
  round_trip(posed_msgs_msg_dds__Status__desc, in, out);
  EXPECT_STREQ(out.header.frame_id, "map");
  EXPECT_STREQ(out.version, "posed 0.1.0");
  EXPECT_STREQ(out.estimator_mode, "strapdown");
  EXPECT_STREQ(out.camera.mode, "fused");
  EXPECT_EQ(out.camera.frames, 42u);
  EXPECT_EQ(out.camera.features, 250);
  EXPECT_EQ(out.camera.confidence[2], 0.75);
  EXPECT_EQ(out.camera.omega[0], 80.5);
  EXPECT_EQ(out.uptime_s, 3600.25);
  EXPECT_STREQ(out.summary, "2 streams");
  EXPECT_STREQ(out.mapping.state, "lost");
  EXPECT_EQ(out.mapping.fixes, 21u);
  EXPECT_EQ(out.mapping.correction_m, 0.5);
  EXPECT_EQ(out.mapping.scans_skipped, 7u);
  ASSERT_EQ(out.streams._length, 2u);
  expect_stream_eq(out.streams._buffer[0], streams[0]);
  expect_stream_eq(out.streams._buffer[1], streams[1]);
  free_sample(posed_msgs_msg_dds__Status__desc, out);
}

// The ROS 2 tool topics through the same fill_* the Publisher uses and back through Cyclone's
// serializer: sequences, nested sequences and strings land where a ROS 2 reader looks.
TEST_F(CdrLoop, TfPathAndDiagnosticsRoundTripThroughTheirFillers) {
  TfMessage tf;
  tf.transforms.resize(2);
  tf.transforms[0] = {WallTime::from_ns(1'500'000'000),
                      "map",
                      "odom",
                      {1, 2, 3},
                      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()))};
  tf.transforms[1] = {WallTime::from_ns(2'000'000'001),
                      "odom",
                      "base_link",
                      {-4, 5, 0.5},
                      Eigen::Quaterniond::Identity()};
  tf2_msgs_msg_dds__TFMessage_ tf_in{};
  std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms;
  detail::fill_tf(tf, tf_in, transforms);
  tf2_msgs_msg_dds__TFMessage_ tf_out{};
  round_trip(tf2_msgs_msg_dds__TFMessage__desc, tf_in, tf_out);
  const TfMessage tf_back = detail::to_plain(tf_out);
  ASSERT_EQ(tf_back.transforms.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(tf_back.transforms[i].stamp, tf.transforms[i].stamp);
    EXPECT_EQ(tf_back.transforms[i].parent_frame, tf.transforms[i].parent_frame);
    EXPECT_EQ(tf_back.transforms[i].child_frame, tf.transforms[i].child_frame);
    EXPECT_EQ(tf_back.transforms[i].p_parent_child_m, tf.transforms[i].p_parent_child_m);
    EXPECT_EQ(tf_back.transforms[i].q_parent_child.coeffs(),
              tf.transforms[i].q_parent_child.coeffs());
  }
  free_sample(tf2_msgs_msg_dds__TFMessage__desc, tf_out);

  PathMessage path;
  path.stamp = WallTime::from_ns(3'000'000'000);
  for (int i = 0; i < 3; ++i) {
    PoseMessage p;
    p.stamp = WallTime::from_ns(1'000'000'000LL * (i + 1));
    p.p_map_base_m = {static_cast<double>(i), 0, 0};
    path.poses.push_back(p);
  }
  char map[] = "map";
  nav_msgs_msg_dds__Path_ path_in{};
  std::vector<geometry_msgs_msg_dds__PoseStamped_> poses;
  detail::fill_path(path, map, path_in, poses);
  nav_msgs_msg_dds__Path_ path_out{};
  round_trip(nav_msgs_msg_dds__Path__desc, path_in, path_out);
  EXPECT_STREQ(path_out.header.frame_id, "map");
  ASSERT_EQ(path_out.poses._length, 3u);
  EXPECT_STREQ(path_out.poses._buffer[2].header.frame_id, "map");
  const PathMessage path_back = detail::to_plain(path_out);
  EXPECT_EQ(path_back.stamp, path.stamp);
  EXPECT_EQ(path_back.poses[2].stamp, path.poses[2].stamp);
  EXPECT_EQ(path_back.poses[2].p_map_base_m, path.poses[2].p_map_base_m);
  free_sample(nav_msgs_msg_dds__Path__desc, path_out);

  DiagnosticsMessage diag;
  diag.stamp = WallTime::from_ns(4'000'000'000);
  diag.status.push_back({DiagnosticStatusMessage::kWarn,
                         "posed: lidar",
                         "degraded",
                         "lidar",
                         {{"rate", "9.9 Hz"}, {"malformed", "12"}}});
  diag.status.push_back(
      {DiagnosticStatusMessage::kOk, "posed: estimator", "lidar_inertial", "fusion core", {}});
  diagnostic_msgs_msg_dds__DiagnosticArray_ diag_in{};
  std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> statuses;
  std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>> values;
  detail::fill_diagnostics(diag, diag_in, statuses, values);
  diag_in.header.frame_id = map;
  diagnostic_msgs_msg_dds__DiagnosticArray_ diag_out{};
  round_trip(diagnostic_msgs_msg_dds__DiagnosticArray__desc, diag_in, diag_out);
  const DiagnosticsMessage diag_back = detail::to_plain(diag_out);
  ASSERT_EQ(diag_back.status.size(), 2u);
  EXPECT_EQ(diag_back.status[0].level, DiagnosticStatusMessage::kWarn);
  EXPECT_EQ(diag_back.status[0].name, "posed: lidar");
  EXPECT_EQ(diag_back.status[0].hardware_id, "lidar");
  EXPECT_EQ(diag_back.status[0].values, diag.status[0].values);
  EXPECT_EQ(diag_back.status[1].message, "lidar_inertial");
  EXPECT_TRUE(diag_back.status[1].values.empty());
  free_sample(diagnostic_msgs_msg_dds__DiagnosticArray__desc, diag_out);
}

/// The wire form without what Cyclone adds for the transport: XCDR lets a writer pad the payload
/// to a multiple of 4 and count the padding in the low bits of the encapsulation options (ROS 2
/// readers, Foxglove and MCAP take either form).
std::vector<unsigned char> unpadded(std::vector<unsigned char> bytes) {
  if (bytes.size() < 4) return bytes;
  const auto padding =
      static_cast<std::ptrdiff_t>(std::min<std::size_t>(bytes[3] & 3u, bytes.size() - 4));
  // erase, not resize: GCC's -O1 (the ASan build) warns about resize's growing branch here
  bytes.erase(bytes.end() - padding, bytes.end());
  bytes[2] = bytes[3] = 0;
  return bytes;
}

// The status's last member is the mapping stage's, laid out as the ros2msg schema says (string
// state, uint64 keyframes, loops, fixes, float64 correction_m, uint64 scans_skipped), with
// nothing after it: a reader of an older layout still finds every field before it where it was.
TEST_F(CdrLoop, StatusEndsWithTheMappingStatusAsItsSchemaSays) {
  StatusMessage msg;
  msg.stamp = WallTime::from_ns(5'000'000'000);
  msg.version = "posed 0.1.0";
  msg.summary = "x";
  msg.streams.resize(1);
  msg.mapping = {"localised", 12, 3, 45, 6.75, 8};
  posed_msgs_msg_dds__Status_ in{};
  std::vector<posed_msgs_msg_dds__StreamStatus_> streams;
  detail::fill_status(msg, in, streams);
  char map[] = "map";
  in.header.frame_id = map;
  posed_msgs_msg_dds__Status_ out{};
  const auto wire = unpadded(round_trip(posed_msgs_msg_dds__Status__desc, in, out));
  free_sample(posed_msgs_msg_dds__Status__desc, out);
  std::vector<std::byte> tapped;
  detail::encode_cdr(Topic::kStatus, &in, tapped);
  ASSERT_EQ(tapped.size(), wire.size());
  EXPECT_EQ(std::memcmp(tapped.data(), wire.data(), wire.size()), 0);

  // The mapping member starts at the state string's length, the last one like it in the message.
  const unsigned char state[] = {10, 0, 0, 0, 'l', 'o', 'c', 'a', 'l', 'i', 's', 'e', 'd', 0};
  const auto at = std::find_end(wire.begin(), wire.end(), std::begin(state), std::end(state));
  ASSERT_NE(at, wire.end());
  CdrBuilder expected;
  expected.bytes.assign(wire.begin(), at);
  expected.put_string("localised");
  expected.put<std::uint64_t>(12);
  expected.put<std::uint64_t>(3);
  expected.put<std::uint64_t>(45);
  expected.put<double>(6.75);
  expected.put<std::uint64_t>(8);
  EXPECT_EQ(wire, expected.bytes);
}

TEST_F(CdrLoop, PointCloud2BytesMatchRos2Layout) {
  CloudMessage cloud;
  cloud.stamp = WallTime::from_ns(5'000'000'007);
  cloud.frame_id = "velodyne";
  cloud.fields = {{"x", 0, PointFieldMessage::kFloat32, 1},
                  {"ring", 4, PointFieldMessage::kUint16, 1}};
  cloud.point_step = 6;
  cloud.width = 2;
  cloud.data = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  sensor_msgs_msg_dds__PointCloud2_ in{};
  std::vector<sensor_msgs_msg_dds__PointField_> fields;
  detail::fill_cloud(cloud, in, fields);
  sensor_msgs_msg_dds__PointCloud2_ out{};
  const auto bytes = round_trip(sensor_msgs_msg_dds__PointCloud2__desc, in, out);

  CdrBuilder expected;  // PointCloud2.msg in order; uint8 and bool are one byte, unaligned
  expected.put<std::int32_t>(5);
  expected.put<std::uint32_t>(7);
  expected.put_string("velodyne");
  expected.put<std::uint32_t>(1);  // height
  expected.put<std::uint32_t>(2);  // width
  expected.put<std::uint32_t>(2);  // fields
  expected.put_string("x");
  expected.put<std::uint32_t>(0);
  expected.put<std::uint8_t>(7);
  expected.put<std::uint32_t>(1);
  expected.put_string("ring");
  expected.put<std::uint32_t>(4);
  expected.put<std::uint8_t>(4);
  expected.put<std::uint32_t>(1);
  expected.put<std::uint8_t>(0);    // is_bigendian
  expected.put<std::uint32_t>(6);   // point_step
  expected.put<std::uint32_t>(12);  // row_step
  expected.put<std::uint32_t>(12);  // data
  for (int i = 1; i <= 12; ++i) expected.put<std::uint8_t>(static_cast<std::uint8_t>(i));
  expected.put<std::uint8_t>(1);  // is_dense
  EXPECT_EQ(unpadded(bytes), expected.bytes);

  const CloudMessage back = detail::to_plain(out);
  EXPECT_EQ(back.stamp, cloud.stamp);
  EXPECT_EQ(back.frame_id, "velodyne");
  ASSERT_EQ(back.fields.size(), 2u);
  EXPECT_EQ(back.fields[1].name, "ring");
  EXPECT_EQ(back.fields[1].datatype, PointFieldMessage::kUint16);
  EXPECT_EQ(back.data, cloud.data);
  free_sample(sensor_msgs_msg_dds__PointCloud2__desc, out);
}

// What the Publisher hands a MessageTap (Foxglove, the recording) is byte for byte what goes on
// the DDS wire, and for a PoseStamped also what the recording's hand-written encoder writes.
TEST_F(CdrLoop, EncodeCdrGivesTheWireBytes) {
  char frame[] = "map";
  geometry_msgs_msg_dds__PoseStamped_ in{};
  in.header.stamp = {1'700'000'001, 5};
  in.header.frame_id = frame;
  in.pose.position = {1, 2, 3};
  in.pose.orientation = {0, 0, 0.6, 0.8};
  geometry_msgs_msg_dds__PoseStamped_ out{};
  const auto wire = unpadded(round_trip(geometry_msgs_msg_dds__PoseStamped__desc, in, out));
  free_sample(geometry_msgs_msg_dds__PoseStamped__desc, out);
  std::vector<std::byte> tapped;
  detail::encode_cdr(Topic::kPose, &in, tapped);
  ASSERT_EQ(tapped.size(), wire.size());
  EXPECT_EQ(std::memcmp(tapped.data(), wire.data(), wire.size()), 0);

  std::vector<std::byte> recorded;
  drivers::recording::ros2::encode_pose_stamped(
      {WallTime::from_ns(1'700'000'001'000'000'005), "map", {1, 2, 3}, {0, 0, 0.6, 0.8}}, recorded);
  EXPECT_EQ(recorded, tapped);

  // A second, larger message reuses the buffer and is still exact.
  CloudMessage cloud;
  cloud.frame_id = "velodyne";
  cloud.fields = {{"x", 0, PointFieldMessage::kFloat32, 1}};
  cloud.point_step = 4;
  cloud.width = 1000;
  cloud.data.assign(4000, 0xAB);
  sensor_msgs_msg_dds__PointCloud2_ cloud_in{};
  std::vector<sensor_msgs_msg_dds__PointField_> fields;
  detail::fill_cloud(cloud, cloud_in, fields);
  sensor_msgs_msg_dds__PointCloud2_ cloud_out{};
  const auto cloud_wire =
      unpadded(round_trip(sensor_msgs_msg_dds__PointCloud2__desc, cloud_in, cloud_out));
  free_sample(sensor_msgs_msg_dds__PointCloud2__desc, cloud_out);
  detail::encode_cdr(Topic::kCloud, &cloud_in, tapped);
  ASSERT_EQ(tapped.size(), cloud_wire.size());
  EXPECT_EQ(std::memcmp(tapped.data(), cloud_wire.data(), cloud_wire.size()), 0);
}

TEST_F(CdrLoop, CompressedImageBytesMatchRos2Layout) {
  ImageMessage image;
  image.stamp = WallTime::from_ns(7'000'000'009);
  image.frame_id = "cam";
  image.format = "jpeg";
  image.data = {0xFF, 0xD8, 0xFF, 0xD9, 0x42};
  sensor_msgs_msg_dds__CompressedImage_ in{};
  detail::fill_image(image, in);
  sensor_msgs_msg_dds__CompressedImage_ out{};
  const auto bytes = round_trip(sensor_msgs_msg_dds__CompressedImage__desc, in, out);
  CdrBuilder expected;  // header, format, uint8[] data
  expected.put<std::int32_t>(7);
  expected.put<std::uint32_t>(9);
  expected.put_string("cam");
  expected.put_string("jpeg");
  expected.put<std::uint32_t>(5);
  for (std::uint8_t b : image.data) expected.put<std::uint8_t>(b);
  EXPECT_EQ(unpadded(bytes), expected.bytes);
  const ImageMessage back = detail::to_plain(out);
  EXPECT_EQ(back.stamp, image.stamp);
  EXPECT_EQ(back.frame_id, "cam");
  EXPECT_EQ(back.format, "jpeg");
  EXPECT_EQ(back.data, image.data);
  free_sample(sensor_msgs_msg_dds__CompressedImage__desc, out);
}

}  // namespace
}  // namespace posed::dds
