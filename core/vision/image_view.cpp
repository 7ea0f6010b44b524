#include "core/vision/image_view.hpp"

#include <cstddef>

namespace posed::vision {

int cv_type(PixelFormat format) {
  switch (format) {
    case PixelFormat::kMono8:
      return CV_8UC1;
    case PixelFormat::kMono16:
      return CV_16UC1;
    case PixelFormat::kBgr8:
    case PixelFormat::kRgb8:
      return CV_8UC3;
    case PixelFormat::kDepth16:
      return -1;
  }
  return -1;
}

cv::Mat view(const Image& image) {
  const int type = cv_type(image.format);
  if (type < 0 || !image.pixels.valid() || image.width == 0 || image.height == 0) return {};
  const std::size_t row_bytes = static_cast<std::size_t>(image.width) *
                                static_cast<std::size_t>(bytes_per_pixel(image.format));
  const auto bytes = image.pixels.bytes();
  if (image.stride < row_bytes ||
      bytes.size() < static_cast<std::size_t>(image.stride) * image.height) {
    return {};
  }
  return cv::Mat(static_cast<int>(image.height), static_cast<int>(image.width), type,
                 static_cast<void*>(bytes.data()), static_cast<std::size_t>(image.stride));
}

}  // namespace posed::vision
