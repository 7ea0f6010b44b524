// Publisher -> Subscriber end to end on a loopback domain, a plain Cyclone reader (what any
// non-posed DDS program does) receiving the Publisher's odometry, and configuration errors.

#include <dds/dds.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>

#include "daemon/dds/generated_types.hpp"
#include "daemon/dds/publisher.hpp"
#include "daemon/dds/subscriber.hpp"
#include "drivers/common/host_clock.hpp"
#include "tests/unit/dds/test_domain.hpp"

namespace posed::dds {
namespace {

/// A stamp no other test run will send, so samples from a stranger on the domain are ignored.
WallTime unique_stamp() {
  std::random_device rd;
  return drivers::wall_now() + Duration::from_ns(rd() % 1'000'000);
}

template <class Message, class Take>
std::vector<Received<Message>> receive_matching(Subscriber& sub, WallTime stamp, Take take) {
  std::vector<Received<Message>> all;
  std::vector<Received<Message>> mine;
  test::eventually([&] {
    sub.wait(Duration::from_ms(100));
    take(all);
    for (auto& r : all) {
      if (r.msg.stamp == stamp) mine.push_back(std::move(r));
    }
    all.clear();
    return !mine.empty();
  });
  return mine;
}

class DdsPubSub : public ::testing::Test {
 protected:
  void SetUp() override {
    config_ = test::loopback_config();
    config_.map_frame = "world";
    config_.odom_frame = "world_odom";
    config_.base_frame = "robot";
    std::string error;
    publisher_ = Publisher::create(config_, error);
    ASSERT_NE(publisher_, nullptr) << error;
    subscriber_ = Subscriber::create(config_, {}, error);
    ASSERT_NE(subscriber_, nullptr) << error;
    for (Topic t : {Topic::kOdom, Topic::kPose, Topic::kStatus}) {
      ASSERT_TRUE(test::eventually([&] { return publisher_->matched_subscribers(t) >= 1; }))
          << topic_name(t) << ": subscriber never matched";
      ASSERT_TRUE(test::eventually([&] { return subscriber_->matched_publishers(t) >= 1; }));
    }
  }

