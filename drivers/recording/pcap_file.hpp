#pragma once
// A capture file mapped read-only into memory, so the pure PcapParser can walk it without
// copies. Owns the mapping; movable, not copyable.

#include <cstddef>
#include <span>
#include <string>

namespace posed::drivers::recording {

class PcapFile {
 public:
  PcapFile() = default;
  PcapFile(PcapFile&& o) noexcept;
  PcapFile& operator=(PcapFile&& o) noexcept;
  PcapFile(const PcapFile&) = delete;
  PcapFile& operator=(const PcapFile&) = delete;
  ~PcapFile();

  /// Maps `path`. On failure returns false and sets `error` ("pcap FILE: reason").
  bool open(const std::string& path, std::string& error);
  std::span<const std::byte> bytes() const { return {data_, size_}; }
  const std::string& path() const { return path_; }

 private:
  void close();
  const std::byte* data_ = nullptr;
  std::size_t size_ = 0;
  std::string path_;
};

}  // namespace posed::drivers::recording
