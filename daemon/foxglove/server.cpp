#include "daemon/foxglove/server.hpp"

// WebSocket framing: Boost.Beast (Debian libboost-dev, 1.74, header-only over Boost.Asio).
// Why Beast rather than websocketpp 0.8.2 or libwebsockets 4.1, also in Debian 12:
// - a write takes a buffer sequence, so a messageData frame goes out as the client's own 13-byte
//   header plus the payload every subscriber shares: one copy per publish, none per client.
//   websocketpp copies each send into a message of its own, libwebsockets wants LWS_PRE bytes of
//   headroom in front of every buffer, i.e. a copy per client;
// - the HTTP upgrade request is ours to read before accepting, so a client that does not offer
//   foxglove.websocket.v1 gets a 400 saying so instead of a connection that then fails;
// - it is maintained with Boost (websocketpp's last release was 2020), brings no event loop of
//   its own, and the same library writes the test client.
// Beast's templates compile slowly; they live in this one file, behind Server::Impl.

#include <pthread.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <map>
#include <optional>
#include <shared_mutex>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>

#include "daemon/foxglove/outbox.hpp"

namespace posed::foxglove {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

/// A connection must send its HTTP upgrade request within this, or it is dropped: otherwise
/// idle TCP connections would hold descriptors forever.
constexpr auto kUpgradeRequestTimeout = std::chrono::seconds(10);
constexpr auto kHandshakeTimeout = std::chrono::seconds(10);
/// Beast's keep-alive: a client silent for half of this gets a ping (between two messages),
/// silent for all of it, it is closed. Browsers and Node's ws answer pings by themselves; this
/// catches clients gone without a FIN (cable pulled, Wi-Fi lost), which TCP alone would notice
/// only after minutes of retransmissions, and clients stuck so long they read nothing at all.
constexpr auto kIdleTimeout = std::chrono::seconds(30);
/// Requests are short JSON (subscribe lists); a larger message closes the connection (1009).
constexpr std::size_t kMaxClientMessageBytes = 1 << 20;
constexpr std::uint32_t kMaxUpgradeHeaderBytes = 8 << 10;
/// accept() failing for want of descriptors (EMFILE) fails again at once; wait before retrying.
constexpr auto kAcceptRetryDelay = std::chrono::milliseconds(100);

/// Sec-WebSocket-Protocol is a comma-separated token list, e.g. "a, foxglove.websocket.v1".
bool offers_subprotocol(std::string_view header) {
  while (!header.empty()) {
    const std::size_t comma = header.find(',');
    std::string_view token = header.substr(0, comma);
    while (!token.empty() && (token.front() == ' ' || token.front() == '\t'))
      token.remove_prefix(1);
    while (!token.empty() && (token.back() == ' ' || token.back() == '\t')) token.remove_suffix(1);
    if (token == kSubprotocol) return true;
    if (comma == std::string_view::npos) break;
    header.remove_prefix(comma + 1);
  }
  return false;
}

std::string endpoint_text(const std::string& address, std::uint16_t port) {
  const bool ipv6 = address.find(':') != std::string::npos;
  return (ipv6 ? "[" + address + "]" : address) + ":" + std::to_string(port);
}

}  // namespace

class Session;

/// What publish() reads without a lock: written by whoever counts, never moved (allocated once
/// for max_channels). A cache line each, so publishers of different channels do not contend.
struct alignas(64) ChannelSlot {
  std::atomic<std::uint32_t> subscribers{0};
  std::atomic<std::uint64_t> published{0};
  std::atomic<std::uint64_t> sent{0};
  std::atomic<std::uint64_t> dropped{0};
  std::atomic<std::uint64_t> bytes_sent{0};
  bool latched = false;  ///< set before the channel is published (channel_count's release)
};

/// A latched channel's newest message, for clients that subscribe later.
struct LatchedMessage {
  std::int64_t log_time_ns = 0;
  Payload payload;
  bool present = false;
};

struct Subscriber {
  std::shared_ptr<Session> session;
  SubscriptionId subscription = 0;
};

struct Server::Impl {
  explicit Impl(const ServerOptions& server_options)
      : options(server_options),
        session_id(std::to_string(std::chrono::system_clock::now().time_since_epoch().count())),
        slots(std::make_unique<ChannelSlot[]>(server_options.max_channels)) {}

