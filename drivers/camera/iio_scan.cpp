#include "drivers/camera/iio_scan.hpp"

#include <algorithm>
#include <charconv>

namespace posed::drivers::camera {
namespace {

bool take_number(std::string_view& s, std::uint32_t& v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc{} || r.ptr == s.data()) return false;
  s.remove_prefix(static_cast<std::size_t>(r.ptr - s.data()));
  return true;
}

bool take(std::string_view& s, std::string_view token) {
  if (s.substr(0, token.size()) != token) return false;
  s.remove_prefix(token.size());
  return true;
}

}  // namespace

bool parse_iio_scan_type(std::string_view s, IioScanType& out) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.remove_suffix(1);
  IioScanType t;
  if (take(s, "le:")) {
    t.big_endian = false;
  } else if (take(s, "be:")) {
    t.big_endian = true;
  } else {
    return false;
  }
  if (take(s, "s")) {
    t.is_signed = true;
  } else if (!take(s, "u")) {
    return false;
  }
  if (!take_number(s, t.realbits) || !take(s, "/") || !take_number(s, t.storagebits)) return false;
  if (take(s, "X") && !take_number(s, t.repeat)) return false;
  if (!take(s, ">>") || !take_number(s, t.shift) || !s.empty()) return false;
  const bool storage_ok =
      t.storagebits == 8 || t.storagebits == 16 || t.storagebits == 32 || t.storagebits == 64;
  // Each bound on its own: realbits + shift can wrap around 2^32. The kernel's repeat is a u8.
  if (!storage_ok || t.realbits == 0 || t.realbits > t.storagebits ||
      t.shift > t.storagebits - t.realbits || t.repeat == 0 || t.repeat > 255) {
    return false;
  }
  out = t;
  return true;
}

std::string to_string(const IioScanType& t) {
  std::string s = t.big_endian ? "be:" : "le:";
  s += t.is_signed ? 's' : 'u';
  s += std::to_string(t.realbits) + "/" + std::to_string(t.storagebits);
  if (t.repeat > 1) s += "X" + std::to_string(t.repeat);
  s += ">>" + std::to_string(t.shift);
  return s;
}

const IioScanElement* IioScanLayout::find(std::string_view name) const {
  for (const auto& e : elements) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

bool layout_iio_scan(std::vector<IioScanElement> elements, IioScanLayout& out, std::string& error) {
  if (elements.empty()) {
    error = "no enabled scan elements";
    return false;
  }
  std::sort(elements.begin(), elements.end(),
            [](const auto& a, const auto& b) { return a.index < b.index; });
  // 64-bit sums: a record is refused when it exceeds kMaxRecordBytes, never wrapped around.
  std::uint64_t bytes = 0, largest = 1;
  for (std::size_t i = 0; i < elements.size(); ++i) {
    if (i > 0 && elements[i].index == elements[i - 1].index) {
      error = "scan elements " + elements[i - 1].name + " and " + elements[i].name +
              " share index " + std::to_string(elements[i].index);
      return false;
    }
    const IioScanType& t = elements[i].type;
    const std::uint64_t size = t.storagebits / 8;
    if (size == 0 || t.realbits == 0 || t.realbits > t.storagebits || t.repeat == 0 ||
        t.shift > t.storagebits - t.realbits) {
      error = "scan element " + elements[i].name + " has an invalid type " + to_string(t);
      return false;
    }
    bytes = (bytes + size - 1) / size * size;  // natural alignment
    elements[i].offset = static_cast<std::uint32_t>(bytes);
    bytes += size * t.repeat;
    largest = std::max(largest, size);
    if (bytes > kMaxRecordBytes) {
      error = "scan elements up to " + elements[i].name + " need " + std::to_string(bytes) +
              " bytes per record, more than " + std::to_string(kMaxRecordBytes);
      return false;
    }
  }
  out.record_bytes = static_cast<std::uint32_t>((bytes + largest - 1) / largest * largest);
  out.elements = std::move(elements);
  return true;
}

std::string describe_iio_layout(std::string_view prefix, const IioScanLayout& layout) {
  std::string s(prefix);
  for (const auto& e : layout.elements) s += ";" + e.name + ":" + to_string(e.type);
  return s;
}

bool parse_iio_layout(std::string_view text, std::string_view prefix, IioScanLayout& out,
                      std::string& error) {
  if (text.substr(0, prefix.size()) != prefix) {
    error = "wire format '" + std::string(text) + "' is not " + std::string(prefix);
    return false;
  }
  text.remove_prefix(prefix.size());
  std::vector<IioScanElement> elements;
  while (!text.empty()) {
    if (text.front() != ';') {
      error = "wire format: expected ';' at '" + std::string(text) + "'";
      return false;
    }
    text.remove_prefix(1);
    const auto end = std::min(text.find(';'), text.size());
    const std::string_view item = text.substr(0, end);
    text.remove_prefix(end);
    const auto colon = item.find(':');
    IioScanElement e;
    if (colon == std::string_view::npos || colon == 0 ||
        !parse_iio_scan_type(item.substr(colon + 1), e.type)) {
      error = "wire format: bad scan element '" + std::string(item) + "'";
      return false;
    }
    e.name = std::string(item.substr(0, colon));
    e.index = static_cast<std::uint32_t>(elements.size());
    elements.push_back(std::move(e));
  }
  return layout_iio_scan(std::move(elements), out, error);
}

std::int64_t iio_element_value(const std::byte* record, const IioScanElement& e) {
  const std::uint32_t n = e.type.storagebits / 8;
  std::uint64_t raw = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto b = static_cast<std::uint64_t>(record[e.offset + i]);
    raw |= e.type.big_endian ? b << (8 * (n - 1 - i)) : b << (8 * i);
  }
  raw >>= e.type.shift;
  if (e.type.realbits < 64) {
    const std::uint64_t mask = (std::uint64_t{1} << e.type.realbits) - 1;
    raw &= mask;
    // The upper bits of a 16-bit HID field stored in 32 are the next field's bytes (the kernel
    // copies a u32 from the report): masking then extending the sign is what makes it a value.
    if (e.type.is_signed && (raw >> (e.type.realbits - 1)) != 0) raw |= ~mask;
  }
  return static_cast<std::int64_t>(raw);
}

}  // namespace posed::drivers::camera
