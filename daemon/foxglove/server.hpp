#pragma once
// A Foxglove WebSocket server (foxglove.websocket.v1): Foxglove Studio connects to
// ws://robot:8765, sees the channels added here and receives the messages published on those
// it subscribes to. It only serves: no client publish, parameters, services or time.
//
// Off the real-time path by construction: publish() never touches a socket. It counts, and when
// someone subscribes it copies the payload once and queues it for each subscriber; the server's
// own I/O thread writes the queues out. A client that cannot keep up loses messages once its
// queue holds max_queued_bytes_per_client, and only that client loses them; one that answers
// nothing, not even a WebSocket ping, for 30 s is disconnected.
//
// Standalone: nothing here knows DDS or the daemon; the payloads are whatever the channel's
// encoding says (CDR for posed's ROS 2 types).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "daemon/foxglove/protocol.hpp"

namespace posed::foxglove {

struct ServerOptions {
  std::string address = "127.0.0.1";  ///< IPv4 or IPv6 literal; loopback unless asked otherwise
  std::uint16_t port = 8765;          ///< 0: an ephemeral port, see Server::port() (tests)
  std::string name = "posed";         ///< serverInfo's name, shown by Foxglove Studio
  /// Queued for one client, beyond which a slow client loses messages [B]
  std::size_t max_queued_bytes_per_client = 8 << 20;
  std::size_t max_channels = 1024;  ///< add_channel() beyond this throws
};

struct ChannelStats {
  ChannelId id = 0;
  std::string topic;
  std::uint64_t messages_published = 0;  ///< publish() calls
  std::uint64_t messages_sent = 0;       ///< messageData frames written, summed over clients
  /// Messages a subscriber did not get: its queue was over the limit, or it went away with the
  /// message still queued. Per subscriber, so sent + dropped + still queued = publishes x
  /// subscribers at the time of each publish.
  std::uint64_t messages_dropped = 0;
  std::uint64_t bytes_sent = 0;  ///< of the frames sent: 13-byte header + payload [B]
};

struct ServerStats {
  std::size_t clients_connected = 0;   ///< past the WebSocket handshake and not gone
  std::uint64_t clients_accepted = 0;  ///< handshakes completed since start
  /// Connections refused before the WebSocket handshake completed: no foxglove.websocket.v1
  /// subprotocol offered, not a WebSocket upgrade, malformed or too slow.
  std::uint64_t clients_rejected = 0;
  std::uint64_t bad_requests = 0;      ///< client requests answered with a status warning
  std::uint64_t bytes_sent = 0;        ///< all WebSocket messages written, JSON included [B]
  std::vector<ChannelStats> channels;  ///< in id order
};

class Server {
 public:
  /// Binds and starts its own I/O thread. On failure returns nullptr and sets `error`, naming
  /// address:port and the OS's reason ("foxglove server: cannot listen on 127.0.0.1:8765: Address
  /// already in use").
  static std::unique_ptr<Server> start(const ServerOptions& options, std::string& error);
  ~Server();  ///< closes every client's connection and joins the I/O thread

  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Advertised to the clients connected now and to later ones when they connect. Ids count
  /// from 1. Throws std::length_error past options.max_channels. Safe from any thread.
  ChannelId add_channel(const ChannelSpec& spec);

  /// Never blocks on the network and never allocates when no client subscribes to `channel`;
  /// when some do, copies the payload once and queues it for each. A subscriber whose queue is
  /// over the limit loses the message (counted in messages_dropped). Safe from several threads;
  /// messages of one thread reach each client in the order published. An id add_channel() did
  /// not return is ignored.
  void publish(ChannelId channel, std::int64_t log_time_ns, std::span<const std::byte> payload);

  /// Waits until every client's queue has been written (or `timeout` passed; then false), so
  /// what was published last (the run's final status) reaches the clients before the server
  /// closes their connections, which discards what is queued. Any thread but the I/O thread.
  bool flush(std::chrono::milliseconds timeout);

  /// Whether any client subscribes to `channel` now: lets callers skip encoding. Lock-free.
  bool has_subscribers(ChannelId channel) const;

  std::uint16_t port() const;  ///< the bound port (the ephemeral one when options.port was 0)
  ServerStats stats() const;

  struct Impl;  // the Boost.Beast side, in server.cpp

 private:
  explicit Server(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace posed::foxglove
