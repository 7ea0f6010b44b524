// rt/initialpose end to end on a loopback domain: InitialPoseWriter (posectl initialpose) and a
// plain Cyclone writer with RViz's QoS (what RViz's 2D Pose Estimate is to posed) into
// InitialPoseReader. Each test uses a topic of its own, so a stranger on the domain cannot add
// samples to its counts.

#include <dds/dds.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "daemon/dds/generated_types.hpp"
#include "daemon/dds/initial_pose_reader.hpp"
#include "daemon/dds/initial_pose_writer.hpp"
#include "daemon/dds/participant.hpp"
#include "daemon/dds/publisher.hpp"
#include "tests/unit/dds/test_domain.hpp"

namespace posed::dds {
namespace {

constexpr Duration kTimeout = Duration::from_s(10);

DdsConfig unique_config() {
  DdsConfig config = test::loopback_config();
  std::random_device rd;
  config.initial_pose_topic = "rt/posed_test/initialpose_" + std::to_string(rd());
  return config;
}

/// What RViz sends for a click at (x, y) facing yaw: z 0, covariance x, y 0.25 m^2 and yaw
/// (pi/12)^2 rad^2.
InitialPose rviz_pose(double x, double y, double yaw, std::int64_t stamp_ns) {
  InitialPose pose;
  pose.stamp_ns = stamp_ns;
  pose.frame_id = "map";
  pose.T_frame_base.translation() = Eigen::Vector3d(x, y, 0.0);
  pose.T_frame_base.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.covariance[0] = 0.25;
  pose.covariance[7] = 0.25;
  pose.covariance[35] = M_PI / 12.0 * M_PI / 12.0;
  return pose;
}

/// Takes until a pose comes or 10 s pass (nothing blocks: take_newest never waits).
std::optional<InitialPose> take_eventually(InitialPoseReader& reader) {
  std::optional<InitialPose> got;
  test::eventually([&] {
    got = reader.take_newest();
    return got.has_value();
  });
  return got;
}

class InitialPoseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    config_ = unique_config();
    std::string error;
    reader_ = InitialPoseReader::create(config_, error);
    ASSERT_NE(reader_, nullptr) << error;
    writer_ = InitialPoseWriter::create(config_, error);
    ASSERT_NE(writer_, nullptr) << error;
    ASSERT_TRUE(writer_->wait_for_reader(kTimeout)) << config_.initial_pose_topic;
    ASSERT_TRUE(test::eventually([&] { return reader_->matched_publishers() >= 1; }));
  }

  /// Writes and waits until the reader has it: what follows sees every sample written.
  void write(const InitialPose& pose) {
    std::string error;
    ASSERT_TRUE(writer_->publish(pose, error)) << error;
    ASSERT_TRUE(writer_->wait_acknowledged(kTimeout));
  }

  DdsConfig config_;
  std::unique_ptr<InitialPoseReader> reader_;
  std::unique_ptr<InitialPoseWriter> writer_;
};

TEST_F(InitialPoseTest, ArrivesIntact) {
  InitialPose sent = rviz_pose(12.5, -3.25, 2.0, 1'700'000'000'123'456'789);
  sent.T_frame_base.translation().z() = 0.75;
  sent.covariance[14] = 0.01;  // z, 3rd row
  write(sent);

  const auto got = take_eventually(*reader_);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->stamp_ns, sent.stamp_ns);
  EXPECT_EQ(got->frame_id, "map");
  EXPECT_TRUE(got->T_frame_base.translation().isApprox(Eigen::Vector3d(12.5, -3.25, 0.75)))
      << got->T_frame_base.translation().transpose();
  EXPECT_TRUE(got->T_frame_base.linear().isApprox(sent.T_frame_base.linear(), 1e-12))
      << got->T_frame_base.linear();
  EXPECT_EQ(got->covariance, sent.covariance);
  EXPECT_EQ(reader_->dropped(), 0u);
  EXPECT_EQ(reader_->refused(), 0u);
  EXPECT_FALSE(reader_->take_newest().has_value()) << "taken twice";
}

