#pragma once
// CSV tables: a header, rows of fields, written whole through an AtomicOutput.
#include <filesystem>
#include <string>
#include <vector>

namespace naris {

class CsvTable {
 public:
  explicit CsvTable(std::vector<std::string> columns);
  // One row; as many fields as columns (fields must not hold commas or newlines).
  void add_row(std::vector<std::string> fields);
  // Throws naris::Error when the write fails (an old file, if any, stays).
  void write(const std::filesystem::path& path) const;

 private:
  std::size_t columns_;
  std::string text_;
};

}  // namespace naris
