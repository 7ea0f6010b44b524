#include "drivers/velodyne/position_packet.hpp"

#include <array>
#include <cstring>

#include "drivers/velodyne/packet_format.hpp"

namespace posed::drivers::velodyne {
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

/// Splits the next comma-separated field off `s`.
std::string_view next_field(std::string_view& s) {
  const auto comma = s.find(',');
  std::string_view f = s.substr(0, comma);
  s = comma == std::string_view::npos ? std::string_view{} : s.substr(comma + 1);
  return f;
}

bool parse_uint(std::string_view s, std::uint32_t& v) {
  if (s.empty() || s.size() > 9) return false;
  v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<std::uint32_t>(c - '0');
  }
  return true;
}

/// "ddmm.mmmm" / "dddmm.mmmm" → degrees; empty → 0.
bool parse_coordinate(std::string_view s, std::string_view hemisphere, double& deg) {
  deg = 0.0;
  if (s.empty()) return true;
  const auto dot = s.find('.');
  const std::size_t int_len = dot == std::string_view::npos ? s.size() : dot;
  if (int_len < 3) return false;
  std::uint32_t whole_deg = 0, whole_min = 0;
  if (!parse_uint(s.substr(0, int_len - 2), whole_deg) ||
      !parse_uint(s.substr(int_len - 2, 2), whole_min)) {
    return false;
  }
  double frac = 0.0, scale = 0.1;
  if (dot != std::string_view::npos) {
    for (char c : s.substr(dot + 1)) {
      if (c < '0' || c > '9') return false;
      frac += (c - '0') * scale;
      scale *= 0.1;
    }
  }
  deg = whole_deg + (whole_min + frac) / 60.0;
  if (hemisphere == "S" || hemisphere == "W") deg = -deg;
  return hemisphere.empty() || hemisphere == "N" || hemisphere == "S" || hemisphere == "E" ||
         hemisphere == "W";
}

/// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
std::int64_t days_from_civil(std::int64_t y, std::uint32_t m, std::uint32_t d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<std::uint32_t>(y - era * 400);
  const std::uint32_t doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const std::uint32_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

}  // namespace

std::string_view to_string(PpsStatus s) {
  switch (s) {
    case PpsStatus::kAbsent:
      return "absent";
    case PpsStatus::kSynchronizing:
      return "synchronizing";
    case PpsStatus::kLocked:
      return "locked";
    case PpsStatus::kError:
      return "error";
  }
  return "unknown";
}

std::string_view to_string(PositionStatus s) {
  switch (s) {
    case PositionStatus::kOk:
      return "ok";
    case PositionStatus::kNoNmea:
      return "no_nmea";
    case PositionStatus::kWrongSize:
      return "wrong_size";
    case PositionStatus::kBadTimestamp:
      return "bad_timestamp";
    case PositionStatus::kBadNmea:
      return "bad_nmea";
  }
  return "unknown";
}