TEST_F(InitialPoseTest, NewestOfTwoIsTakenAndTheOlderCountedDropped) {
  write(rviz_pose(1.0, 2.0, 0.1, 1'000'000'000));
  write(rviz_pose(3.0, 4.0, -0.2, 2'000'000'000));

  const auto got = reader_->take_newest();  // both acknowledged: both wait in the reader
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->stamp_ns, 2'000'000'000);
  EXPECT_DOUBLE_EQ(got->T_frame_base.translation().x(), 3.0);
  EXPECT_EQ(reader_->dropped(), 1u);
  EXPECT_FALSE(reader_->take_newest().has_value());
}

/// A plain Cyclone writer on the reader's topic with RViz's QoS, writing any quaternion.
class RawInitialPoseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    config_ = unique_config();
    std::string error;
    reader_ = InitialPoseReader::create(config_, error);
    ASSERT_NE(reader_, nullptr) << error;
    participant_ = detail::Participant::open(config_, error);
    ASSERT_NE(participant_, nullptr) << error;
    const dds_entity_t topic = detail::create_initial_pose_topic(participant_->handle(),
                                                                 config_.initial_pose_topic, error);
    ASSERT_GT(topic, 0) << error;
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 5);
    writer_ = dds_create_writer(participant_->handle(), topic, qos, nullptr);
    dds_delete_qos(qos);
    ASSERT_GT(writer_, 0);
    ASSERT_TRUE(test::eventually([&] { return reader_->matched_publishers() >= 1; }));
    ASSERT_TRUE(test::eventually([&] {
      dds_publication_matched_status_t status{};
      return dds_get_publication_matched_status(writer_, &status) == DDS_RETCODE_OK &&
             status.current_count >= 1;
    }));
  }

  void write(const geometry_msgs_msg_dds__PoseWithCovarianceStamped_& sample) {
    ASSERT_EQ(dds_write(writer_, &sample), DDS_RETCODE_OK);
    ASSERT_EQ(dds_wait_for_acks(writer_, kTimeout.ns), DDS_RETCODE_OK);
  }

  static geometry_msgs_msg_dds__PoseWithCovarianceStamped_ sample(double qx, double qy, double qz,
                                                                  double qw) {
    static char frame[] = "map";
    geometry_msgs_msg_dds__PoseWithCovarianceStamped_ s{};
    s.header.stamp = {1'700'000'000, 0};
    s.header.frame_id = frame;
    s.pose.pose.position = {1.0, 2.0, 0.0};
    s.pose.pose.orientation = {qx, qy, qz, qw};
    return s;
  }

  DdsConfig config_;
  std::unique_ptr<InitialPoseReader> reader_;
  std::unique_ptr<detail::Participant> participant_;
  dds_entity_t writer_ = 0;
};

TEST_F(RawInitialPoseTest, BadQuaternionIsRefusedAndCounted) {
  write(sample(0.0, 0.0, 0.0, 0.5));  // |q| = 0.5
  EXPECT_FALSE(reader_->take_newest().has_value());
  EXPECT_EQ(reader_->refused(), 1u);

  write(sample(0.0, 0.0, std::numeric_limits<double>::quiet_NaN(), 1.0));
  EXPECT_FALSE(reader_->take_newest().has_value());
  EXPECT_EQ(reader_->refused(), 2u);
  EXPECT_EQ(reader_->dropped(), 0u);
}

TEST_F(RawInitialPoseTest, NonFinitePositionIsRefused) {
  auto s = sample(0.0, 0.0, 0.0, 1.0);
  s.pose.pose.position.y = std::numeric_limits<double>::infinity();
  write(s);
  EXPECT_FALSE(reader_->take_newest().has_value());
  EXPECT_EQ(reader_->refused(), 1u);
}

TEST_F(RawInitialPoseTest, AlmostUnitQuaternionIsNormalisedAndARefusedOneDoesNotHideAGoodOne) {
  // Within 1e-3 of unit length (a quaternion printed to 4 decimals): accepted, normalised.
  const double c = std::cos(0.25), s = std::sin(0.25);
  write(sample(0.0, 0.0, 1.0004 * s, 1.0004 * c));
  write(sample(0.0, 0.0, 0.0, 0.0));  // newer, refused
  const auto got = reader_->take_newest();
  ASSERT_TRUE(got.has_value());
  const Eigen::Matrix3d R = got->T_frame_base.linear();
  EXPECT_TRUE(
      R.isApprox(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12))
      << R;
  EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
  EXPECT_EQ(reader_->refused(), 1u);
  EXPECT_EQ(reader_->dropped(), 0u);
}

TEST(InitialPoseReader, SharesThePublishersParticipantAndOutlivesIt) {
  const DdsConfig config = unique_config();
  std::string error;
  auto publisher = Publisher::create(config, error);
  ASSERT_NE(publisher, nullptr) << error;
  auto reader = InitialPoseReader::create(*publisher, config, error);
  ASSERT_NE(reader, nullptr) << error;
  EXPECT_EQ(reader->topic(), config.initial_pose_topic);
  publisher.reset();  // the reader keeps the participant

  auto writer = InitialPoseWriter::create(config, error);
  ASSERT_NE(writer, nullptr) << error;
  ASSERT_TRUE(writer->wait_for_reader(kTimeout));
  ASSERT_TRUE(writer->publish(rviz_pose(5.0, 6.0, 0.0, 42), error)) << error;
  const auto got = take_eventually(*reader);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->stamp_ns, 42);
}

TEST(InitialPoseReader, AnEmptyTopicReadsNothing) {
  DdsConfig config = unique_config();
  config.initial_pose_topic.clear();
  std::string error;
  EXPECT_EQ(InitialPoseReader::create(config, error), nullptr);
  EXPECT_EQ(error, "");
  EXPECT_EQ(InitialPoseWriter::create(config, error), nullptr);
  EXPECT_NE(error, "");
}

TEST(InitialPoseReader, TopicCarriesTheRos2TypeName) {
  std::string error;
  auto participant = detail::Participant::open(test::loopback_config(), error);
  ASSERT_NE(participant, nullptr) << error;
  const dds_entity_t topic =
      detail::create_initial_pose_topic(participant->handle(), "rt/initialpose", error);
  ASSERT_GT(topic, 0) << error;
  char type[128] = {};
  ASSERT_GT(dds_get_type_name(topic, type, sizeof type), 0);
  EXPECT_STREQ(type, "geometry_msgs::msg::dds_::PoseWithCovarianceStamped_");
}

}  // namespace
}  // namespace posed::dds
