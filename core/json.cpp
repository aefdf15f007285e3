#include "core/json.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"

namespace naris {

Json significant(double x, int digits) {
  if (!std::isfinite(x)) return nullptr;
  return std::stod(fmt::format("{:.{}g}", x, digits));
}

Json read_json_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) fail("{}: cannot read", path.string());
  try {
    return Json::parse(in);
  } catch (const std::exception& e) {
    fail("{}: not a JSON file ({})", path.string(), e.what());
  }
}

void write_json_file(const std::filesystem::path& path, const Json& value) {
  write_text_file(path, value.dump(2) + "\n");
}

}  // namespace naris
