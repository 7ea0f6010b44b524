#include "daemon/foxglove/outbox.hpp"

#include <cassert>
#include <cstring>
#include <utility>

namespace posed::foxglove {

Payload copy_payload(std::span<const std::byte> bytes) {
  if (bytes.empty()) return {};
  // for_overwrite: the bytes are written right away, zeroing them first would be a second pass.
  std::shared_ptr<std::byte[]> copy = std::make_shared_for_overwrite<std::byte[]>(bytes.size());
  std::memcpy(copy.get(), bytes.data(), bytes.size());
  return {std::move(copy), bytes.size()};
}

std::size_t OutFrame::size_bytes() const {
  return kind == Kind::kText ? text.size() : header.size() + payload.size;
}

OutFrame OutFrame::text_frame(std::string json) {
  OutFrame frame;
  frame.kind = Kind::kText;
  frame.text = std::move(json);
  return frame;
}

OutFrame OutFrame::message_data(ChannelId channel, const MessageDataHeader& header,
                                Payload payload) {
  OutFrame frame;
  frame.kind = Kind::kMessageData;
  frame.channel = channel;
  frame.header = header;
  frame.payload = std::move(payload);
  return frame;
}

PushResult Outbox::push(OutFrame&& frame, Admission admission) {
  const std::size_t size = frame.size_bytes();
  std::lock_guard lock(mutex_);
  if (closed_) return PushResult::kRefusedClosed;
  if (admission == Admission::kBounded && !frames_.empty() && queued_bytes_ + size > limit_bytes_) {
    return PushResult::kRefusedFull;
  }
  frames_.push_back(std::move(frame));
  queued_bytes_ += size;
  if (writer_active_) return PushResult::kQueued;
  writer_active_ = true;
  return PushResult::kQueuedWriterIdle;
}

const OutFrame* Outbox::begin_write() {
  std::lock_guard lock(mutex_);
  assert(!in_flight_);
  if (closed_ || frames_.empty()) {
    writer_active_ = false;
    return nullptr;
  }
  in_flight_ = true;
  return &frames_.front();
}

WrittenFrame Outbox::end_write() {
  std::lock_guard lock(mutex_);
  assert(in_flight_ && !frames_.empty());
  const OutFrame& front = frames_.front();
  const WrittenFrame written{front.kind, front.channel, front.size_bytes()};
  queued_bytes_ -= written.size_bytes;
  frames_.pop_front();
  in_flight_ = false;
  return written;
}

std::vector<ChannelId> Outbox::close() {
  std::deque<OutFrame> discarded;
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
    if (in_flight_) {
      // The write still reads the front frame; it leaves with end_write().
      discarded.assign(std::make_move_iterator(frames_.begin() + 1),
                       std::make_move_iterator(frames_.end()));
      frames_.erase(frames_.begin() + 1, frames_.end());
      queued_bytes_ = frames_.front().size_bytes();
    } else {
      discarded.swap(frames_);
      queued_bytes_ = 0;
    }
  }
  std::vector<ChannelId> dropped_channels;
  for (const OutFrame& frame : discarded) {
    if (frame.kind == OutFrame::Kind::kMessageData) dropped_channels.push_back(frame.channel);
  }
  return dropped_channels;
}

std::size_t Outbox::queued_bytes() const {
  std::lock_guard lock(mutex_);
  return queued_bytes_;
}

}  // namespace posed::foxglove
