#pragma once
// The report of a case or of a comparison: one self-contained report.html (figures embedded as
// data URIs, inline style, no network), which opens offline in any browser, and report.md
// beside it for those who prefer text (figures by relative path).
#include <filesystem>
#include <string>
#include <vector>

namespace naris::report {

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Section {
  std::string title, text;
  std::vector<Table> tables;
  std::vector<std::filesystem::path> figures;  // PNG files
};

struct Report {
  std::string title, version;
  std::vector<Section> sections;
  std::string settings;  // the case file's text (or the comparison's inputs)
};

// A table as Markdown, header first.
std::string markdown_table(const Table& table);

// Writes report.html and report.md into `folder`; a figure path is written relative to it in
// report.md. Throws naris::Error when a figure cannot be read or a file written.
void write_report(const Report& report, const std::filesystem::path& folder);

// The report of a case's results folder: solution/, planes/ where present, and trace/ when the
// case traces (`traced`; a trace/ left by an earlier run is not the case's).
Report case_report(const std::filesystem::path& results, const std::string& name,
                   const std::string& settings, const std::string& version, bool traced);

}  // namespace naris::report
