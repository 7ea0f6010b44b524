#include "daemon/build_info.hpp"

namespace posed {
std::string_view version_string() { return POSED_VERSION_STRING; }
}  // namespace posed