  // ---- I/O thread ----
  void run();
  void accept_next();
  void on_accept(beast::error_code ec, tcp::socket socket);
  void shutdown();
  void handle_request(const std::shared_ptr<Session>& session, std::string_view text);
  void subscribe(const std::shared_ptr<Session>& session, const SubscribeRequest& request);
  void unsubscribe(Session& session, const UnsubscribeRequest& request);
  /// Answers a bad request with a status warning; that is all it costs the client.
  void refuse(Session& session, const std::string& reason);
  void register_session(const std::shared_ptr<Session>& session);
  void unregister_session(Session& session);

  // ---- any thread ----
  ChannelSlot* slot(ChannelId id) const {
    if (id == 0 || id > channel_count.load(std::memory_order_acquire)) return nullptr;
    return &slots[id - 1];
  }

  const ServerOptions options;
  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  asio::steady_timer accept_retry{io};
  std::uint16_t bound_port = 0;
  /// Changes the next connection's serverInfo after a restart, so Foxglove Studio, reconnecting
  /// on its own, knows to drop what it had.
  const std::string session_id;

  const std::unique_ptr<ChannelSlot[]> slots;  // [id - 1]
  std::atomic<ChannelId> channel_count{0};

  /// Guards what follows: add_channel and the I/O thread write, publish() and stats() read.
  /// Frames for a client are queued under it, so a client sees serverInfo, then the channels
  /// advertised before it connected, then every later advertise, in that order.
  mutable std::shared_mutex registry_mutex;
  std::vector<ChannelSpec> specs;                    // [id - 1]
  std::vector<std::string> channel_objects;          // [id - 1], channel_json()
  std::vector<std::vector<Subscriber>> subscribers;  // [id - 1]
  /// [id - 1]; written by publish() under the shared registry lock and latch_mutex, read by
  /// subscribe() under the unique one: a new subscriber gets each message once, never twice.
  std::vector<LatchedMessage> latched;
  std::mutex latch_mutex;
  std::vector<std::shared_ptr<Session>> sessions;  // past the handshake

  /// Every connection, handshake or not, so shutdown can close them (I/O thread only).
  std::vector<std::weak_ptr<Session>> connections;
  bool stopping = false;  // I/O thread only

  std::atomic<std::uint64_t> clients_accepted{0};
  std::atomic<std::uint64_t> clients_rejected{0};
  std::atomic<std::uint64_t> bad_requests{0};
  std::atomic<std::uint64_t> bytes_sent{0};

  std::thread thread;
};

/// One client connection: the upgrade, the read loop of its requests and the write loop of its
/// Outbox. Lives as long as one of its handlers or the registry holds it; every method but
/// send() runs on the I/O thread.
class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(Server::Impl& server, tcp::socket socket)
      : server_(server),
        executor_(server.io.get_executor()),
        ws_(std::move(socket)),
        outbox_(server.options.max_queued_bytes_per_client) {}

  void start();
  /// Any thread. False when refused: over the byte limit, or closed.
  bool send(OutFrame&& frame, Admission admission);
  /// Idempotent; ends the connection and takes the client out of the registry.
  void close();
  /// Bytes queued for the client, the frame being written included. Any thread.
  std::size_t queued_bytes() const { return outbox_.queued_bytes(); }

  /// The client's subscriptions, under Impl::registry_mutex.
  std::map<SubscriptionId, ChannelId> subscriptions;

 private:
  void on_upgrade_request(beast::error_code ec);
  void reject(std::string reason);
  void on_handshake(beast::error_code ec);
  void read_next();
  void on_read(beast::error_code ec);
  void write_next();
  void on_written(beast::error_code ec, std::size_t bytes);

  Server::Impl& server_;
  const asio::io_context::executor_type executor_;  // copied once: send() posts from any thread
  websocket::stream<beast::tcp_stream> ws_;
  std::optional<http::request_parser<http::empty_body>> upgrade_parser_;
  http::response<http::string_body> rejection_;
  beast::flat_buffer read_buffer_;
  Outbox outbox_;
  bool registered_ = false;
  bool closed_ = false;
};

// ---------------------------------------------------------------------------------------------
// Session

void Session::start() {
  beast::get_lowest_layer(ws_).expires_after(kUpgradeRequestTimeout);
  upgrade_parser_.emplace();
  upgrade_parser_->header_limit(kMaxUpgradeHeaderBytes);
  http::async_read(beast::get_lowest_layer(ws_), read_buffer_, *upgrade_parser_,
                   [self = shared_from_this()](beast::error_code ec, std::size_t) {
                     self->on_upgrade_request(ec);
                   });
}

