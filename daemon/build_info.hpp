#pragma once
#include <string_view>

namespace posed {
/// "posed 0.1.0" — shown by --version and in the DDS status.
std::string_view version_string();
}  // namespace posed
