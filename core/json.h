#pragma once
// JSON result files (summary.json, mesh.json): nlohmann's ordered JSON, keys in the order
// written, numbers to the precision a result file states.
#include <filesystem>
#include <nlohmann/json.hpp>

namespace naris {

using Json = nlohmann::ordered_json;

// x to `digits` significant digits (not finite: null in the file).
Json significant(double x, int digits = 6);

// Reads a JSON file; throws naris::Error for a missing or malformed one.
Json read_json_file(const std::filesystem::path& path);

// Writes `value` as the whole of `path`, indented, through an AtomicOutput.
void write_json_file(const std::filesystem::path& path, const Json& value);

}  // namespace naris
