#include "core/csv.h"

#include <fmt/format.h>

#include "core/atomic_file.h"
#include "core/error.h"

namespace naris {

CsvTable::CsvTable(std::vector<std::string> columns) : columns_(columns.size()) {
  text_ = fmt::format("{}\n", fmt::join(columns, ","));
}

void CsvTable::add_row(std::vector<std::string> fields) {
  if (fields.size() != columns_)
    fail("internal: a CSV row of {} fields in a table of {} columns", fields.size(), columns_);
  text_ += fmt::format("{}\n", fmt::join(fields, ","));
}

void CsvTable::write(const std::filesystem::path& path) const {
  write_text_file(path, text_);
}

}  // namespace naris