void Session::on_upgrade_request(beast::error_code ec) {
  if (closed_) return;  // the server is stopping
  if (ec) {
    server_.clients_rejected.fetch_add(1, std::memory_order_relaxed);
    close();
    return;
  }
  const auto& request = upgrade_parser_->get();
  if (!websocket::is_upgrade(request)) {
    reject("posed's Foxglove WebSocket server: connect with a WebSocket client offering the " +
           std::string(kSubprotocol) + " subprotocol, e.g. Foxglove Studio");
    return;
  }
  const auto offered = request[http::field::sec_websocket_protocol];
  if (!offers_subprotocol(std::string_view(offered.data(), offered.size()))) {
    reject("posed's Foxglove WebSocket server speaks only the " + std::string(kSubprotocol) +
           " subprotocol, which this request does not offer");
    return;
  }
  // From here Beast's own timeouts apply: handshake, then idle with keep-alive pings.
  beast::get_lowest_layer(ws_).expires_never();
  ws_.set_option(websocket::stream_base::timeout{kHandshakeTimeout, kIdleTimeout, true});
  ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& response) {
    response.set(http::field::sec_websocket_protocol, std::string(kSubprotocol));
    response.set(http::field::server, "posed");
  }));
  ws_.read_message_max(kMaxClientMessageBytes);
  // One frame per message: server frames are unmasked, so Beast writes the header and the
  // shared payload straight from their buffers, where fragmenting would cut them into 4 KiB
  // frames for nothing (every client reassembles).
  ws_.auto_fragment(false);
  ws_.async_accept(request, [self = shared_from_this()](beast::error_code handshake_ec) {
    self->on_handshake(handshake_ec);
  });
}

void Session::reject(std::string reason) {
  server_.clients_rejected.fetch_add(1, std::memory_order_relaxed);
  const auto& request = upgrade_parser_->get();
  rejection_.version(request.version());
  rejection_.result(http::status::bad_request);
  rejection_.set(http::field::server, "posed");
  rejection_.set(http::field::content_type, "text/plain; charset=utf-8");
  rejection_.keep_alive(false);
  rejection_.body() = std::move(reason) + "\n";
  rejection_.prepare_payload();
  http::async_write(beast::get_lowest_layer(ws_), rejection_,
                    [self = shared_from_this()](beast::error_code, std::size_t) { self->close(); });
}

void Session::on_handshake(beast::error_code ec) {
  if (closed_) return;  // the server is stopping
  if (ec) {
    server_.clients_rejected.fetch_add(1, std::memory_order_relaxed);
    close();
    return;
  }
  upgrade_parser_.reset();
  read_buffer_.clear();
  server_.clients_accepted.fetch_add(1, std::memory_order_relaxed);
  registered_ = true;
  server_.register_session(shared_from_this());
  read_next();
}

void Session::read_next() {
  ws_.async_read(read_buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    self->on_read(ec);
  });
}

void Session::on_read(beast::error_code ec) {
  // closed_: a request that arrived as the connection was closed must not subscribe again.
  if (ec || closed_) {
    close();
    return;
  }
  if (ws_.got_text()) {
    const auto data = read_buffer_.cdata();
    server_.handle_request(shared_from_this(),
                           std::string_view(static_cast<const char*>(data.data()), data.size()));
  } else {
    server_.refuse(*this, "binary messages are not accepted: this server offers no clientPublish");
  }
  read_buffer_.consume(read_buffer_.size());
  read_next();
}

bool Session::send(OutFrame&& frame, Admission admission) {
  switch (outbox_.push(std::move(frame), admission)) {
    case PushResult::kQueued:
      return true;
    case PushResult::kQueuedWriterIdle:
      asio::post(executor_, [self = shared_from_this()] { self->write_next(); });
      return true;
    case PushResult::kRefusedFull:
    case PushResult::kRefusedClosed:
      return false;
  }
  return false;
}

