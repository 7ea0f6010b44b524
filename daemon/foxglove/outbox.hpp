#pragma once
// What one client is yet to be sent: its frames in order, bounded in bytes, written one at a
// time by the server's I/O thread while any thread may push.
//
// Why a mutex around a deque rather than posed's lock-free SpscQueue: any number of threads
// publish, and the bound is in bytes, not items (a 2 MB cloud and a 700 B odometry share one
// budget). The lock is held for a push or a pop, never across I/O, so a publisher waits at most
// for another publisher's push. A deque because pushing never moves queued frames: the frame
// being written stays where the WebSocket write is reading it.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "daemon/foxglove/protocol.hpp"

namespace posed::foxglove {

/// One publish()'s bytes, copied once and shared by every subscriber's frame.
struct Payload {
  std::shared_ptr<const std::byte[]> bytes;  ///< null when size is 0
  std::size_t size = 0;                      ///< [B]
};
Payload copy_payload(std::span<const std::byte> bytes);

struct OutFrame {
  enum class Kind : std::uint8_t { kText, kMessageData };
  Kind kind = Kind::kText;
  ChannelId channel = 0;           ///< kMessageData: whose counters its fate moves
  MessageDataHeader header{};      ///< kMessageData
  Payload payload;                 ///< kMessageData
  std::string text;                ///< kText: JSON
  std::size_t size_bytes() const;  ///< as counted against the limit and sent [B]

  static OutFrame text_frame(std::string json);
  static OutFrame message_data(ChannelId channel, const MessageDataHeader& header, Payload payload);
};

/// How a push meets the byte limit.
enum class Admission : std::uint8_t {
  kBounded,  ///< refused when over the limit: messageData, status (a slow client loses them)
  kAlways,   ///< queued whatever the size: serverInfo, advertise (without them a client is lost)
};

enum class PushResult : std::uint8_t {
  kQueued,            ///< queued; the writer is already busy and will reach it
  kQueuedWriterIdle,  ///< queued; the caller must schedule the writer (begin_write)
  kRefusedFull,       ///< not queued: the queue is over its byte limit
  kRefusedClosed,     ///< not queued: the client is gone
};

/// What end_write() removed, for the counters.
struct WrittenFrame {
  OutFrame::Kind kind = OutFrame::Kind::kText;
  ChannelId channel = 0;
  std::size_t size_bytes = 0;  ///< [B]
};

class Outbox {
 public:
  /// A bounded push is refused when the queued bytes plus its own would exceed `limit_bytes`,
  /// unless the queue is empty: one message larger than the limit still reaches an idle client.
  explicit Outbox(std::size_t limit_bytes) : limit_bytes_(limit_bytes) {}

  PushResult push(OutFrame&& frame, Admission admission);

  /// The next frame to write, or nullptr when there is none or the outbox is closed, in which
  /// case the writer is idle again and the next push says kQueuedWriterIdle. The frame stays
  /// valid and in place until end_write().
  const OutFrame* begin_write();
  /// Removes the frame begin_write() returned, once its write has completed, well or not.
  WrittenFrame end_write();

  /// Refuses every later push and discards what is queued, except a frame being written (its
  /// end_write() still comes). Returns the channel of each discarded messageData frame.
  std::vector<ChannelId> close();

  std::size_t queued_bytes() const;  ///< [B], the frame being written included

 private:
  mutable std::mutex mutex_;
  std::deque<OutFrame> frames_;
  std::size_t queued_bytes_ = 0;
  const std::size_t limit_bytes_;
  bool writer_active_ = false;  ///< a writer is scheduled or writing
  bool in_flight_ = false;      ///< frames_.front() is being written
  bool closed_ = false;
};

}  // namespace posed::foxglove
