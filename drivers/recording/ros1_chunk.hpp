#pragma once
// Decompression of ROS bag chunks. A Chunk record's header names its compression ("none", "bz2"
// or "lz4") and the size of its records uncompressed. bz2 is a plain bzip2 stream (rosbag writes
// it with libbz2); lz4 is roslz4's output, which is the LZ4 *frame* format (magic 0x184D2204),
// so liblz4's frame API reads it.
//
// Never throws; a chunk that does not decompress to exactly its declared size is an error with
// the reason, and the caller skips the chunk.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace posed::drivers::recording::ros1 {

enum class ChunkCompression : std::uint8_t { kNone, kBz2, kLz4, kUnknown };

/// "none" -> kNone, "bz2" -> kBz2, "lz4" -> kLz4, anything else kUnknown.
ChunkCompression parse_chunk_compression(std::string_view name);

class ChunkDecompressor {
 public:
  ChunkDecompressor() = default;
  ~ChunkDecompressor();
  ChunkDecompressor(const ChunkDecompressor&) = delete;
  ChunkDecompressor& operator=(const ChunkDecompressor&) = delete;

  /// Decompresses `in` into `out` (resized to `uncompressed_size`; its capacity is reused).
  /// kNone copies. false + `error` ("lz4: ERROR_frameType_unknown", "bz2: data ends early",
  /// "decompressed to 100 B, the chunk header says 200 B") when it fails.
  bool decompress(ChunkCompression compression, std::span<const std::byte> in,
                  std::size_t uncompressed_size, std::vector<std::byte>& out, std::string& error);

 private:
  bool lz4(std::span<const std::byte> in, std::span<std::byte> out, std::string& error);
  void* lz4_ctx_ = nullptr;  // LZ4F_dctx*, created on first use
};

}  // namespace posed::drivers::recording::ros1