void Session::write_next() {
  const OutFrame* frame = outbox_.begin_write();
  if (frame == nullptr) return;
  auto on_done = [self = shared_from_this()](beast::error_code ec, std::size_t bytes) {
    self->on_written(ec, bytes);
  };
  if (frame->kind == OutFrame::Kind::kText) {
    ws_.text(true);
    ws_.async_write(asio::buffer(frame->text), std::move(on_done));
    return;
  }
  ws_.binary(true);
  const std::array<asio::const_buffer, 2> buffers{
      asio::buffer(frame->header),
      asio::const_buffer(frame->payload.bytes.get(), frame->payload.size)};
  ws_.async_write(buffers, std::move(on_done));
}

void Session::on_written(beast::error_code ec, std::size_t bytes) {
  const WrittenFrame written = outbox_.end_write();
  if (written.kind == OutFrame::Kind::kMessageData) {
    ChannelSlot& slot = server_.slots[written.channel - 1];
    if (ec) {
      slot.dropped.fetch_add(1, std::memory_order_relaxed);
    } else {
      slot.sent.fetch_add(1, std::memory_order_relaxed);
      slot.bytes_sent.fetch_add(bytes, std::memory_order_relaxed);
    }
  }
  if (ec) {
    close();  // the client vanished mid-send, or closed
    return;
  }
  server_.bytes_sent.fetch_add(bytes, std::memory_order_relaxed);
  write_next();
}

void Session::close() {
  if (closed_) return;
  closed_ = true;
  if (registered_) server_.unregister_session(*this);
  for (const ChannelId channel : outbox_.close()) {
    server_.slots[channel - 1].dropped.fetch_add(1, std::memory_order_relaxed);
  }
  // Not a WebSocket close handshake: a client that does not read would hold it up. Pending
  // reads and writes complete with operation_aborted and release this session.
  beast::error_code ignored;
  beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
  beast::get_lowest_layer(ws_).close();
}

// ---------------------------------------------------------------------------------------------
// Server::Impl

void Server::Impl::run() {
  pthread_setname_np(pthread_self(), "foxglove-io");
  // A handler that throws (bad_alloc) must not end the thread: the other clients stay served.
  for (;;) {
    try {
      io.run();
      return;
    } catch (const std::exception&) {
    }
  }
}

void Server::Impl::accept_next() {
  acceptor.async_accept(
      io, [this](beast::error_code ec, tcp::socket socket) { on_accept(ec, std::move(socket)); });
}

void Server::Impl::on_accept(beast::error_code ec, tcp::socket socket) {
  if (stopping || ec == asio::error::operation_aborted) return;
  if (ec) {
    accept_retry.expires_after(kAcceptRetryDelay);
    accept_retry.async_wait([this](beast::error_code wait_ec) {
      if (!wait_ec && !stopping) accept_next();
    });
    return;
  }
  // Small frames (odometry, status) must not wait for Nagle's algorithm to fill a segment.
  beast::error_code ignored;
  socket.set_option(tcp::no_delay(true), ignored);
  auto session = std::make_shared<Session>(*this, std::move(socket));
  std::erase_if(connections, [](const std::weak_ptr<Session>& c) { return c.expired(); });
  connections.push_back(session);
  session->start();
  accept_next();
}

void Server::Impl::shutdown() {
  stopping = true;
  beast::error_code ignored;
  acceptor.close(ignored);
  accept_retry.cancel();
  for (const std::weak_ptr<Session>& connection : connections) {
    if (const auto session = connection.lock()) session->close();
  }
  connections.clear();
  // io.run() returns once the aborted operations have completed.
}

void Server::Impl::register_session(const std::shared_ptr<Session>& session) {
  std::unique_lock lock(registry_mutex);
  sessions.push_back(session);
  session->send(OutFrame::text_frame(server_info_json(options.name, session_id)),
                Admission::kAlways);
  if (!channel_objects.empty()) {
    session->send(OutFrame::text_frame(advertise_json(channel_objects)), Admission::kAlways);
  }
}

void Server::Impl::unregister_session(Session& session) {
  std::unique_lock lock(registry_mutex);
  for (const auto& [subscription, channel] : session.subscriptions) {
    std::erase_if(subscribers[channel - 1],
                  [&](const Subscriber& s) { return s.session.get() == &session; });
    slots[channel - 1].subscribers.fetch_sub(1, std::memory_order_release);
  }
  session.subscriptions.clear();
  std::erase_if(sessions, [&](const std::shared_ptr<Session>& s) { return s.get() == &session; });
}