bool parse_gprmc(std::string_view s, GprmcFix& out) noexcept {
  // Trim line ending and NUL padding.
  while (!s.empty() && (s.back() == '\r' || s.back() == '\n' || s.back() == '\0'))
    s.remove_suffix(1);
  if (s.size() < 7 || s[0] != '$') return false;
  if (s.substr(3, 4) != "RMC,") return false;  // $GPRMC, $GNRMC, ...
  const auto star = s.rfind('*');
  std::string_view body = s.substr(1, star == std::string_view::npos ? s.npos : star - 1);
  if (star != std::string_view::npos) {
    if (s.size() < star + 3) return false;
    const int hi = hex_digit(s[star + 1]), lo = hex_digit(s[star + 2]);
    if (hi < 0 || lo < 0) return false;
    std::uint8_t sum = 0;
    for (char c : body) sum = static_cast<std::uint8_t>(sum ^ static_cast<std::uint8_t>(c));
    if (sum != hi * 16 + lo) return false;
  }
  next_field(body);  // talker + "RMC"
  const std::string_view time = next_field(body);
  const std::string_view status = next_field(body);
  const std::string_view lat = next_field(body);
  const std::string_view lat_h = next_field(body);
  const std::string_view lon = next_field(body);
  const std::string_view lon_h = next_field(body);
  next_field(body);  // speed over ground [kn]
  next_field(body);  // course [deg]
  const std::string_view date = next_field(body);

  GprmcFix fix;
  if (time.size() < 6 || date.size() != 6) return false;
  if (!parse_uint(time.substr(0, 2), fix.hour) || !parse_uint(time.substr(2, 2), fix.minute) ||
      !parse_uint(time.substr(4, 2), fix.second)) {
    return false;
  }
  if (time.size() > 6) {
    if (time[6] != '.') return false;
    std::uint32_t scale = 100'000;
    for (char c : time.substr(7)) {
      if (c < '0' || c > '9') return false;
      fix.microsecond += static_cast<std::uint32_t>(c - '0') * scale;
      scale /= 10;
    }
  }
  std::uint32_t yy = 0;
  if (!parse_uint(date.substr(0, 2), fix.day) || !parse_uint(date.substr(2, 2), fix.month) ||
      !parse_uint(date.substr(4, 2), yy)) {
    return false;
  }
  // NMEA carries a two-digit year; GPS receivers of these sensors date from 1980 on.
  fix.year = yy < 80 ? 2000 + yy : 1900 + yy;
  if (fix.hour > 23 || fix.minute > 59 || fix.second > 60 || fix.month < 1 || fix.month > 12 ||
      fix.day < 1 || fix.day > 31) {
    return false;
  }
  if (status != "A" && status != "V") return false;
  fix.valid = status == "A";
  if (!parse_coordinate(lat, lat_h, fix.latitude_deg) ||
      !parse_coordinate(lon, lon_h, fix.longitude_deg)) {
    return false;
  }
  out = fix;
  return true;
}

PositionStatus parse_position_packet(std::span<const std::byte> payload,
                                     PositionPacket& out) noexcept {
  if (payload.size() != kPositionPacketBytes) return PositionStatus::kWrongSize;
  out = PositionPacket{};
  out.device_time_us = read_u32_le(payload.data() + kPositionTimestampOffset);
  if (out.device_time_us >= kUsPerHour) return PositionStatus::kBadTimestamp;
  const auto pps = static_cast<std::uint8_t>(payload[kPpsOffset]);
  out.pps = pps <= 3 ? static_cast<PpsStatus>(pps) : PpsStatus::kError;
  const char* nmea = reinterpret_cast<const char*>(payload.data() + kNmeaOffset);
  const std::size_t len = ::strnlen(nmea, kNmeaBytes);
  const std::string_view sentence(nmea, len);
  if (sentence.size() < 7 || sentence.substr(3, 4) != "RMC,") return PositionStatus::kNoNmea;
  GprmcFix fix;
  if (!parse_gprmc(sentence, fix)) return PositionStatus::kBadNmea;
  out.gprmc = fix;
  return PositionStatus::kOk;
}

std::optional<WallTime> top_of_hour(const GprmcFix& fix, std::uint32_t device_time_us) noexcept {
  if (!fix.valid || fix.month < 1 || fix.month > 12 || fix.day < 1 || fix.day > 31) {
    return std::nullopt;
  }
  const std::int64_t days = days_from_civil(fix.year, fix.month, fix.day);
  std::int64_t hour_start_s = days * 86'400 + static_cast<std::int64_t>(fix.hour) * 3'600;
  const std::int64_t fix_us_in_hour =
      (static_cast<std::int64_t>(fix.minute) * 60 + fix.second) * 1'000'000 + fix.microsecond;
  const std::int64_t diff_us = static_cast<std::int64_t>(device_time_us) - fix_us_in_hour;
  constexpr std::int64_t kHalfHourUs = 1'800'000'000;
  if (diff_us < -kHalfHourUs) hour_start_s += 3'600;  // counter wrapped after the fix
  if (diff_us > kHalfHourUs) hour_start_s -= 3'600;   // fix is from the next hour already
  return WallTime::from_ns(hour_start_s * 1'000'000'000);
}

}  // namespace posed::drivers::velodyne
