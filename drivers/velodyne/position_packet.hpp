#pragma once
// Position packets (port 8308): the sensor's view of time. Layout from the VLP-32C user manual,
// section 9.4 "Position Packet Format" (512-byte UDP payload):
//   187 reserved · 187..197 temperatures and ADC calibration status · 198 u32 LE timestamp
//   [µs past the top of the hour] · 202 PPS status (0 absent, 1 synchronizing, 2 locked,
//   3 error) · 203..205 thermal status · 206 NMEA sentence ($GPRMC or $GPGGA, 128 B, NUL padded)
// The HDL-32E sends the same 512 bytes with the timestamp at 198 and the NMEA at 206; its byte
// 202 is unused (reads 0, "absent").
//
// The GPRMC sentence gives the UTC date and time of the last PPS; together with the packet's µs
// past the hour that fixes the absolute time of every data packet's µs-past-the-hour stamp.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "core/time.hpp"

namespace posed::drivers::velodyne {

inline constexpr std::size_t kPositionPacketBytes = 512;
inline constexpr std::size_t kPositionTimestampOffset = 198;
inline constexpr std::size_t kPpsOffset = 202;
inline constexpr std::size_t kNmeaOffset = 206;
inline constexpr std::size_t kNmeaBytes = 128;
/// the period of the µs-past-the-hour stamps [µs]
inline constexpr std::uint32_t kUsPerHour = 3'600'000'000u;

enum class PpsStatus : std::uint8_t {
  kAbsent = 0,
  kSynchronizing = 1,
  kLocked = 2,
  kError = 3,
};

std::string_view to_string(PpsStatus s);

/// The fields of a $GPRMC sentence that matter for time.
struct GprmcFix {
  /// 'A' (valid) in the status field; 'V' means the receiver has no fix
  bool valid = false;
  /// UTC time of day of the fix [h, min, s] and its fractional part [µs]
  std::uint32_t hour = 0, minute = 0, second = 0, microsecond = 0;
  /// UTC date (four-digit year)
  std::uint32_t day = 0, month = 0, year = 0;
  /// latitude (north positive) and longitude (east positive) [deg]; 0 when empty
  double latitude_deg = 0.0, longitude_deg = 0.0;
};

enum class PositionStatus : std::uint8_t {
  kOk,            ///< timestamp, PPS status and a GPRMC sentence
  kNoNmea,        ///< timestamp and PPS status, but no (or a non-RMC) sentence
  kWrongSize,     ///< not a 512-byte payload
  kBadTimestamp,  ///< µs past the hour ≥ 3600 s
  kBadNmea,       ///< a $GPRMC sentence that fails its checksum or does not parse
};

std::string_view to_string(PositionStatus s);

struct PositionPacket {
  /// the sensor's clock when it sent the packet [µs past the top of the hour]
  std::uint32_t device_time_us = 0;
  PpsStatus pps = PpsStatus::kAbsent;
  /// present when status is kOk
  std::optional<GprmcFix> gprmc;
};

/// Parses a position packet payload (pure, never throws).
PositionStatus parse_position_packet(std::span<const std::byte> payload,
                                     PositionPacket& out) noexcept;

/// Parses one NMEA $GPRMC (or $GNRMC) sentence, checking the "*hh" checksum when present.
bool parse_gprmc(std::string_view sentence, GprmcFix& out) noexcept;

/// UTC of the top of the hour that `device_time_us` counts from, using the fix's date and hour.
/// The sentence describes the last PPS, so near the hour boundary the µs counter may already have
/// wrapped (or not yet): the hour is chosen to put the counter within 30 min of the fix time.
/// nullopt for an invalid fix or date.
std::optional<WallTime> top_of_hour(const GprmcFix& fix, std::uint32_t device_time_us) noexcept;

/// Absolute UTC time of a device stamp in µs past the hour, given the top of that hour.
constexpr WallTime absolute_time(WallTime top_of_hour, std::uint32_t device_time_us) {
  return top_of_hour + Duration::from_us(device_time_us);
}

}  // namespace posed::drivers::velodyne
