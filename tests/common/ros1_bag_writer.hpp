#pragma once
// Test-only writer of ROS bags, format 2.0 (wiki.ros.org/Bags/Format/2.0), written as `rosbag
// record` writes them: the magic line, a bag header record padded to 4096 B, Chunk records
// (none, bz2 or lz4 = LZ4 frame as roslz4 writes) each holding the Connection record of every
// connection first used in it and the MessageData records, followed by one IndexData record per
// connection in the chunk, then at index_pos every Connection record and one ChunkInfo record
// per chunk. The bag header is rewritten at the end with index_pos, conn_count and chunk_count.
// Without close() (or with write_index = false) the bag looks like one whose recorder was
// killed: index_pos 0, no index section.
//
// Header-only so the reader's tests and the replay tests share it; it never uses the reader.

#include <bzlib.h>
#include <lz4frame.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace posed::test {

class Ros1BagWriter {
 public:
  enum class Compression { kNone, kBz2, kLz4 };
  struct Options {
    static Options with(Compression c, std::size_t chunk_threshold_bytes = 768 * 1024,
                        bool write_index = true) {
      Options o;
      o.compression = c;
      o.chunk_threshold_bytes = chunk_threshold_bytes;
      o.write_index = write_index;
      return o;
    }
    Compression compression = Compression::kNone;
    /// a chunk is closed once its uncompressed records reach this size (rosbag: 768 KiB) [B]
    std::size_t chunk_threshold_bytes = 768 * 1024;
    /// write the index section and the final bag header
    bool write_index = true;
  };

  Ros1BagWriter() : Ros1BagWriter(Options{}) {}
  explicit Ros1BagWriter(Options options) : options_(options) {
    append(kMagic);
    header_offset_ = bytes_.size();
    put(bytes_, bag_header_record());
  }

  /// A connection; returns its id (0, 1, ...).
  std::uint32_t add_connection(std::string topic, std::string type, std::string md5sum,
                               std::string definition, std::string callerid = "",
                               bool latching = false) {
    Connection c{static_cast<std::uint32_t>(connections_.size()),
                 std::move(topic),
                 std::move(type),
                 std::move(md5sum),
                 std::move(definition),
                 std::move(callerid),
                 latching};
    connections_.push_back(std::move(c));
    return connections_.back().id;
  }

  /// One message received at `time_ns` (bag time) [ns].
  void write(std::uint32_t conn, std::uint64_t time_ns, std::span<const std::byte> data) {
    const Connection& c = connections_.at(conn);
    if (!in_chunk_.count(conn)) {
      in_chunk_[conn] = {};
      connection_record(chunk_, c);
    }
    in_chunk_[conn].push_back({time_ns, static_cast<std::uint32_t>(chunk_.size())});
    std::vector<std::byte> header;
    field(header, "op", u8(0x02));
    field(header, "conn", u32(conn));
    field(header, "time", time(time_ns));
    record(chunk_, header, data);
    chunk_start_ = chunk_messages_ == 0 ? time_ns : std::min(chunk_start_, time_ns);
    chunk_end_ = std::max(chunk_end_, time_ns);
    ++chunk_messages_;
    if (chunk_.size() >= options_.chunk_threshold_bytes) close_chunk();
  }
  void write(std::uint32_t conn, std::uint64_t time_ns, const std::vector<std::byte>& data) {
    write(conn, time_ns, std::span<const std::byte>(data));
  }

  /// A MessageData record on connection id `conn` that was never added (bad input for tests):
  /// goes into the current chunk without a Connection record or index entry.
  void write_orphan(std::uint32_t conn, std::uint64_t time_ns, std::span<const std::byte> data) {
    std::vector<std::byte> header;
    field(header, "op", u8(0x02));
    field(header, "conn", u32(conn));
    field(header, "time", time(time_ns));
    record(chunk_, header, data);
  }

