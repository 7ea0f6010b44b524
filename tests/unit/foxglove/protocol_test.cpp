// The protocol's bytes and JSON without sockets: what the server says, and what it makes of
// whatever a client sends.

#include "daemon/foxglove/protocol.hpp"

#include <gtest/gtest.h>

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace posed::foxglove {
namespace {

using json = nlohmann::json;

TEST(FoxgloveProtocol, MessageDataHeaderIsOpcodeThenLittleEndianIdAndTime) {
  const MessageDataHeader header = message_data_header(0x04030201u, 0x0C0B0A0908070605);
  const std::array<std::uint8_t, 13> expected{0x01, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06,
                                              0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(static_cast<std::uint8_t>(header[i]), expected[i]) << "byte " << i;
  }
  // Before 1970 cannot be said in an unsigned time; it is sent as 0.
  const MessageDataHeader negative = message_data_header(1, -5);
  for (std::size_t i = 5; i < 13; ++i) EXPECT_EQ(negative[i], std::byte{0});
}

TEST(FoxgloveProtocol, ServerInfoHasNoCapabilities) {
  const json info = json::parse(server_info_json("posed", "123"));
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["name"], "posed");
  EXPECT_EQ(info["capabilities"], json::array());
  EXPECT_EQ(info["sessionId"], "123");
  EXPECT_FALSE(json::parse(server_info_json("posed", "")).contains("sessionId"));
}

TEST(FoxgloveProtocol, AdvertiseCarriesEveryChannelField) {
  const ChannelSpec odom{"/posed/odom", "cdr", "nav_msgs/msg/Odometry", "ros2msg",
                         "std_msgs/Header header\n\"quoted\"\n"};
  const ChannelSpec path{"/posed/path", "cdr", "nav_msgs/msg/Path", "ros2msg", ""};
  const std::vector<std::string> objects{channel_json(1, odom), channel_json(2, path)};
  const json advertise = json::parse(advertise_json(objects));
  EXPECT_EQ(advertise["op"], "advertise");
  ASSERT_EQ(advertise["channels"].size(), 2u);
  EXPECT_EQ(advertise["channels"][0], (json{{"id", 1},
                                            {"topic", "/posed/odom"},
                                            {"encoding", "cdr"},
                                            {"schemaName", "nav_msgs/msg/Odometry"},
                                            {"schema", "std_msgs/Header header\n\"quoted\"\n"},
                                            {"schemaEncoding", "ros2msg"}}));
  EXPECT_EQ(advertise["channels"][1]["id"], 2);
  EXPECT_EQ(json::parse(advertise_json({}))["channels"], json::array());
}

TEST(FoxgloveProtocol, InvalidUtf8IsReplacedNotThrown) {
  const ChannelSpec odd{"/bad\xff topic", "cdr", "x", "ros2msg", ""};
  EXPECT_NO_THROW(json::parse(channel_json(1, odd)));
  EXPECT_NO_THROW(json::parse(status_json(StatusLevel::kWarning, "quoting \xfe")));
}

TEST(FoxgloveProtocol, SubscribeAndUnsubscribeAreParsed) {
  const auto subscribe = parse_client_request(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":1},{"id":4294967295,"channelId":2}]})");
  const auto* s = std::get_if<SubscribeRequest>(&subscribe);
  ASSERT_NE(s, nullptr);
  ASSERT_EQ(s->subscriptions.size(), 2u);
  EXPECT_EQ(s->subscriptions[0].id, 0u);
  EXPECT_EQ(s->subscriptions[0].channel, 1u);
  EXPECT_EQ(s->subscriptions[1].id, 4294967295u);

  const auto unsubscribe = parse_client_request(R"({"op":"unsubscribe","subscriptionIds":[3,1]})");
  const auto* u = std::get_if<UnsubscribeRequest>(&unsubscribe);
  ASSERT_NE(u, nullptr);
  EXPECT_EQ(u->subscription_ids, (std::vector<SubscriptionId>{3, 1}));
}

TEST(FoxgloveProtocol, EverythingElseIsABadRequestWithAReason) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"", "malformed"},
      {"{\"op\":", "malformed"},
      {"[]", "object"},
      {"{}", "'op'"},
      {R"({"op":7})", "'op'"},
      {R"({"op":"getParameters","parameterNames":[]})", "unsupported op 'getParameters'"},
      {R"({"op":"subscribe"})", "'subscriptions'"},
      {R"({"op":"subscribe","subscriptions":[1]})", "object"},
      {R"({"op":"subscribe","subscriptions":[{"id":1}]})", "u32"},
      {R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":1}]})", "u32"},
      {R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})", "u32"},
      {R"({"op":"subscribe","subscriptions":[{"id":"1","channelId":1}]})", "u32"},
      {R"({"op":"unsubscribe","subscriptionIds":[-1]})", "u32"},
      {R"({"op":"unsubscribe","subscriptionIds":"1"})", "'subscriptionIds'"},
  };
  for (const auto& [text, says] : cases) {
    const auto request = parse_client_request(text);
    const auto* bad = std::get_if<BadRequest>(&request);
    ASSERT_NE(bad, nullptr) << text;
    EXPECT_NE(bad->reason.find(says), std::string::npos) << text << " -> " << bad->reason;
  }
  // A long op name is not echoed in full.
  const auto request = parse_client_request(R"({"op":")" + std::string(10000, 'x') + "\"}");
  EXPECT_LT(std::get<BadRequest>(request).reason.size(), 200u);
}

}  // namespace
}  // namespace posed::foxglove
