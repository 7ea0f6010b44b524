#pragma once
// A Foxglove client for the tests, on the server's WebSocket library (Boost.Beast) but written
// from the spec: every wait has a deadline, so a broken server fails a test instead of hanging
// it. Single-threaded: its io_context runs only inside its own calls, so a client the test stops
// calling is a client that stops reading.

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/foxglove/protocol.hpp"

namespace posed::foxglove::test {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using namespace std::chrono_literals;

struct Received {
  bool binary = false;
  std::string data;
};

/// A messageData frame taken apart.
struct MessageData {
  SubscriptionId subscription = 0;
  std::uint64_t log_time_ns = 0;
  std::string payload;
};

inline std::optional<MessageData> parse_message_data(const Received& frame) {
  if (!frame.binary || frame.data.size() < kMessageDataHeaderBytes ||
      static_cast<std::byte>(frame.data[0]) != kMessageDataOpcode) {
    return std::nullopt;
  }
  auto byte = [&](std::size_t i) { return static_cast<std::uint8_t>(frame.data[i]); };
  MessageData message;
  for (std::size_t i = 0; i < 4; ++i)
    message.subscription |= SubscriptionId{byte(1 + i)} << (8 * i);
  for (std::size_t i = 0; i < 8; ++i) message.log_time_ns |= std::uint64_t{byte(5 + i)} << (8 * i);
  message.payload = frame.data.substr(kMessageDataHeaderBytes);
  return message;
}

class TestClient {
 public:
  struct ConnectOptions {
    std::string subprotocol{kSubprotocol};  ///< empty: offer none
    int receive_buffer_bytes = 0;           ///< 0: the kernel's default [B]
  };

  /// Connects to 127.0.0.1:port and completes the WebSocket handshake. Returns "" or what failed;
  /// a refused handshake leaves the server's HTTP response in rejection().
  std::string connect(std::uint16_t port, const ConnectOptions& options) {
    beast::error_code ec;
    auto& socket = beast::get_lowest_layer(ws_).socket();
    socket.open(tcp::v4(), ec);
    if (!ec && options.receive_buffer_bytes > 0) {
      socket.set_option(asio::socket_base::receive_buffer_size(options.receive_buffer_bytes), ec);
    }
    if (ec) return "socket: " + ec.message();
    bool connected = false;
    socket.async_connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port),
                         [&](beast::error_code connect_ec) {
                           ec = connect_ec;
                           connected = true;
                         });
    if (!run_until(connected, 2s)) return "connect: timed out";
    if (ec) return "connect: " + ec.message();

    const std::string subprotocol = options.subprotocol;
    ws_.set_option(
        websocket::stream_base::decorator([subprotocol](websocket::request_type& request) {
          if (!subprotocol.empty()) request.set(http::field::sec_websocket_protocol, subprotocol);
        }));
    bool handshaken = false;
    ws_.async_handshake(rejection_, "127.0.0.1:" + std::to_string(port), "/",
                        [&](beast::error_code handshake_ec) {
                          ec = handshake_ec;
                          handshaken = true;
                        });
    if (!run_until(handshaken, 2s)) return "handshake: timed out";
    if (ec) return "handshake: " + ec.message();
    return "";
  }
  std::string connect(std::uint16_t port) { return connect(port, ConnectOptions{}); }

  /// The server's answer to the handshake (the 400 and its reason when refused).
  const http::response<http::string_body>& rejection() const { return rejection_; }

  /// The next message within `timeout`, or nullopt (timeout, or the connection ended).
  std::optional<Received> next(std::chrono::milliseconds timeout = 2s) {
    if (!read_pending_) {
      read_pending_ = true;
      read_done_ = false;
      ws_.async_read(buffer_, [this](beast::error_code ec, std::size_t) {
        read_ec_ = ec;
        read_done_ = true;
      });
    }
    if (!run_until(read_done_, timeout)) return std::nullopt;
    read_pending_ = false;
    if (read_ec_) return std::nullopt;
    Received received{ws_.got_binary(), beast::buffers_to_string(buffer_.cdata())};
    buffer_.consume(buffer_.size());
    return received;
  }

  /// The next message, which must be JSON text; a null json otherwise.
  nlohmann::json next_json(std::chrono::milliseconds timeout = 2s) {
    const auto received = next(timeout);
    if (!received || received->binary) return nullptr;
    return nlohmann::json::parse(received->data, nullptr, false);
  }

  /// The next messageData, skipping nothing: anything else is a nullopt.
  std::optional<MessageData> next_message_data(std::chrono::milliseconds timeout = 2s) {
    const auto received = next(timeout);
    if (!received) return std::nullopt;
    return parse_message_data(*received);
  }

  bool send_text(std::string_view text) {
    ws_.text(true);
    return write(asio::buffer(text.data(), text.size()));
  }
  bool send_binary(std::string_view bytes) {
    ws_.binary(true);
    return write(asio::buffer(bytes.data(), bytes.size()));
  }
  bool subscribe(SubscriptionId id, ChannelId channel) {
    return send_text(nlohmann::json{{"op", "subscribe"},
                                    {"subscriptions", {{{"id", id}, {"channelId", channel}}}}}
                         .dump());
  }
  bool unsubscribe(SubscriptionId id) {
    return send_text(nlohmann::json{{"op", "unsubscribe"}, {"subscriptionIds", {id}}}.dump());
  }

  /// Vanishes: a TCP reset, no WebSocket close, as a client killed or unplugged mid-transfer.
  void vanish() {
    beast::error_code ec;
    auto& socket = beast::get_lowest_layer(ws_).socket();
    socket.set_option(asio::socket_base::linger(true, 0), ec);
    socket.close(ec);
  }

 private:
  template <class Buffer>
  bool write(const Buffer& buffer) {
    bool done = false;
    beast::error_code ec;
    ws_.async_write(buffer, [&](beast::error_code write_ec, std::size_t) {
      ec = write_ec;
      done = true;
    });
    return run_until(done, 2s) && !ec;
  }

  /// Runs this client's handlers until `done` or the deadline.
  bool run_until(const bool& done, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    io_.restart();
    while (!done) {
      const auto now = std::chrono::steady_clock::now();
      if (now >= deadline) return false;
      io_.run_one_for(deadline - now);
    }
    return true;
  }

  asio::io_context io_;
  websocket::stream<beast::tcp_stream> ws_{io_};
  http::response<http::string_body> rejection_;
  beast::flat_buffer buffer_;
  bool read_pending_ = false;
  bool read_done_ = false;
  beast::error_code read_ec_;
};

}  // namespace posed::foxglove::test