  /// Finishes the last chunk and, unless write_index is false, the index and the bag header.
  const std::vector<std::byte>& close() {
    close_chunk();
    if (!options_.write_index || closed_) return bytes_;
    closed_ = true;
    index_pos_ = bytes_.size();
    for (const Connection& c : connections_) connection_record(bytes_, c);
    for (const ChunkInfo& ci : chunk_infos_) {
      std::vector<std::byte> header, data;
      field(header, "op", u8(0x06));
      field(header, "ver", u32(1));
      field(header, "chunk_pos", u64(ci.pos));
      field(header, "start_time", time(ci.start));
      field(header, "end_time", time(ci.end));
      field(header, "count", u32(static_cast<std::uint32_t>(ci.counts.size())));
      for (const auto& [conn, n] : ci.counts) {
        put(data, u32(conn));
        put(data, u32(n));
      }
      record(bytes_, header, data);
    }
    // Same field sizes as the placeholder, so the record keeps its 4096 B.
    const std::vector<std::byte> header = bag_header_record();
    std::memcpy(bytes_.data() + header_offset_, header.data(), header.size());
    return bytes_;
  }

  const std::vector<std::byte>& bytes() const { return bytes_; }
  /// file offsets of the Chunk records written so far [B]
  std::vector<std::uint64_t> chunk_offsets() const {
    std::vector<std::uint64_t> out;
    for (const ChunkInfo& ci : chunk_infos_) out.push_back(ci.pos);
    return out;
  }

  /// messages in each chunk written so far
  std::vector<std::uint64_t> chunk_message_counts() const {
    std::vector<std::uint64_t> out;
    for (const ChunkInfo& ci : chunk_infos_) {
      std::uint64_t n = 0;
      for (const auto& [conn, count] : ci.counts) n += count;
      out.push_back(n);
    }
    return out;
  }

