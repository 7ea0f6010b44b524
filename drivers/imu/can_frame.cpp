#include "drivers/imu/can_frame.hpp"

#include <linux/can.h>

#include <cstring>

namespace posed::drivers::can {

bool is_valid_fd_len(std::size_t len) {
  return len <= 8 || len == 12 || len == 16 || len == 20 || len == 24 || len == 32 || len == 48 ||
         len == 64;
}

std::size_t to_kernel_bytes(const CanFrame& frame, std::span<std::uint8_t> out) {
  canid_t id = frame.id & (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  if (frame.extended) id |= CAN_EFF_FLAG;
  if (frame.remote) id |= CAN_RTR_FLAG;
  if (frame.error) id = (frame.id & CAN_ERR_MASK) | CAN_ERR_FLAG;
  if (frame.fd) {
    if (out.size() < kCanFdMtu || !is_valid_fd_len(frame.len)) return 0;
    canfd_frame k{};
    k.can_id = id;
    k.len = frame.len;
    k.flags = frame.fd_flags;
    std::memcpy(k.data, frame.data.data(), frame.len);
    std::memcpy(out.data(), &k, sizeof k);
    return sizeof k;
  }
  if (out.size() < kCanMtu || frame.len > 8) return 0;
  can_frame k{};
  k.can_id = id;
  k.len = frame.len;
  std::memcpy(k.data, frame.data.data(), frame.remote ? 0 : frame.len);
  std::memcpy(out.data(), &k, sizeof k);
  return sizeof k;
}

bool from_kernel_bytes(std::span<const std::uint8_t> bytes, CanFrame& frame) {
  static_assert(sizeof(can_frame) == kCanMtu && sizeof(canfd_frame) == kCanFdMtu);
  canfd_frame k{};
  if (bytes.size() != kCanMtu && bytes.size() != kCanFdMtu) return false;
  std::memcpy(&k, bytes.data(), bytes.size());
  frame = CanFrame{};
  frame.fd = bytes.size() == kCanFdMtu;
  frame.len = k.len;
  if (frame.fd ? !is_valid_fd_len(frame.len) : frame.len > 8) return false;
  frame.error = (k.can_id & CAN_ERR_FLAG) != 0;
  frame.extended = (k.can_id & CAN_EFF_FLAG) != 0;
  frame.remote = (k.can_id & CAN_RTR_FLAG) != 0;
  frame.id = frame.error      ? (k.can_id & CAN_ERR_MASK)
             : frame.extended ? (k.can_id & CAN_EFF_MASK)
                              : (k.can_id & CAN_SFF_MASK);
  if (frame.fd) frame.fd_flags = k.flags;
  if (!frame.remote) std::memcpy(frame.data.data(), k.data, frame.len);
  return true;
}

}  // namespace posed::drivers::can