void Server::Impl::handle_request(const std::shared_ptr<Session>& session, std::string_view text) {
  const ClientRequest request = parse_client_request(text);
  if (const auto* bad = std::get_if<BadRequest>(&request)) {
    refuse(*session, bad->reason);
  } else if (const auto* subscribe_request = std::get_if<SubscribeRequest>(&request)) {
    subscribe(session, *subscribe_request);
  } else {
    unsubscribe(*session, std::get<UnsubscribeRequest>(request));
  }
}

void Server::Impl::subscribe(const std::shared_ptr<Session>& session,
                             const SubscribeRequest& request) {
  std::vector<std::string> refusals;
  {
    std::unique_lock lock(registry_mutex);
    for (const Subscription& wanted : request.subscriptions) {
      const std::string ids = "subscription " + std::to_string(wanted.id) + " to channel " +
                              std::to_string(wanted.channel);
      if (session->subscriptions.contains(wanted.id)) {
        refusals.push_back(ids + " ignored: subscription id already in use");
        continue;
      }
      if (wanted.channel == 0 || wanted.channel > specs.size()) {
        refusals.push_back(ids + " ignored: no such channel");
        continue;
      }
      const bool already =
          std::any_of(session->subscriptions.begin(), session->subscriptions.end(),
                      [&](const auto& entry) { return entry.second == wanted.channel; });
      if (already) {
        refusals.push_back(ids + " ignored: already subscribed to that channel");
        continue;
      }
      session->subscriptions.emplace(wanted.id, wanted.channel);
      subscribers[wanted.channel - 1].push_back({session, wanted.id});
      slots[wanted.channel - 1].subscribers.fetch_add(1, std::memory_order_release);
      const LatchedMessage& last = latched[wanted.channel - 1];
      if (last.present) {
        // Counted as sent once written, as every message is.
        if (!session->send(
                OutFrame::message_data(
                    wanted.channel, message_data_header(wanted.id, last.log_time_ns), last.payload),
                Admission::kBounded)) {
          slots[wanted.channel - 1].dropped.fetch_add(1, std::memory_order_relaxed);
        }
      }
    }
  }
  for (const std::string& reason : refusals) refuse(*session, reason);
}

void Server::Impl::unsubscribe(Session& session, const UnsubscribeRequest& request) {
  std::vector<std::string> refusals;
  {
    std::unique_lock lock(registry_mutex);
    for (const SubscriptionId id : request.subscription_ids) {
      const auto it = session.subscriptions.find(id);
      if (it == session.subscriptions.end()) {
        refusals.push_back("unsubscribe " + std::to_string(id) + " ignored: no such subscription");
        continue;
      }
      const ChannelId channel = it->second;
      session.subscriptions.erase(it);
      std::erase_if(subscribers[channel - 1],
                    [&](const Subscriber& s) { return s.session.get() == &session; });
      slots[channel - 1].subscribers.fetch_sub(1, std::memory_order_release);
    }
  }
  for (const std::string& reason : refusals) refuse(session, reason);
}

void Server::Impl::refuse(Session& session, const std::string& reason) {
  bad_requests.fetch_add(1, std::memory_order_relaxed);
  // Bounded: a client that floods bad requests and reads nothing fills only its own queue.
  session.send(OutFrame::text_frame(status_json(StatusLevel::kWarning, reason)),
               Admission::kBounded);
}

// ---------------------------------------------------------------------------------------------
// Server

Server::Server(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::unique_ptr<Server> Server::start(const ServerOptions& options, std::string& error) {
  const std::string where = endpoint_text(options.address, options.port);
  beast::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options.address, ec);
  if (ec) {
    error = "foxglove server: cannot listen on " + where + ": '" + options.address +
            "' is not an IP address (" + ec.message() + ")";
    return nullptr;
  }
  auto impl = std::make_unique<Impl>(options);
  const tcp::endpoint endpoint(address, options.port);
  impl->acceptor.open(endpoint.protocol(), ec);
  if (!ec) {
    // A restarted posed must be able to bind while the last one's connections sit in TIME_WAIT.
    impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
  }
  if (!ec) impl->acceptor.bind(endpoint, ec);
  if (!ec) impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (!ec) impl->bound_port = impl->acceptor.local_endpoint(ec).port();
  if (ec) {
    error = "foxglove server: cannot listen on " + where + ": " + ec.message();
    return nullptr;
  }
  impl->accept_next();
  try {
    impl->thread = std::thread([raw = impl.get()] { raw->run(); });
  } catch (const std::system_error& e) {
    error = "foxglove server on " + where + ": cannot start its I/O thread: " + e.what();
    return nullptr;
  }
  return std::unique_ptr<Server>(new Server(std::move(impl)));
}

