#include "drivers/recording/ros1_bag_records.hpp"

#include <bit>
#include <cstdio>
#include <cstring>

namespace posed::drivers::recording::ros1 {

static_assert(std::endian::native == std::endian::little,
              "ROS bags are little-endian; the loads below assume a little-endian host");

std::string_view op_name(std::uint8_t op) {
  switch (static_cast<BagOp>(op)) {
    case BagOp::kMessageData:
      return "MessageData";
    case BagOp::kBagHeader:
      return "BagHeader";
    case BagOp::kIndexData:
      return "IndexData";
    case BagOp::kChunk:
      return "Chunk";
    case BagOp::kChunkInfo:
      return "ChunkInfo";
    case BagOp::kConnection:
      return "Connection";
  }
  return "unknown";
}

std::uint32_t load_u32(const std::byte* p) {
  std::uint32_t v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::uint64_t load_u64(const std::byte* p) {
  std::uint64_t v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

std::uint64_t load_time_ns(const std::byte* p) {
  return static_cast<std::uint64_t>(load_u32(p)) * 1'000'000'000ull + load_u32(p + 4);
}

RecordStatus read_record(std::span<const std::byte> bytes, std::uint64_t at, BagRecord& out,
                         std::uint64_t& needed) {
  const std::uint64_t size = bytes.size();
  const std::uint64_t left = at <= size ? size - at : 0;
  needed = 4;
  if (left < needed) return RecordStatus::kTruncated;
  const std::uint64_t header_len = load_u32(bytes.data() + at);
  needed = 8 + header_len;
  if (left < needed) return RecordStatus::kTruncated;
  const std::uint64_t data_len = load_u32(bytes.data() + at + 4 + header_len);
  needed = 8 + header_len + data_len;
  if (left < needed) return RecordStatus::kTruncated;
  out.header =
      bytes.subspan(static_cast<std::size_t>(at + 4), static_cast<std::size_t>(header_len));
  out.data = bytes.subspan(static_cast<std::size_t>(at + 8 + header_len),
                           static_cast<std::size_t>(data_len));
  out.size_bytes = needed;
  return RecordStatus::kOk;
}

bool RecordFields::parse(std::span<const std::byte> header, std::string& error) {
  count_ = 0;
  dropped_ = 0;
  std::size_t pos = 0;
  std::size_t index = 0;
  while (pos < header.size()) {
    char buf[160];
    if (header.size() - pos < 4) {
      std::snprintf(buf, sizeof buf, "field %zu at +%zu: %zu B left, a length needs 4", index, pos,
                    header.size() - pos);
      error = buf;
      return false;
    }
    const std::size_t len = load_u32(header.data() + pos);
    pos += 4;
    if (len > header.size() - pos) {
      std::snprintf(buf, sizeof buf, "field %zu at +%zu: length %zu runs past the header (%zu B)",
                    index, pos - 4, len, header.size());
      error = buf;
      return false;
    }
    const auto* text = reinterpret_cast<const char*>(header.data() + pos);
    const void* eq = std::memchr(text, '=', len);
    if (eq == nullptr) {
      std::snprintf(buf, sizeof buf, "field %zu at +%zu: no '=' in its %zu B", index, pos - 4, len);
      error = buf;
      return false;
    }
    const auto name_len = static_cast<std::size_t>(static_cast<const char*>(eq) - text);
    if (count_ < kMaxFields) {
      fields_[count_++] = {std::string_view(text, name_len),
                           header.subspan(pos + name_len + 1, len - name_len - 1)};
    } else {
      ++dropped_;
    }
    pos += len;
    ++index;
  }
  return true;
}

std::optional<std::span<const std::byte>> RecordFields::find(std::string_view name) const {
  for (std::size_t i = 0; i < count_; ++i) {
    if (fields_[i].name == name) return fields_[i].value;
  }
  return std::nullopt;
}

bool RecordFields::get_u8(std::string_view name, std::uint8_t& out) const {
  const auto v = find(name);
  if (!v || v->size() != 1) return false;
  out = static_cast<std::uint8_t>((*v)[0]);
  return true;
}

bool RecordFields::get_u32(std::string_view name, std::uint32_t& out) const {
  const auto v = find(name);
  if (!v || v->size() != 4) return false;
  out = load_u32(v->data());
  return true;
}

bool RecordFields::get_u64(std::string_view name, std::uint64_t& out) const {
  const auto v = find(name);
  if (!v || v->size() != 8) return false;
  out = load_u64(v->data());
  return true;
}

bool RecordFields::get_time_ns(std::string_view name, std::uint64_t& out) const {
  const auto v = find(name);
  if (!v || v->size() != 8) return false;
  out = load_time_ns(v->data());
  return true;
}

bool RecordFields::get_string(std::string_view name, std::string_view& out) const {
  const auto v = find(name);
  if (!v) return false;
  out = std::string_view(reinterpret_cast<const char*>(v->data()), v->size());
  return true;
}

}  // namespace posed::drivers::recording::ros1
