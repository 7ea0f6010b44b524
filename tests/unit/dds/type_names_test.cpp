// ROS 2 finds a topic's type by its DDS type name: "<pkg>::msg::dds_::<Type>_". A typo here
// means `ros2 topic echo` silently sees nothing, so every name is checked exactly, and the topic
// names are checked against ROS 2's "rt/" mangling.

#include <dds/dds.h>
#include <gtest/gtest.h>

#include <string>

#include "daemon/dds/generated_types.hpp"
#include "daemon/dds/messages.hpp"
#include "daemon/dds/participant.hpp"
#include "tests/unit/dds/test_domain.hpp"

namespace posed::dds {
namespace {

TEST(DdsTypeNames, MatchRosidlDdsNames) {
  EXPECT_STREQ(builtin_interfaces_msg_dds__Time__desc.m_typename,
               "builtin_interfaces::msg::dds_::Time_");
  EXPECT_STREQ(std_msgs_msg_dds__Header__desc.m_typename, "std_msgs::msg::dds_::Header_");
  EXPECT_STREQ(geometry_msgs_msg_dds__Point__desc.m_typename, "geometry_msgs::msg::dds_::Point_");
  EXPECT_STREQ(geometry_msgs_msg_dds__Quaternion__desc.m_typename,
               "geometry_msgs::msg::dds_::Quaternion_");
  EXPECT_STREQ(geometry_msgs_msg_dds__Pose__desc.m_typename, "geometry_msgs::msg::dds_::Pose_");
  EXPECT_STREQ(geometry_msgs_msg_dds__PoseWithCovariance__desc.m_typename,
               "geometry_msgs::msg::dds_::PoseWithCovariance_");
  EXPECT_STREQ(geometry_msgs_msg_dds__Vector3__desc.m_typename,
               "geometry_msgs::msg::dds_::Vector3_");
  EXPECT_STREQ(geometry_msgs_msg_dds__Twist__desc.m_typename, "geometry_msgs::msg::dds_::Twist_");
  EXPECT_STREQ(geometry_msgs_msg_dds__TwistWithCovariance__desc.m_typename,
               "geometry_msgs::msg::dds_::TwistWithCovariance_");
  EXPECT_STREQ(geometry_msgs_msg_dds__PoseStamped__desc.m_typename,
               "geometry_msgs::msg::dds_::PoseStamped_");
  EXPECT_STREQ(geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc.m_typename,
               "geometry_msgs::msg::dds_::PoseWithCovarianceStamped_");
  EXPECT_STREQ(nav_msgs_msg_dds__Odometry__desc.m_typename, "nav_msgs::msg::dds_::Odometry_");
  EXPECT_STREQ(posed_msgs_msg_dds__StreamStatus__desc.m_typename,
               "posed_msgs::msg::dds_::StreamStatus_");
  EXPECT_STREQ(posed_msgs_msg_dds__Status__desc.m_typename, "posed_msgs::msg::dds_::Status_");
  EXPECT_STREQ(geometry_msgs_msg_dds__TransformStamped__desc.m_typename,
               "geometry_msgs::msg::dds_::TransformStamped_");
  EXPECT_STREQ(tf2_msgs_msg_dds__TFMessage__desc.m_typename, "tf2_msgs::msg::dds_::TFMessage_");
  EXPECT_STREQ(nav_msgs_msg_dds__Path__desc.m_typename, "nav_msgs::msg::dds_::Path_");
  EXPECT_STREQ(diagnostic_msgs_msg_dds__DiagnosticArray__desc.m_typename,
               "diagnostic_msgs::msg::dds_::DiagnosticArray_");
  EXPECT_STREQ(diagnostic_msgs_msg_dds__DiagnosticStatus__desc.m_typename,
               "diagnostic_msgs::msg::dds_::DiagnosticStatus_");
}

TEST(DdsTypeNames, ROS2TypesHaveNoKey) {
  // ROS 2 messages are keyless; a key would change the wire (key hash) and instance handling.
  EXPECT_EQ(nav_msgs_msg_dds__Odometry__desc.m_nkeys, 0u);
  EXPECT_EQ(geometry_msgs_msg_dds__PoseStamped__desc.m_nkeys, 0u);
  EXPECT_EQ(geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc.m_nkeys, 0u);
  EXPECT_EQ(posed_msgs_msg_dds__Status__desc.m_nkeys, 0u);
}

TEST(DdsTopicNames, AreRos2Mangled) {
  EXPECT_EQ(topic_name(Topic::kOdom), "rt/posed/odom");
  EXPECT_EQ(topic_name(Topic::kPose), "rt/posed/pose");
  EXPECT_EQ(topic_name(Topic::kStatus), "rt/posed/status");
  EXPECT_EQ(topic_name(Topic::kTf), "rt/tf");
  EXPECT_EQ(topic_name(Topic::kTfStatic), "rt/tf_static");
  EXPECT_EQ(topic_name(Topic::kPath), "rt/posed/path");
  EXPECT_EQ(topic_name(Topic::kDiagnostics), "rt/diagnostics");
}

TEST(DdsTopicNames, ParseAcceptsShortRosAndDdsNames) {
  Topic t = Topic::kOdom;
  EXPECT_TRUE(parse_topic("pose", t));
  EXPECT_EQ(t, Topic::kPose);
  EXPECT_TRUE(parse_topic("/posed/status", t));
  EXPECT_EQ(t, Topic::kStatus);
  EXPECT_TRUE(parse_topic("rt/posed/odom", t));
  EXPECT_EQ(t, Topic::kOdom);
  EXPECT_TRUE(parse_topic("/tf_static", t));
  EXPECT_EQ(t, Topic::kTfStatic);
  EXPECT_TRUE(parse_topic("diagnostics", t));
  EXPECT_EQ(t, Topic::kDiagnostics);
  EXPECT_FALSE(parse_topic("rt/posed/odometry", t));
  EXPECT_FALSE(parse_topic("", t));
}

TEST(DdsTopicNames, TopicsCarryTheRosTypeName) {
  std::string error;
  auto participant = detail::Participant::open(test::loopback_config(), error);
  ASSERT_NE(participant, nullptr) << error;
  const struct {
    Topic topic;
    const char* type;
  } cases[] = {{Topic::kOdom, "nav_msgs::msg::dds_::Odometry_"},
               {Topic::kPose, "geometry_msgs::msg::dds_::PoseStamped_"},
               {Topic::kStatus, "posed_msgs::msg::dds_::Status_"},
               {Topic::kTf, "tf2_msgs::msg::dds_::TFMessage_"},
               {Topic::kTfStatic, "tf2_msgs::msg::dds_::TFMessage_"},
               {Topic::kPath, "nav_msgs::msg::dds_::Path_"},
               {Topic::kDiagnostics, "diagnostic_msgs::msg::dds_::DiagnosticArray_"}};
  for (const auto& c : cases) {
    const dds_entity_t topic = detail::create_topic(participant->handle(), c.topic, error);
    ASSERT_GT(topic, 0) << error;
    char name[128] = {};
    char type[128] = {};
    // Both return the full length (or an error); shorter than the buffer means not truncated.
    ASSERT_GT(dds_get_name(topic, name, sizeof name), 0);
    ASSERT_LT(dds_get_name(topic, name, sizeof name), static_cast<dds_return_t>(sizeof name));
    ASSERT_GT(dds_get_type_name(topic, type, sizeof type), 0);
    ASSERT_LT(dds_get_type_name(topic, type, sizeof type), static_cast<dds_return_t>(sizeof type));
    EXPECT_EQ(std::string(name), topic_name(c.topic));
    EXPECT_STREQ(type, c.type);
  }
}

}  // namespace
}  // namespace posed::dds