Server::~Server() {
  asio::post(impl_->io, [impl = impl_.get()] { impl->shutdown(); });
  if (impl_->thread.joinable()) impl_->thread.join();
}

bool Server::flush(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    bool drained = true;
    {
      std::shared_lock lock(impl_->registry_mutex);
      for (const auto& session : impl_->sessions) {
        if (session->queued_bytes() > 0) {
          drained = false;
          break;
        }
      }
    }
    if (drained) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

ChannelId Server::add_channel(const ChannelSpec& spec) {
  Impl& impl = *impl_;
  std::unique_lock lock(impl.registry_mutex);
  if (impl.specs.size() >= impl.options.max_channels) {
    throw std::length_error("foxglove server: cannot add channel " + spec.topic + ": all " +
                            std::to_string(impl.options.max_channels) +
                            " channels (ServerOptions::max_channels) are in use");
  }
  const auto id = static_cast<ChannelId>(impl.specs.size() + 1);
  impl.specs.push_back(spec);
  impl.channel_objects.push_back(channel_json(id, spec));
  impl.subscribers.emplace_back();
  impl.latched.emplace_back();
  impl.slots[id - 1].latched = spec.latched;
  impl.channel_count.store(id, std::memory_order_release);
  const std::string advertise = advertise_json(std::span(&impl.channel_objects.back(), 1));
  for (const auto& session : impl.sessions) {
    session->send(OutFrame::text_frame(advertise), Admission::kAlways);
  }
  return id;
}

void Server::publish(ChannelId channel, std::int64_t log_time_ns,
                     std::span<const std::byte> payload) {
  ChannelSlot* slot = impl_->slot(channel);
  if (slot == nullptr) return;
  slot->published.fetch_add(1, std::memory_order_relaxed);
  // The common case, free: nobody subscribes and nothing is kept for later subscribers.
  if (!slot->latched && slot->subscribers.load(std::memory_order_acquire) == 0) return;

  const Payload shared = copy_payload(payload);
  std::shared_lock lock(impl_->registry_mutex);
  if (slot->latched) {
    std::lock_guard latch(impl_->latch_mutex);
    impl_->latched[channel - 1] = {log_time_ns, shared, true};
  }
  for (const Subscriber& subscriber : impl_->subscribers[channel - 1]) {
    OutFrame frame = OutFrame::message_data(
        channel, message_data_header(subscriber.subscription, log_time_ns), shared);
    if (!subscriber.session->send(std::move(frame), Admission::kBounded)) {
      slot->dropped.fetch_add(1, std::memory_order_relaxed);
    }
  }
}

bool Server::has_subscribers(ChannelId channel) const {
  const ChannelSlot* slot = impl_->slot(channel);
  return slot != nullptr && slot->subscribers.load(std::memory_order_relaxed) > 0;
}

std::uint16_t Server::port() const { return impl_->bound_port; }

ServerStats Server::stats() const {
  const Impl& impl = *impl_;
  ServerStats stats;
  stats.clients_accepted = impl.clients_accepted.load(std::memory_order_relaxed);
  stats.clients_rejected = impl.clients_rejected.load(std::memory_order_relaxed);
  stats.bad_requests = impl.bad_requests.load(std::memory_order_relaxed);
  stats.bytes_sent = impl.bytes_sent.load(std::memory_order_relaxed);
  std::shared_lock lock(impl.registry_mutex);
  stats.clients_connected = impl.sessions.size();
  stats.channels.reserve(impl.specs.size());
  for (std::size_t i = 0; i < impl.specs.size(); ++i) {
    const ChannelSlot& slot = impl.slots[i];
    stats.channels.push_back({.id = static_cast<ChannelId>(i + 1),
                              .topic = impl.specs[i].topic,
                              .messages_published = slot.published.load(std::memory_order_relaxed),
                              .messages_sent = slot.sent.load(std::memory_order_relaxed),
                              .messages_dropped = slot.dropped.load(std::memory_order_relaxed),
                              .bytes_sent = slot.bytes_sent.load(std::memory_order_relaxed)});
  }
  return stats;
}

}  // namespace posed::foxglove