  void save(const std::string& path) const {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes_.data()),
              static_cast<std::streamsize>(bytes_.size()));
    if (!out) throw std::runtime_error("cannot write " + path);
  }

 private:
  static constexpr std::string_view kMagic = "#ROSBAG V2.0\n";
  struct Connection {
    std::uint32_t id;
    std::string topic, type, md5sum, definition, callerid;
    bool latching;
  };
  struct Entry {
    std::uint64_t time_ns;
    std::uint32_t offset;
  };
  struct ChunkInfo {
    std::uint64_t pos, start, end;
    std::map<std::uint32_t, std::uint32_t> counts;
  };

  template <class T>
  static std::vector<std::byte> pod(T v) {
    std::vector<std::byte> b(sizeof v);
    std::memcpy(b.data(), &v, sizeof v);
    return b;
  }
  static std::vector<std::byte> u8(std::uint8_t v) { return pod(v); }
  static std::vector<std::byte> u32(std::uint32_t v) { return pod(v); }
  static std::vector<std::byte> u64(std::uint64_t v) { return pod(v); }
  static std::vector<std::byte> time(std::uint64_t ns) {
    std::vector<std::byte> b = u32(static_cast<std::uint32_t>(ns / 1'000'000'000));
    const auto n = u32(static_cast<std::uint32_t>(ns % 1'000'000'000));
    b.insert(b.end(), n.begin(), n.end());
    return b;
  }
  static std::vector<std::byte> text(std::string_view s) {
    std::vector<std::byte> b(s.size());
    if (!s.empty()) std::memcpy(b.data(), s.data(), s.size());
    return b;
  }
  static void put(std::vector<std::byte>& out, std::span<const std::byte> b) {
    out.insert(out.end(), b.begin(), b.end());
  }
  void append(std::string_view s) { put(bytes_, text(s)); }
  static void field(std::vector<std::byte>& header, std::string_view name,
                    const std::vector<std::byte>& value) {
    put(header, u32(static_cast<std::uint32_t>(name.size() + 1 + value.size())));
    put(header, text(name));
    header.push_back(std::byte{'='});
    put(header, value);
  }
  static void record(std::vector<std::byte>& out, const std::vector<std::byte>& header,
                     std::span<const std::byte> data) {
    put(out, u32(static_cast<std::uint32_t>(header.size())));
    put(out, header);
    put(out, u32(static_cast<std::uint32_t>(data.size())));
    put(out, data);
  }
  static void connection_record(std::vector<std::byte>& out, const Connection& c) {
    std::vector<std::byte> header, data;
    field(header, "op", u8(0x07));
    field(header, "conn", u32(c.id));
    field(header, "topic", text(c.topic));
    field(data, "topic", text(c.topic));
    field(data, "type", text(c.type));
    field(data, "md5sum", text(c.md5sum));
    field(data, "message_definition", text(c.definition));
    if (!c.callerid.empty()) field(data, "callerid", text(c.callerid));
    if (c.latching) field(data, "latching", text("1"));
    record(out, header, data);
  }
  std::vector<std::byte> bag_header_record() const {
    std::vector<std::byte> header, out;
    field(header, "op", u8(0x03));
    field(header, "index_pos", u64(index_pos_));
    field(header, "conn_count", u32(closed_ ? static_cast<std::uint32_t>(connections_.size()) : 0));
    field(header, "chunk_count",
          u32(closed_ ? static_cast<std::uint32_t>(chunk_infos_.size()) : 0));
    // rosbag pads the bag header record to 4096 B so it can be rewritten in place.
    const std::size_t padding = 4096 - 8 - header.size();
    record(out, header, std::vector<std::byte>(padding, std::byte{' '}));
    return out;
  }

  std::vector<std::byte> compress(const std::vector<std::byte>& in, std::string& name) const {
    switch (options_.compression) {
      case Compression::kNone:
        name = "none";
        return in;
      case Compression::kBz2: {
        name = "bz2";
        std::vector<std::byte> out(in.size() + in.size() / 100 + 600);
        auto len = static_cast<unsigned int>(out.size());
        if (BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(out.data()), &len,
                                     const_cast<char*>(reinterpret_cast<const char*>(in.data())),
                                     static_cast<unsigned int>(in.size()), 9, 0, 0) != BZ_OK) {
          throw std::runtime_error("bz2 compression failed");
        }
        out.resize(len);
        return out;
      }
      case Compression::kLz4: {
        name = "lz4";
        std::vector<std::byte> out(LZ4F_compressFrameBound(in.size(), nullptr));
        const std::size_t len =
            LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
        if (LZ4F_isError(len)) throw std::runtime_error("lz4 compression failed");
        out.resize(len);
        return out;
      }
    }
    return in;
  }

  void close_chunk() {
    if (in_chunk_.empty()) return;
    ChunkInfo ci{bytes_.size(), chunk_start_, chunk_end_, {}};
    std::string name;
    const std::vector<std::byte> data = compress(chunk_, name);
    std::vector<std::byte> header;
    field(header, "op", u8(0x05));
    field(header, "compression", text(name));
    field(header, "size", u32(static_cast<std::uint32_t>(chunk_.size())));
    record(bytes_, header, data);
    for (const auto& [conn, entries] : in_chunk_) {
      std::vector<std::byte> ih, id;
      field(ih, "op", u8(0x04));
      field(ih, "ver", u32(1));
      field(ih, "conn", u32(conn));
      field(ih, "count", u32(static_cast<std::uint32_t>(entries.size())));
      for (const Entry& e : entries) {
        put(id, time(e.time_ns));
        put(id, u32(e.offset));
      }
      record(bytes_, ih, id);
      ci.counts[conn] = static_cast<std::uint32_t>(entries.size());
    }
    chunk_infos_.push_back(std::move(ci));
    chunk_.clear();
    in_chunk_.clear();
    chunk_messages_ = 0;
    chunk_end_ = 0;
  }

  Options options_;
  std::vector<std::byte> bytes_;
  std::size_t header_offset_ = 0;
  std::uint64_t index_pos_ = 0;
  bool closed_ = false;
  std::vector<Connection> connections_;
  std::vector<std::byte> chunk_;
  std::map<std::uint32_t, std::vector<Entry>> in_chunk_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0, chunk_messages_ = 0;
  std::vector<ChunkInfo> chunk_infos_;
};

}  // namespace posed::test
