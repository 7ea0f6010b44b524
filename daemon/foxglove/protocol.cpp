#include "daemon/foxglove/protocol.hpp"

// nlohmann/json (Debian nlohmann-json3-dev): the JSON side of the protocol is a handful of small
// objects per connection, never on a hot path; it is confined to this file.
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

namespace posed::foxglove {
namespace {

using nlohmann::json;

/// dump() that replaces invalid UTF-8 rather than throwing: a topic from a config file or a
/// reason quoting client bytes must not take the server down.
std::string dump(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

/// An id as u32: the spec's ids are JSON numbers, but a client sending -1, 2^40 or 1.5 must get a
/// warning, not a wrapped-around id.
std::optional<std::uint32_t> u32_value(const json& value) {
  if (!value.is_number_integer()) return std::nullopt;
  if (value.is_number_unsigned()) {
    const auto unsigned_value = value.get<std::uint64_t>();
    if (unsigned_value > std::numeric_limits<std::uint32_t>::max()) return std::nullopt;
    return static_cast<std::uint32_t>(unsigned_value);
  }
  const auto signed_value = value.get<std::int64_t>();
  if (signed_value < 0 || signed_value > std::numeric_limits<std::uint32_t>::max()) {
    return std::nullopt;
  }
  return static_cast<std::uint32_t>(signed_value);
}

std::optional<std::uint32_t> u32_field(const json& object, const char* key) {
  const auto it = object.find(key);
  if (it == object.end()) return std::nullopt;
  return u32_value(*it);
}

ClientRequest parse_subscribe(const json& request) {
  const auto list = request.find("subscriptions");
  if (list == request.end() || !list->is_array()) {
    return BadRequest{"subscribe: 'subscriptions' must be an array"};
  }
  SubscribeRequest subscribe;
  for (const json& entry : *list) {
    if (!entry.is_object()) return BadRequest{"subscribe: each subscription must be an object"};
    const auto id = u32_field(entry, "id");
    const auto channel = u32_field(entry, "channelId");
    if (!id || !channel) {
      return BadRequest{"subscribe: each subscription needs 'id' and 'channelId' as u32 integers"};
    }
    subscribe.subscriptions.push_back({*id, *channel});
  }
  return subscribe;
}

ClientRequest parse_unsubscribe(const json& request) {
  const auto list = request.find("subscriptionIds");
  if (list == request.end() || !list->is_array()) {
    return BadRequest{"unsubscribe: 'subscriptionIds' must be an array"};
  }
  UnsubscribeRequest unsubscribe;
  for (const json& entry : *list) {
    const auto id = u32_value(entry);
    if (!id) return BadRequest{"unsubscribe: subscription ids must be u32 integers"};
    unsubscribe.subscription_ids.push_back(*id);
  }
  return unsubscribe;
}

}  // namespace

std::string server_info_json(std::string_view name, std::string_view session_id) {
  json info{{"op", "serverInfo"},
            {"name", name},
            {"capabilities", json::array()},
            {"supportedEncodings", json::array()},
            {"metadata", json::object()}};
  if (!session_id.empty()) info["sessionId"] = session_id;
  return dump(info);
}

std::string channel_json(ChannelId id, const ChannelSpec& spec) {
  return dump(json{{"id", id},
                   {"topic", spec.topic},
                   {"encoding", spec.encoding},
                   {"schemaName", spec.schema_name},
                   {"schema", spec.schema},
                   {"schemaEncoding", spec.schema_encoding}});
}

std::string advertise_json(std::span<const std::string> channel_objects) {
  constexpr std::string_view kHead = R"({"op":"advertise","channels":[)";
  constexpr std::string_view kTail = "]}";
  std::size_t size = kHead.size() + kTail.size() + channel_objects.size();
  for (const std::string& object : channel_objects) size += object.size();
  std::string message;
  message.reserve(size);
  message += kHead;
  for (std::size_t i = 0; i < channel_objects.size(); ++i) {
    if (i > 0) message += ',';
    message += channel_objects[i];
  }
  message += kTail;
  return message;
}

std::string status_json(StatusLevel level, std::string_view message) {
  return dump(json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}});
}

MessageDataHeader message_data_header(SubscriptionId subscription, std::int64_t log_time_ns) {
  const auto time_ns = static_cast<std::uint64_t>(log_time_ns < 0 ? 0 : log_time_ns);
  MessageDataHeader header{};
  header[0] = kMessageDataOpcode;
  for (std::size_t i = 0; i < 4; ++i) {
    header[1 + i] = static_cast<std::byte>((subscription >> (8 * i)) & 0xFFu);
  }
  for (std::size_t i = 0; i < 8; ++i) {
    header[5 + i] = static_cast<std::byte>((time_ns >> (8 * i)) & 0xFFu);
  }
  return header;
}

ClientRequest parse_client_request(std::string_view text) {
  // The non-throwing parse: a malformed request is the client's problem, reported to it.
  const json request = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (request.is_discarded()) return BadRequest{"malformed JSON request"};
  if (!request.is_object()) return BadRequest{"a request must be a JSON object"};
  const auto op = request.find("op");
  if (op == request.end() || !op->is_string()) return BadRequest{"a request needs an 'op' string"};
  const auto& name = op->get_ref<const std::string&>();
  if (name == "subscribe") return parse_subscribe(request);
  if (name == "unsubscribe") return parse_unsubscribe(request);
  // Quoting the op back is bounded: a client can only make its own status messages longer.
  constexpr std::size_t kMaxQuotedOpChars = 64;
  return BadRequest{
      "unsupported op '" + name.substr(0, kMaxQuotedOpChars) +
      "': this server has no capabilities and accepts only subscribe and unsubscribe"};
}

}  // namespace posed::foxglove
