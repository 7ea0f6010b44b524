#include "drivers/recording/mapped_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

namespace posed::drivers::recording {

MappedFile::MappedFile(MappedFile&& o) noexcept
    : data_(std::exchange(o.data_, nullptr)),
      size_(std::exchange(o.size_, 0)),
      path_(std::move(o.path_)) {}

MappedFile& MappedFile::operator=(MappedFile&& o) noexcept {
  if (this != &o) {
    close();
    data_ = std::exchange(o.data_, nullptr);
    size_ = std::exchange(o.size_, 0);
    path_ = std::move(o.path_);
  }
  return *this;
}

MappedFile::~MappedFile() { close(); }

void MappedFile::close() {
  if (data_ != nullptr && size_ > 0) {
    ::munmap(const_cast<std::byte*>(data_), size_);
  }
  data_ = nullptr;
  size_ = 0;
}

bool MappedFile::open(const std::string& path, std::string& error, std::string_view kind) {
  const std::string what = std::string(kind) + " " + path;
  close();
  path_ = path;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error = what + ": cannot open: " + std::strerror(errno);
    return false;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    error = what + ": cannot stat: " + std::strerror(errno);
    ::close(fd);
    return false;
  }
  size_ = static_cast<std::size_t>(st.st_size);
  if (size_ == 0) {  // mmap refuses length 0; the readers report an empty file as truncated
    ::close(fd);
    return true;
  }
  void* p = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) {
    error = what + ": cannot map: " + std::strerror(errno);
    size_ = 0;
    return false;
  }
  ::madvise(p, size_, MADV_SEQUENTIAL);
  // No 2 MB page-table mappings of the page cache's large folios: releasing part of one unmaps
  // all of it, and the reader maps it whole again with its next record (a replay's readers held
  // 8 MB of a file between two of them, 4.6 MB without).
  ::madvise(p, size_, MADV_NOHUGEPAGE);
  data_ = static_cast<const std::byte*>(p);
  return true;
}

std::size_t MappedFile::release(std::size_t begin, std::size_t end) {
  static const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t first = (begin + page - 1) / page * page;
  end = std::min(end, size_) / page * page;
  if (data_ == nullptr || end <= first) return begin;
  // MAP_PRIVATE and never written: dropped pages read back from the file unchanged.
  ::madvise(const_cast<std::byte*>(data_) + first, end - first, MADV_DONTNEED);
  return end;
}

}  // namespace posed::drivers::recording
