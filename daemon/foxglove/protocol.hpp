#pragma once
// The Foxglove WebSocket protocol (subprotocol foxglove.websocket.v1) as values and bytes, with no
// sockets: the JSON the server sends, the client requests it understands, and the header of a
// binary messageData frame. Spec: github.com/foxglove/ws-protocol, docs/spec.md; the reference
// implementation is the npm package @foxglove/ws-protocol (FoxgloveServer.ts, parse.ts).
//
// posed only serves data: it announces no capabilities, so of the client's requests only
// subscribe and unsubscribe mean something. Everything else is a BadRequest, which the server
// answers with a status warning and otherwise ignores.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace posed::foxglove {

inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";

/// One topic as a Foxglove client sees it (the spec's Channel, less the id the server assigns).
struct ChannelSpec {
  std::string topic;            ///< e.g. "/posed/odom"
  std::string encoding;         ///< message encoding, "cdr"
  std::string schema_name;      ///< e.g. "nav_msgs/msg/Odometry"
  std::string schema_encoding;  ///< "ros2msg"
  std::string schema;           ///< full schema text in schema_encoding
  /// Keep the newest message and send it to every client that subscribes later, as a
  /// transient-local DDS topic reaches a late reader (rt/tf_static, rt/posed/map): the
  /// protocol itself has no such notion, and Foxglove Studio connects whenever its user does.
  bool latched = false;
};

/// Assigned by the server, from 1; 0 is never a channel.
using ChannelId = std::uint32_t;
/// Chosen by the client, per connection (FoxgloveClient counts from 0).
using SubscriptionId = std::uint32_t;

enum class StatusLevel : std::uint8_t { kInfo = 0, kWarning = 1, kError = 2 };

// ---- server -> client, JSON text frames ----

/// {"op":"serverInfo",...}; capabilities are empty (no client publish, time, parameters...).
/// An empty session_id is left out.
std::string server_info_json(std::string_view name, std::string_view session_id);
/// One entry of advertise's "channels": {"id":...,"topic":...,"encoding":...,"schemaName":...,
/// "schema":...,"schemaEncoding":...}. Text that is not valid UTF-8 is replaced, not refused.
std::string channel_json(ChannelId id, const ChannelSpec& spec);
/// {"op":"advertise","channels":[...]} from channel_json() objects, which the server keeps
/// rather than re-encoding every schema for each client that connects.
std::string advertise_json(std::span<const std::string> channel_objects);
/// {"op":"status","level":...,"message":...}
std::string status_json(StatusLevel level, std::string_view message);

// ---- server -> client, binary messageData ----

inline constexpr std::byte kMessageDataOpcode{0x01};
/// opcode (1 byte), subscription id (u32 LE), log time (u64 LE, ns); the payload follows.
inline constexpr std::size_t kMessageDataHeaderBytes = 1 + 4 + 8;
using MessageDataHeader = std::array<std::byte, kMessageDataHeaderBytes>;

/// The header in front of a payload. The wire carries an unsigned time, so a negative
/// log_time_ns (before 1970) is sent as 0.
MessageDataHeader message_data_header(SubscriptionId subscription, std::int64_t log_time_ns);

// ---- client -> server ----

struct Subscription {
  SubscriptionId id = 0;
  ChannelId channel = 0;
};
struct SubscribeRequest {
  std::vector<Subscription> subscriptions;
};
struct UnsubscribeRequest {
  std::vector<SubscriptionId> subscription_ids;
};
/// A request the server refuses as a whole; `reason` is sent back in a status message.
struct BadRequest {
  std::string reason;
};
using ClientRequest = std::variant<SubscribeRequest, UnsubscribeRequest, BadRequest>;

/// Parses one text frame. Never throws: malformed JSON, unknown or unsupported ops, missing
/// fields and ids outside u32 are BadRequests naming what was wrong.
ClientRequest parse_client_request(std::string_view text);

}  // namespace posed::foxglove
