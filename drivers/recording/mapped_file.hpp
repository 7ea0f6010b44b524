#pragma once
// A file mapped read-only into memory, so the recording readers (MCAP, ROS 1 bags, pcap) parse
// it in place without copies and the kernel pages it in as they walk it front to back. Owns the
// mapping; movable, not copyable.

#include <cstddef>
#include <span>
#include <string>
#include <string_view>

namespace posed::drivers::recording {

class MappedFile {
 public:
  MappedFile() = default;
  MappedFile(MappedFile&& o) noexcept;
  MappedFile& operator=(MappedFile&& o) noexcept;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile();

  /// Maps `path` (an empty file maps to no bytes). On failure returns false and sets `error`
  /// ("KIND PATH: cannot open|stat|map: reason"), `kind` naming the format for the user.
  bool open(const std::string& path, std::string& error, std::string_view kind = "file");
  /// Unmaps; bytes() is empty afterwards.
  void close();
  /// Drops the pages wholly inside bytes [begin, end) from this process's resident memory (a
  /// reader walking front to back is done with them): without it a long replay's RSS grows by
  /// the recording's size. Their bytes stay readable: the kernel pages them in again if touched.
  /// Returns where the released pages end (`end` down to a page, at least `begin`): the next
  /// release starts there, so no page is left between two (a reader releasing after every
  /// image-sized record kept one page in 16 of the file, 65 MB over a minute of replay).
  std::size_t release(std::size_t begin, std::size_t end);
  std::span<const std::byte> bytes() const { return {data_, size_}; }
  const std::string& path() const { return path_; }

 private:
  const std::byte* data_ = nullptr;
  std::size_t size_ = 0;
  std::string path_;
};

}  // namespace posed::drivers::recording
