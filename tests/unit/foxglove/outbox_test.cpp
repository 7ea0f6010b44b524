// A client's outbox: the byte limit, the writer hand-off, and what closing discards.

#include "daemon/foxglove/outbox.hpp"

#include <gtest/gtest.h>

#include <string>

namespace posed::foxglove {
namespace {

OutFrame message(ChannelId channel, std::size_t payload_bytes) {
  const std::string bytes(payload_bytes, 'x');
  return OutFrame::message_data(channel, message_data_header(1, 0),
                                copy_payload(std::as_bytes(std::span(bytes.data(), bytes.size()))));
}

TEST(FoxgloveOutbox, TheFirstPushWakesTheWriterAndLaterOnesDoNot) {
  Outbox outbox(1 << 20);
  EXPECT_EQ(outbox.push(OutFrame::text_frame("{}"), Admission::kBounded),
            PushResult::kQueuedWriterIdle);
  EXPECT_EQ(outbox.push(message(1, 10), Admission::kBounded), PushResult::kQueued);
  EXPECT_EQ(outbox.queued_bytes(), 2 + kMessageDataHeaderBytes + 10);

  ASSERT_NE(outbox.begin_write(), nullptr);
  EXPECT_EQ(outbox.end_write().kind, OutFrame::Kind::kText);
  const OutFrame* frame = outbox.begin_write();
  ASSERT_NE(frame, nullptr);
  EXPECT_EQ(frame->payload.size, 10u);
  const WrittenFrame written = outbox.end_write();
  EXPECT_EQ(written.channel, 1u);
  EXPECT_EQ(written.size_bytes, kMessageDataHeaderBytes + 10);
  EXPECT_EQ(outbox.begin_write(), nullptr);  // empty: the writer goes idle
  EXPECT_EQ(outbox.push(message(1, 10), Admission::kBounded), PushResult::kQueuedWriterIdle);
}

TEST(FoxgloveOutbox, BoundedPushesStopAtTheLimitButAnEmptyQueueTakesOne) {
  Outbox outbox(100);
  // Larger than the whole limit, but the queue is empty: an idle client still gets a big cloud.
  EXPECT_EQ(outbox.push(message(1, 500), Admission::kBounded), PushResult::kQueuedWriterIdle);
  EXPECT_EQ(outbox.push(message(1, 1), Admission::kBounded), PushResult::kRefusedFull);
  // Channel announcements are never refused.
  EXPECT_EQ(outbox.push(OutFrame::text_frame(std::string(300, 'a')), Admission::kAlways),
            PushResult::kQueued);
}

TEST(FoxgloveOutbox, PayloadIsSharedNotCopiedPerFrame) {
  const std::string bytes(1000, 'p');
  const Payload payload = copy_payload(std::as_bytes(std::span(bytes.data(), bytes.size())));
  const OutFrame a = OutFrame::message_data(1, message_data_header(1, 0), payload);
  const OutFrame b = OutFrame::message_data(1, message_data_header(2, 0), payload);
  EXPECT_EQ(a.payload.bytes.get(), b.payload.bytes.get());
  EXPECT_EQ(copy_payload({}).bytes, nullptr);
}

TEST(FoxgloveOutbox, CloseDiscardsAllButTheFrameBeingWritten) {
  Outbox outbox(1 << 20);
  outbox.push(message(1, 10), Admission::kBounded);
  outbox.push(OutFrame::text_frame("{}"), Admission::kBounded);
  outbox.push(message(2, 10), Admission::kBounded);
  outbox.push(message(3, 10), Admission::kBounded);
  ASSERT_NE(outbox.begin_write(), nullptr);  // channel 1's frame is on the wire

  EXPECT_EQ(outbox.close(), (std::vector<ChannelId>{2, 3}));
  EXPECT_EQ(outbox.push(message(1, 1), Admission::kAlways), PushResult::kRefusedClosed);
  EXPECT_EQ(outbox.end_write().channel, 1u);  // its write completes, well or not
  EXPECT_EQ(outbox.begin_write(), nullptr);
  EXPECT_EQ(outbox.queued_bytes(), 0u);
}

TEST(FoxgloveOutbox, CloseWithTheWriterIdleDiscardsEverything) {
  Outbox outbox(1 << 20);
  outbox.push(message(4, 10), Admission::kBounded);  // writer scheduled, not yet writing
  EXPECT_EQ(outbox.close(), (std::vector<ChannelId>{4}));
  EXPECT_EQ(outbox.begin_write(), nullptr);
}

}  // namespace
}  // namespace posed::foxglove
