#pragma once
// The RealSense D4xx "HW monitor" command protocol, spoken over the camera's vendor-specific USB
// interface (bulk OUT, then one bulk IN reply). Pure packet building and checking; the USB I/O
// is UsbTransport's.
//
// Command (librealsense src/hw-monitor.cpp, hw_monitor::fill_usb_buffer; little-endian):
//   u16 length   bytes after this 4-byte preamble (= 20 + data bytes)
//   u16 magic    0xCDAB (IVCAM_MONITOR_MAGIC_NUMBER, src/hw-monitor.h)
//   u32 opcode
//   u32 param1 .. param4
//   data[]       at most 1000 bytes (HW_MONITOR_BUFFER_SIZE)
// Reply: u32 opcode echoed, then the command's data (hw_monitor::send checks the echo; a
// mismatching value is the firmware's negative hwmon_response error code). Replies are at most
// 1024 bytes (command_transfer_usb's DEFAULT_BUFFER_SIZE, src/platform/command-transfer.h).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace posed::drivers::camera {

inline constexpr std::uint16_t kHwmMagic = 0xCDAB;
/// GETINTCAL: read an internal calibration table, param1 = table id (src/ds/ds-private.h fw_cmd)
inline constexpr std::uint32_t kHwmOpGetIntCal = 0x15;
/// preamble (length, magic) + opcode + four params [B]
inline constexpr std::size_t kHwmCommandHeaderBytes = 24;
/// command data limit (HW_MONITOR_BUFFER_SIZE) [B]
inline constexpr std::size_t kHwmMaxDataBytes = 1000;
/// reply buffer (command_transfer_usb DEFAULT_BUFFER_SIZE) [B]
inline constexpr std::size_t kHwmMaxReplyBytes = 1024;

/// Builds one command packet. `data` beyond kHwmMaxDataBytes is cut (a caller error).
std::vector<std::byte> build_hwm_command(std::uint32_t opcode, std::uint32_t param1 = 0,
                                         std::uint32_t param2 = 0, std::uint32_t param3 = 0,
                                         std::uint32_t param4 = 0,
                                         std::span<const std::byte> data = {});

/// A command packet taken apart (for fakes and logs).
struct HwmCommand {
  std::uint32_t opcode = 0;
  std::uint32_t params[4] = {0, 0, 0, 0};
  std::span<const std::byte> data;
};
/// false when `packet` is shorter than the header, has the wrong magic or a length field that
/// disagrees with its size.
bool parse_hwm_command(std::span<const std::byte> packet, HwmCommand& out);

enum class HwmStatus : std::uint8_t {
  kOk,
  kTooShort,     ///< fewer than 4 bytes: no opcode echo
  kWrongOpcode,  ///< the echo is another opcode or a firmware error code
};
std::string_view to_string(HwmStatus s);

/// Checks a reply to `opcode`; on kOk `payload` is the data after the echo. `echoed` is the
/// first u32 as received (a negative value is a firmware error code).
HwmStatus parse_hwm_reply(std::span<const std::byte> reply, std::uint32_t opcode,
                          std::span<const std::byte>& payload, std::int32_t& echoed);

}  // namespace posed::drivers::camera
