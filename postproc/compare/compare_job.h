#pragma once
// `naris compare` as a library call: several subjects' results side by side (section 4.3.1,
// Figs. 4.12, 4.13): a table of every subject's numbers (compare.csv, compare.md), one plane of
// all subjects on one colour scale, and the cross-sectional area against the distance from the
// anterior tip for all (the acoustic-rhinometry view, minimum marked), and the report of it all
// (report.html, report.md). docs/formats.md.
#include <filesystem>
#include <string>
#include <vector>

#include "core/json.h"
#include "solver/airflow/solution_file.h"

namespace naris::compare {

struct CompareJob {
  // Case folders (holding case.yaml; their results where its `output` says) or results folders
  // (holding solution/ and planes/).
  std::vector<std::filesystem::path> inputs;
  std::filesystem::path output = "compare";
  int plane = 5;              // the plane drawn side by side, numbered as in planes.csv
  double profile_step = 1.0;  // mm between the sections of the area–distance plot
  bool figures = true;
  std::string version;  // naris's, for the report
};

struct Subject {
  std::string name;
  std::filesystem::path results;
  Json solution, planes, trace;           // the stages' summary.json (trace: null when not traced)
  airflow::SolutionState solution_state;  // solution/solution.h5, read once
  std::string units;                      // of its mesh
};

struct CompareResult {
  std::vector<Subject> subjects;
  std::vector<std::string> columns;            // compare.csv's header
  std::vector<std::vector<std::string>> rows;  // one per subject
  std::vector<std::string> files;              // written, relative to the output folder
  double seconds = 0.0;
};

// Throws naris::Error before writing anything for an input that is neither a case nor a results
// folder, a subject without the solve or planes stage, or subjects whose planes or mesh units
// differ.
CompareResult run_compare_job(const CompareJob& job);
std::string format_compare_summary(const CompareJob& job, const CompareResult& result);

}  // namespace naris::compare
