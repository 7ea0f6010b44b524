#include "drivers/recording/map_files.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace posed::drivers::recording {

bool write_atomically(const std::string& path, std::string& error,
                      const std::function<bool(std::FILE*)>& body) {
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) {
    error = "cannot create " + tmp + ": " + std::strerror(errno);
    return false;
  }
  const bool wrote = body(f);
  const int saved_errno = errno;
  if (std::fclose(f) != 0 || !wrote) {
    error = "writing " + tmp + " failed: " + std::strerror(wrote ? errno : saved_errno);
    std::remove(tmp.c_str());
    return false;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    error = "cannot rename " + tmp + " to " + path + ": " + std::strerror(errno);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

std::string tum_line(std::int64_t stamp_ns, const Eigen::Vector3d& p_m,
                     const Eigen::Quaterniond& q) {
  char buf[256];
  const std::int64_t s = stamp_ns / 1'000'000'000;
  std::int64_t frac = stamp_ns % 1'000'000'000;
  const char* sign = stamp_ns < 0 && s == 0 ? "-" : "";
  if (frac < 0) frac = -frac;
  std::snprintf(buf, sizeof buf, "%s%lld.%09lld %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", sign,
                static_cast<long long>(s), static_cast<long long>(frac), p_m.x(), p_m.y(), p_m.z(),
                q.x(), q.y(), q.z(), q.w());
  return buf;
}

bool write_pcd(const std::string& path, const std::vector<Eigen::Vector3f>& points_m,
               std::string& error) {
  return write_atomically(path, error, [&](std::FILE* f) {
    const std::size_t n = points_m.size();
    if (std::fprintf(f,
                     "# .PCD v0.7 - Point Cloud Data file format\n"
                     "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                     "WIDTH %zu\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %zu\nDATA binary\n",
                     n, n) < 0) {
      return false;
    }
    // Eigen::Vector3f is three packed floats: the binary body is the vector's memory.
    static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
    return n == 0 || std::fwrite(points_m.data(), sizeof(Eigen::Vector3f), n, f) == n;
  });
}

bool write_tum(const std::string& path, const std::vector<StampedTransform>& poses,
               std::string& error) {
  return write_atomically(path, error, [&](std::FILE* f) {
    if (std::fputs("# posed keyframes: stamp[s] tx ty tz[m] qx qy qz qw (base_link in map)\n", f) <
        0) {
      return false;
    }
    for (const StampedTransform& p : poses) {
      const std::string line =
          tum_line(p.stamp.ns, p.T.translation(), Eigen::Quaterniond(p.T.linear()).normalized());
      if (std::fputs(line.c_str(), f) < 0) return false;
    }
    return true;
  });
}

}  // namespace posed::drivers::recording
