#pragma once
// One CAN / CAN FD frame as a plain struct, and its exact byte form. The byte form is the kernel's
// struct can_frame (16 B) or struct canfd_frame (72 B), as read() from a CAN_RAW socket returns
// it, so live SocketCAN and replayed candump logs hand identical RawChunks to the decoders.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace posed::drivers::can {

struct CanFrame {
  /// arbitration ID without flag bits: 11-bit (standard) or 29-bit (extended)
  std::uint32_t id = 0;
  /// 29-bit identifier
  bool extended = false;
  /// remote transmission request (no data; `len` is the requested length)
  bool remote = false;
  /// error frame (id holds the CAN_ERR_* class bits, data the details)
  bool error = false;
  /// CAN FD frame (up to 64 data bytes)
  bool fd = false;
  /// CAN FD flags (CANFD_BRS = 0x01, CANFD_ESI = 0x02)
  std::uint8_t fd_flags = 0;
  /// data length [B]: 0..8 classic, 0..64 FD
  std::uint8_t len = 0;
  std::array<std::uint8_t, 64> data{};
};

/// Kernel wire sizes [B].
inline constexpr std::size_t kCanMtu = 16;
inline constexpr std::size_t kCanFdMtu = 72;

/// Writes the kernel struct form of `frame` into `out`; returns bytes written (16 or 72) or 0 if
/// `out` is too small or the frame invalid (len too large for its kind).
std::size_t to_kernel_bytes(const CanFrame& frame, std::span<std::uint8_t> out);
/// Parses a kernel struct can_frame/canfd_frame (by its size); false on any other size or an
/// invalid length field.
bool from_kernel_bytes(std::span<const std::uint8_t> bytes, CanFrame& frame);

/// Valid CAN FD data lengths are 0..8, 12, 16, 20, 24, 32, 48, 64.
bool is_valid_fd_len(std::size_t len);

}  // namespace posed::drivers::can
