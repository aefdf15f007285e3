#include "core/json.h"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "core/atomic_file.h"

namespace naris {

Json significant(double x, int digits) {
  if (!std::isfinite(x)) return nullptr;
  return std::stod(fmt::format("{:.{}g}", x, digits));
}

void write_json_file(const std::filesystem::path& path, const Json& value) {
  write_text_file(path, value.dump(2) + "\n");
}

}  // namespace naris
