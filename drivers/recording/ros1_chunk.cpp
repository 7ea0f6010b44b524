#include "drivers/recording/ros1_chunk.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <climits>
#include <cstring>

namespace posed::drivers::recording::ros1 {

ChunkCompression parse_chunk_compression(std::string_view name) {
  if (name == "none") return ChunkCompression::kNone;
  if (name == "bz2") return ChunkCompression::kBz2;
  if (name == "lz4") return ChunkCompression::kLz4;
  return ChunkCompression::kUnknown;
}

ChunkDecompressor::~ChunkDecompressor() {
  if (lz4_ctx_ != nullptr) LZ4F_freeDecompressionContext(static_cast<LZ4F_dctx*>(lz4_ctx_));
}

namespace {

std::string size_mismatch(std::size_t got, std::size_t want) {
  return "decompressed to " + std::to_string(got) + " B, the chunk header says " +
         std::to_string(want) + " B";
}

const char* bz2_error(int rc) {
  switch (rc) {
    case BZ_DATA_ERROR:
      return "bz2: data error (corrupt stream)";
    case BZ_DATA_ERROR_MAGIC:
      return "bz2: not a bzip2 stream (bad magic)";
    case BZ_UNEXPECTED_EOF:
      return "bz2: data ends early";
    case BZ_OUTBUFF_FULL:
      return "bz2: decompresses to more than the chunk header says";
    case BZ_MEM_ERROR:
      return "bz2: out of memory";
    default:
      return "bz2: failed";
  }
}

}  // namespace

bool ChunkDecompressor::lz4(std::span<const std::byte> in, std::span<std::byte> out,
                            std::string& error) {
  if (lz4_ctx_ == nullptr) {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
      error = "lz4: cannot create a decompression context";
      return false;
    }
    lz4_ctx_ = ctx;
  }
  auto* ctx = static_cast<LZ4F_dctx*>(lz4_ctx_);
  // A context left mid-frame by an earlier bad chunk must not leak state into this one.
  LZ4F_resetDecompressionContext(ctx);
  std::size_t in_pos = 0, out_pos = 0;
  for (;;) {
    std::size_t in_size = in.size() - in_pos;
    std::size_t out_size = out.size() - out_pos;
    const std::size_t hint = LZ4F_decompress(ctx, out.data() + out_pos, &out_size,
                                             in.data() + in_pos, &in_size, nullptr);
    if (LZ4F_isError(hint)) {
      error = std::string("lz4: ") + LZ4F_getErrorName(hint);
      return false;
    }
    in_pos += in_size;
    out_pos += out_size;
    if (hint == 0) break;  // frame complete
    if (in_pos >= in.size()) {
      error = "lz4: frame ends early (" + std::to_string(in.size()) + " B compressed, " +
              std::to_string(out_pos) + " B out)";
      return false;
    }
    if (in_size == 0 && out_size == 0) {
      // No progress: the output is full while the frame goes on.
      error = "lz4: decompresses to more than the chunk header says (" +
              std::to_string(out.size()) + " B)";
      return false;
    }
  }
  if (out_pos != out.size()) {
    error = "lz4: " + size_mismatch(out_pos, out.size());
    return false;
  }
  return true;
}

bool ChunkDecompressor::decompress(ChunkCompression compression, std::span<const std::byte> in,
                                   std::size_t uncompressed_size, std::vector<std::byte>& out,
                                   std::string& error) {
  out.resize(uncompressed_size);
  switch (compression) {
    case ChunkCompression::kNone:
      if (in.size() != uncompressed_size) {
        error = "none: " + size_mismatch(in.size(), uncompressed_size);
        return false;
      }
      if (!in.empty()) std::memcpy(out.data(), in.data(), in.size());
      return true;
    case ChunkCompression::kBz2: {
      if (in.size() > UINT_MAX || uncompressed_size > UINT_MAX) {
        error = "bz2: chunk larger than 4 GiB";
        return false;
      }
      auto dest_len = static_cast<unsigned int>(uncompressed_size);
      // libbz2 takes non-const pointers but does not write through `source`.
      const int rc = BZ2_bzBuffToBuffDecompress(
          reinterpret_cast<char*>(out.data()), &dest_len,
          const_cast<char*>(reinterpret_cast<const char*>(in.data())),
          static_cast<unsigned int>(in.size()), /*small=*/0, /*verbosity=*/0);
      if (rc != BZ_OK) {
        error = bz2_error(rc);
        return false;
      }
      if (dest_len != uncompressed_size) {
        error = "bz2: " + size_mismatch(dest_len, uncompressed_size);
        return false;
      }
      return true;
    }
    case ChunkCompression::kLz4:
      return lz4(in, out, error);
    case ChunkCompression::kUnknown:
      break;
  }
  error = "unknown compression";
  return false;
}

}  // namespace posed::drivers::recording::ros1