  DdsConfig config_;
  std::unique_ptr<Publisher> publisher_;
  std::unique_ptr<Subscriber> subscriber_;
};

TEST_F(DdsPubSub, OdomArrivesIntactWithConfiguredFrames) {
  OdomMessage msg;
  msg.stamp = unique_stamp();
  msg.p_map_base_m = {10.5, -3.25, 0.5};
  msg.q_map_base = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  msg.v_base_mps = {1.2, 0.0, -0.01};
  msg.w_base_radps = {0.0, 0.02, 0.3};
  msg.pose_covariance[0] = 0.01;
  msg.twist_covariance[35] = 0.04;
  const WallTime before = drivers::wall_now();
  ASSERT_TRUE(publisher_->publish_odom(msg));

  const auto got = receive_matching<OdomMessage>(*subscriber_, msg.stamp,
                                                 [&](auto& out) { subscriber_->take_odom(out); });
  ASSERT_EQ(got.size(), 1u);
  const auto& r = got[0];
  EXPECT_EQ(r.frame_id, "world_odom");
  EXPECT_EQ(r.child_frame_id, "robot");
  EXPECT_EQ(r.msg.p_map_base_m, msg.p_map_base_m);
  EXPECT_EQ(r.msg.q_map_base.coeffs(), msg.q_map_base.coeffs());
  EXPECT_EQ(r.msg.v_base_mps, msg.v_base_mps);
  EXPECT_EQ(r.msg.w_base_radps, msg.w_base_radps);
  EXPECT_EQ(r.msg.pose_covariance, msg.pose_covariance);
  EXPECT_EQ(r.msg.twist_covariance, msg.twist_covariance);
  EXPECT_GE(r.received_wall, before);
  EXPECT_EQ(publisher_->write_failures(), 0u);
}

TEST_F(DdsPubSub, PoseArrivesIntact) {
  PoseMessage msg;
  msg.stamp = unique_stamp();
  msg.p_map_base_m = {1, 2, 3};
  msg.q_map_base = Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5);
  ASSERT_TRUE(publisher_->publish_pose(msg));
  const auto got = receive_matching<PoseMessage>(*subscriber_, msg.stamp,
                                                 [&](auto& out) { subscriber_->take_pose(out); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].frame_id, "world");
  EXPECT_EQ(got[0].msg.p_map_base_m, msg.p_map_base_m);
  EXPECT_EQ(got[0].msg.q_map_base.coeffs(), msg.q_map_base.coeffs());
}

TEST_F(DdsPubSub, StatusArrivesWithEveryStream) {
  StatusMessage msg;
  msg.stamp = unique_stamp();
  msg.version = "posed 9.9.9";
  msg.estimator_mode = "strapdown";
  msg.uptime_s = 61.5;
  msg.summary = "imu ok, lidar stale";
  msg.mapping = {"mapping", 412, 9, 0, 31.5, 2};
  for (int i = 0; i < 12; ++i) {  // more than the preallocated 8: the buffer must grow
    StreamStatusMessage s;
    s.name = "stream" + std::to_string(i);
    s.rate_hz = 10.0 * i;
    s.received = static_cast<std::uint64_t>(1000 + i);
    s.decoded = static_cast<std::uint64_t>(990 + i);
    s.dropped = static_cast<std::uint64_t>(i);
    s.malformed = 3;
    s.clock_offset_ns = -1'000'000'000'000 * i;
    s.clock_drift_ppm = -2.5;
    s.clock_jitter_ns = 1e4;
    s.clock_uncertainty_ns = 5e3;
    s.clock_state = i % 2 ? "locked" : "converging";
    s.health = i == 1 ? "stale" : "ok";
    msg.streams.push_back(s);
  }
  ASSERT_TRUE(publisher_->publish_status(msg));
  const auto got = receive_matching<StatusMessage>(
      *subscriber_, msg.stamp, [&](auto& out) { subscriber_->take_status(out); });
  ASSERT_EQ(got.size(), 1u);
  const StatusMessage& r = got[0].msg;
  EXPECT_EQ(got[0].frame_id, "world");
  EXPECT_EQ(r.version, msg.version);
  EXPECT_EQ(r.estimator_mode, msg.estimator_mode);
  EXPECT_EQ(r.uptime_s, msg.uptime_s);
  EXPECT_EQ(r.summary, msg.summary);
  EXPECT_EQ(r.mapping.state, "mapping");
  EXPECT_EQ(r.mapping.keyframes, 412u);
  EXPECT_EQ(r.mapping.loops, 9u);
  EXPECT_EQ(r.mapping.fixes, 0u);
  EXPECT_EQ(r.mapping.correction_m, 31.5);
  EXPECT_EQ(r.mapping.scans_skipped, 2u);
  ASSERT_EQ(r.streams.size(), msg.streams.size());
  for (std::size_t i = 0; i < r.streams.size(); ++i) {
    EXPECT_EQ(r.streams[i].name, msg.streams[i].name);
    EXPECT_EQ(r.streams[i].rate_hz, msg.streams[i].rate_hz);
    EXPECT_EQ(r.streams[i].received, msg.streams[i].received);
    EXPECT_EQ(r.streams[i].decoded, msg.streams[i].decoded);
    EXPECT_EQ(r.streams[i].dropped, msg.streams[i].dropped);
    EXPECT_EQ(r.streams[i].malformed, msg.streams[i].malformed);
    EXPECT_EQ(r.streams[i].clock_offset_ns, msg.streams[i].clock_offset_ns);
    EXPECT_EQ(r.streams[i].clock_drift_ppm, msg.streams[i].clock_drift_ppm);
    EXPECT_EQ(r.streams[i].clock_jitter_ns, msg.streams[i].clock_jitter_ns);
    EXPECT_EQ(r.streams[i].clock_uncertainty_ns, msg.streams[i].clock_uncertainty_ns);
    EXPECT_EQ(r.streams[i].clock_state, msg.streams[i].clock_state);
    EXPECT_EQ(r.streams[i].health, msg.streams[i].health);
  }
}

TEST_F(DdsPubSub, ManyOdomSamplesArriveInOrder) {
  constexpr int kCount = 200;
  const WallTime base = unique_stamp();
  for (int i = 0; i < kCount; ++i) {
    OdomMessage msg;
    msg.stamp = base + Duration::from_ms(i);
    msg.p_map_base_m.x() = i;
    ASSERT_TRUE(publisher_->publish_odom(msg));
    // Keep-last 10 on both sides: pace so the reader keeps up (the contract is "latest", not
    // "every sample" when a reader stalls).
    if (i % 5 == 4) subscriber_->wait(Duration::from_ms(1));
  }
  std::vector<Received<OdomMessage>> all;
  test::eventually([&] {
    subscriber_->wait(Duration::from_ms(50));
    subscriber_->take_odom(all);
    return !all.empty() && all.back().msg.stamp == base + Duration::from_ms(kCount - 1);
  });
  ASSERT_FALSE(all.empty());
  EXPECT_EQ(all.back().msg.stamp, base + Duration::from_ms(kCount - 1));  // the latest arrives
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LT(all[i - 1].msg.stamp, all[i].msg.stamp);
}

TEST(DdsPlainReader, ReceivesPublisherOdomByRosTypeAndTopicName) {
  DdsConfig config = test::loopback_config();
  std::string error;
  auto publisher = Publisher::create(config, error);
  ASSERT_NE(publisher, nullptr) << error;

  // A second participant on the same domain using only Cyclone and the IDL, like a ROS 2 node.
  const dds_entity_t pp = dds_create_participant(config.domain_id, nullptr, nullptr);
  ASSERT_GT(pp, 0);
  const dds_entity_t topic =
      dds_create_topic(pp, &nav_msgs_msg_dds__Odometry__desc, "rt/posed/odom", nullptr, nullptr);
  ASSERT_GT(topic, 0);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  const dds_entity_t reader = dds_create_reader(pp, topic, qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(reader, 0);
  ASSERT_TRUE(test::eventually([&] { return publisher->matched_subscribers(Topic::kOdom) >= 1; }));

  OdomMessage msg;
  msg.stamp = unique_stamp();
  msg.p_map_base_m = {4, 5, 6};
  ASSERT_TRUE(publisher->publish_odom(msg));
  bool found = false;
  test::eventually([&] {
    void* samples[1] = {nullptr};
    dds_sample_info_t info{};
    while (dds_take(reader, samples, &info, 1, 1) == 1) {
      const auto* odom = static_cast<const nav_msgs_msg_dds__Odometry_*>(samples[0]);
      const std::int64_t ns =
          std::int64_t{odom->header.stamp.sec} * 1'000'000'000 + odom->header.stamp.nanosec;
      if (info.valid_data && ns == msg.stamp.ns) {
        found = true;
        EXPECT_STREQ(odom->header.frame_id, "odom");
        EXPECT_STREQ(odom->child_frame_id, "base_link");
        EXPECT_EQ(odom->pose.pose.position.y, 5.0);
        EXPECT_EQ(odom->pose.pose.orientation.w, 1.0);
      }
      dds_return_loan(reader, samples, 1);
    }
    return found;
  });
  EXPECT_TRUE(found);
  dds_delete(pp);
}

TEST(DdsConfigErrors, MissingXmlFileIsNamed) {
  DdsConfig config = test::loopback_config();
  config.cyclonedds_xml_path = "/nonexistent/posed-cyclone.xml";
  std::string error;
  EXPECT_EQ(Publisher::create(config, error), nullptr);
  EXPECT_NE(error.find("/nonexistent/posed-cyclone.xml"), std::string::npos) << error;
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
}

TEST(DdsConfigErrors, InvalidXmlIsRejectedAndNamed) {
  const std::string path = ::testing::TempDir() + "posed-bad-cyclone.xml";
  {
    std::ofstream out(path);
    out << "<CycloneDDS><Domain><Discovery><MaxAutoParticipantIndex>lots"
           "</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>\n";
  }
  DdsConfig config = test::loopback_config();
  config.cyclonedds_xml_path = path;
  std::string error;
  EXPECT_EQ(Subscriber::create(config, {}, error), nullptr);
  EXPECT_NE(error.find(path), std::string::npos) << error;
  std::remove(path.c_str());
}

TEST(DdsConfigErrors, SameDomainWithAnotherXmlIsRefused) {
  DdsConfig config = test::loopback_config();
  std::string error;
  auto publisher = Publisher::create(config, error);
  ASSERT_NE(publisher, nullptr) << error;
  // Same file, second user: shares the domain.
  auto subscriber = Subscriber::create(config, {}, error);
  ASSERT_NE(subscriber, nullptr) << error;
  // Another file on the same domain would silently run with the first file's settings.
  const std::string other = ::testing::TempDir() + "posed-other-cyclone.xml";
  { std::ofstream(other) << "<CycloneDDS/>\n"; }
  config.cyclonedds_xml_path = other;
  EXPECT_EQ(Subscriber::create(config, {}, error), nullptr);
  EXPECT_NE(error.find(other), std::string::npos) << error;
  std::remove(other.c_str());
}

}  // namespace
}  // namespace posed::dds
