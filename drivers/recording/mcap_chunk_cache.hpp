#pragma once
// Decompressed chunks shared by several readers of one MCAP file. A replay reads the file once per
// stream (each McapReplaySource has its own McapReader, so a stream never waits for another), and
// each reader used to decompress and CRC every chunk: with four streams, LZ4 and the CRC were a
// sixth of a four-sensor replay's CPU. The streams advance through the file roughly together, so
// the first reader to reach a chunk decompresses and checks it and the others find it here. Only
// chunks that decompressed to their size and passed their CRC are shared; a reader that misses
// (evicted, or far ahead) decompresses on its own, so nothing depends on the cache but speed.
// Thread-safe; a chunk handed out stays alive while a reader walks it, whatever is evicted.
// Chunk buffers are reused: a replay decompresses megabytes a second, and fresh 1 MB blocks
// interleaved with the estimator's long-lived allocations left the heap holding 10-15 MB more at
// the end of one pass of a looped replay than another (docs/faults.md, stop 46).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace posed::drivers::recording {

struct McapChunkCacheCounters {
  std::uint64_t hits = 0;    ///< chunks a reader found decompressed [1]
  std::uint64_t misses = 0;  ///< chunks a reader decompressed itself [1]
};

class McapChunkCache {
 public:
  using Chunk = std::shared_ptr<const std::vector<std::byte>>;

  /// Keeps the chunks most recently added, up to `capacity_bytes` decompressed (the newest
  /// always). The streams read within a read-ahead window (150 ms) of each other at recorded
  /// timing and within their queues' depth at full speed: 16 MB is a few seconds of a four-sensor
  /// recording. (32 chunks, as it was, held 85 MB of a replay's 155 MB heap.)
  explicit McapChunkCache(std::size_t capacity_bytes = 16u << 20)
      : capacity_bytes_(capacity_bytes) {}

  /// A buffer to decompress a chunk into (resize it; what it holds is a stale chunk's bytes) and
  /// then add(): the storage of a chunk that was evicted and that no reader walks any more when
  /// there is one, else new.
  std::shared_ptr<std::vector<std::byte>> buffer() {
    std::unique_ptr<std::vector<std::byte>> storage;
    {
      std::lock_guard lock(spare_->mutex);
      if (!spare_->buffers.empty()) {
        storage = std::move(spare_->buffers.back());
        spare_->buffers.pop_back();
        ++spare_->reused;
      }
    }
    if (!storage) storage = std::make_unique<std::vector<std::byte>>();
    // The deleter holds the spare list, not the cache: a reader may outlive the cache.
    return {storage.release(), [spare = spare_](std::vector<std::byte>* b) {
              std::unique_ptr<std::vector<std::byte>> owned(b);
              std::lock_guard lock(spare->mutex);
              if (spare->buffers.size() < kMaxSpareBuffers)
                spare->buffers.push_back(std::move(owned));
            }};
  }

  /// buffer() calls served by a buffer a chunk had before [1]
  std::uint64_t buffers_reused() const {
    std::lock_guard lock(spare_->mutex);
    return spare_->reused;
  }

  /// The chunk at file offset `offset`, decompressed and checked, or null.
  Chunk find(std::uint64_t offset) {
    std::lock_guard lock(mutex_);
    for (const auto& [at, chunk] : chunks_) {
      if (at == offset) {
        ++counters_.hits;
        return chunk;
      }
    }
    ++counters_.misses;
    return nullptr;
  }

  void add(std::uint64_t offset, Chunk chunk) {
    std::lock_guard lock(mutex_);
    for (const auto& entry : chunks_) {
      if (entry.first == offset) return;  // another reader was quicker
    }
    bytes_ += chunk->size();
    chunks_.emplace_back(offset, std::move(chunk));
    while (chunks_.size() > 1 && bytes_ > capacity_bytes_) {
      bytes_ -= chunks_.front().second->size();
      chunks_.pop_front();
    }
  }

  /// True for the first reader that asks (on its first read): that one folds the data section's
  /// CRC, over the same bytes every other reader of the file walks (one pass instead of one per
  /// stream: 6 % of a four-sensor replay's CPU). Chunks stay checked by whoever decompresses them.
  bool claim_data_crc() {
    std::lock_guard lock(mutex_);
    if (data_crc_claimed_) return false;
    data_crc_claimed_ = true;
    return true;
  }

  McapChunkCacheCounters counters() const {
    std::lock_guard lock(mutex_);
    return counters_;
  }

 private:
  /// Evicted chunks free their buffers one at a time, and each is taken again by the next
  /// decompression; a few spare cover readers that drop several at once.
  static constexpr std::size_t kMaxSpareBuffers = 4;
  struct Spare {
    std::mutex mutex;
    std::vector<std::unique_ptr<std::vector<std::byte>>> buffers;
    std::uint64_t reused = 0;
  };

  const std::size_t capacity_bytes_;
  std::size_t bytes_ = 0;  // decompressed bytes of the chunks held
  std::shared_ptr<Spare> spare_ = std::make_shared<Spare>();
  mutable std::mutex mutex_;
  std::deque<std::pair<std::uint64_t, Chunk>> chunks_;  // oldest first
  McapChunkCacheCounters counters_;
  bool data_crc_claimed_ = false;
};

}  // namespace posed::drivers::recording
