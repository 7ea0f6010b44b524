#include "drivers/recording/ros2_messages.hpp"

#include <cstring>

namespace posed::drivers::recording::ros2 {
namespace {

/// Appends CDR fields; alignment is relative to the first byte after the encapsulation header.
class CdrOut {
 public:
  explicit CdrOut(std::vector<std::byte>& out) : out_(out) {
    out_.clear();
    const std::uint8_t hdr[4] = {0x00, 0x01, 0x00, 0x00};  // CDR_LE, options 0
    put(hdr, 4);
  }
  void align(std::size_t n) {
    while ((out_.size() - 4) % n != 0) out_.push_back(std::byte{0});
  }
  void i32(std::int32_t v) {
    align(4);
    put(&v, 4);
  }
  void u32(std::uint32_t v) {
    align(4);
    put(&v, 4);
  }
  void f64(double v) {
    align(8);
    put(&v, 8);
  }
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    put(s.data(), s.size());
    out_.push_back(std::byte{0});
  }
  void put(const void* p, std::size_t n) {
    const auto* b = static_cast<const std::byte*>(p);
    out_.insert(out_.end(), b, b + n);
  }

 private:
  std::vector<std::byte>& out_;
};

class CdrIn {
 public:
  explicit CdrIn(std::span<const std::byte> b) : b_(b) {
    // little-endian CDR (00 01) only: what ROS 2 on x86/ARM writes
    ok_ = b.size() >= 4 && b[0] == std::byte{0} && b[1] == std::byte{1};
    pos_ = 4;
  }
  void align(std::size_t n) { pos_ += (n - (pos_ - 4) % n) % n; }
  template <class T>
  T get() {
    align(sizeof(T));
    T v{};
    if (!ok_ || pos_ + sizeof(T) > b_.size()) {
      ok_ = false;
      return v;
    }
    std::memcpy(&v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string str() {
    const auto n = get<std::uint32_t>();
    if (!ok_ || n == 0 || n > b_.size() - pos_) {
      ok_ = false;
      return {};
    }
    std::string s(reinterpret_cast<const char*>(b_.data() + pos_), n - 1);
    pos_ += n;
    return s;
  }
  bool ok() const { return ok_; }

 private:
  std::span<const std::byte> b_;
  std::size_t pos_ = 0;
  bool ok_ = false;
};

void header(CdrOut& o, const StampedPose& p) {
  // builtin_interfaces/Time: floor division so negative stamps keep 0 <= nanosec < 1e9
  std::int64_t sec = p.stamp.ns / 1'000'000'000;
  std::int64_t nsec = p.stamp.ns % 1'000'000'000;
  if (nsec < 0) {
    nsec += 1'000'000'000;
    --sec;
  }
  o.i32(static_cast<std::int32_t>(sec));
  o.u32(static_cast<std::uint32_t>(nsec));
  o.str(p.frame_id);
}

void pose(CdrOut& o, const StampedPose& p) {
  for (double v : p.p_xyz_m) o.f64(v);
  for (double v : p.q_xyzw) o.f64(v);
}

bool read_header_and_pose(CdrIn& in, StampedPose& out, std::string* child) {
  const auto sec = in.get<std::int32_t>();
  const auto nsec = in.get<std::uint32_t>();
  out.stamp = WallTime::from_ns(static_cast<std::int64_t>(sec) * 1'000'000'000 + nsec);
  out.frame_id = in.str();
  if (child != nullptr) *child = in.str();
  for (double& v : out.p_xyz_m) v = in.get<double>();
  for (double& v : out.q_xyzw) v = in.get<double>();
  return in.ok();
}

}  // namespace

void encode_pose_stamped(const StampedPose& p, std::vector<std::byte>& out) {
  CdrOut o(out);
  header(o, p);
  pose(o, p);
}

void encode_odometry(const StampedPose& p, std::string_view child_frame_id,
                     const std::array<double, 3>& v_mps, const std::array<double, 3>& w_radps,
                     std::vector<std::byte>& out) {
  CdrOut o(out);
  header(o, p);
  o.str(child_frame_id);
  pose(o, p);
  for (int i = 0; i < 36; ++i) o.f64(0.0);  // fixed-size array: no length prefix
  for (double v : v_mps) o.f64(v);
  for (double v : w_radps) o.f64(v);
  for (int i = 0; i < 36; ++i) o.f64(0.0);
}

bool decode_pose_stamped(std::span<const std::byte> cdr, StampedPose& out) {
  CdrIn in(cdr);
  return read_header_and_pose(in, out, nullptr);
}

bool decode_odometry(std::span<const std::byte> cdr, StampedPose& out,
                     std::string* child_frame_id) {
  CdrIn in(cdr);
  std::string child;
  if (!read_header_and_pose(in, out, &child)) return false;
  for (int i = 0; i < 36 + 6 + 36; ++i) in.get<double>();
  if (child_frame_id != nullptr) *child_frame_id = child;
  return in.ok();
}

}  // namespace posed::drivers::recording::ros2
