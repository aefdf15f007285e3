// `naris run case.yaml`: the stages of a case, from the CT (or the phantom) to the flow, its
// particle paths and its cross-sections, one file (or folder) each. A stage is skipped when its
// outputs are newer than its inputs (the executable included) and its settings are the ones it
// last ran with (kept in <output>/.naris-run/); `--force` runs everything.
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <sstream>

#include "app/commands.h"
#include "app/stage_settings.h"
#include "app/trace_figures.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "core/units.h"
#include "mesh/image/image_jobs.h"
#include "mesh/image/phantom.h"
#include "mesh/image/read_volume.h"
#include "mesh/pipeline/mesh_job.h"
#include "postproc/report/report.h"
#include "solver/parallel/petsc.h"

namespace naris::app {
namespace fs = std::filesystem;

namespace {

bool present(const YAML::Node& node) {
  return node && !node.IsNull();
}
// A section's settings as text: a stage reruns when they change.
std::string dump(const YAML::Node& node) {
  return present(node) ? YAML::Dump(node) : "";
}

// A case-file section of the phantom and the top level read strictly: every key must be known,
// every value of the right type.
class Section {
 public:
  Section(YAML::Node node, std::string where) : node_(std::move(node)), where_(std::move(where)) {
    if (node_ && !node_.IsNull() && !node_.IsMap()) fail("{}: expected a map of settings", where_);
  }
  bool present() const { return node_ && !node_.IsNull(); }
  template <class T>
  void get(const char* key, T& value) {
    known_.insert(key);
    if (!present() || !node_[key]) return;
    try {
      value = node_[key].as<T>();
    } catch (const YAML::Exception&) {
      fail("{}.{}: '{}' is not a valid value", where_, key, YAML::Dump(node_[key]));
    }
  }
  template <class T>
  void get(const char* key, std::optional<T>& value) {
    T v{};
    known_.insert(key);
    if (!present() || !node_[key] || node_[key].IsNull()) return;
    get(key, v);
    value = v;
  }
  void allow(const char* key) { known_.insert(key); }
  void finish() const {
    if (!present()) return;
    for (const auto& kv : node_) {
      const auto key = kv.first.as<std::string>();
      if (!known_.count(key))
        fail("{}: unknown setting '{}' (known: {})", where_, key, fmt::join(known_, ", "));
    }
  }

 private:
  YAML::Node node_;
  std::string where_;
  std::set<std::string> known_;
};

struct Stage {
  std::string name;
  std::vector<fs::path> inputs, outputs;
  std::string settings;
  std::function<std::string()> run;  // returns its summary
};

struct StageOutcome {
  std::string name;
  bool ran = false;
  double seconds = 0.0;
  fs::path output;
};

bool up_to_date(const Stage& s, const fs::path& stamp) {
  if (!fs::exists(stamp)) return false;
  std::ifstream in(stamp);
  std::stringstream text;
  text << in.rdbuf();
  if (text.str() != s.settings) return false;
  // The program that wrote the outputs is one of their inputs: a rebuilt naris runs them again.
  std::error_code error;
  fs::file_time_type newest_input =
      fs::last_write_time(fs::read_symlink("/proc/self/exe", error), error);
  if (error) newest_input = fs::file_time_type::min();
  for (const auto& p : s.inputs) {
    if (!fs::exists(p)) return false;
    newest_input = std::max(newest_input, fs::last_write_time(p));
  }
  for (const auto& p : s.outputs)
    if (!fs::exists(p) || fs::last_write_time(p) < newest_input) return false;
  return true;
}

void write_stamp(const Stage& s, const fs::path& stamp) {
  write_text_file(stamp, s.settings);
}

struct RunOptions {
  fs::path case_file;
  bool force = false;
};

// What a case file asks for: its stages in order, each with its files and settings.
struct CasePlan {
  std::string name;
  fs::path case_file, out;
  std::vector<Stage> stages;
  std::optional<int> phantom_subject;  // the phantom knows its exact airway
  fs::path airway;                     // the segmentation, when the case segments
};

YAML::Node load_case(const fs::path& case_file) {
  if (!fs::is_regular_file(case_file))
    fail("{}: no such case file (give a case.yaml, e.g. cases/phantom/case.yaml)",
         case_file.string());
  YAML::Node root;
  try {
    root = YAML::LoadFile(case_file.string());
  } catch (const YAML::Exception& e) {
    fail("{}: not valid YAML: {}", case_file.string(), e.what());
  }
  if (!root.IsMap()) fail("{}: a case file is a map of stages", case_file.string());
  return root;
}

// phantom → ct.nrrd (+ exact.nrrd)
void plan_phantom(Section& section, const YAML::Node& node, const fs::path& ct, CasePlan& plan) {
  auto job = std::make_shared<PhantomJob>();
  bool exact_mask = true;
  section.get("subject", job->subject);
  section.get("pixel", job->sampling.pixel);
  section.get("slice", job->sampling.slice);
  section.get("noise", job->sampling.noise);
  section.get("exact_mask", exact_mask);
  section.finish();
  job->output = ct;
  if (exact_mask) job->exact_mask = plan.out / "exact.nrrd";
  plan.phantom_subject = job->subject;
  plan.stages.push_back({"phantom", {}, {job->output}, dump(node), [job] {
                           return format_phantom_summary(*job, run_phantom_job(*job));
                         }});
  if (exact_mask) plan.stages.back().outputs.push_back(job->exact_mask);
}

// interpolate → interpolated.nrrd, segment → airway.nrrd (each when the case has it); returns
// the image the mesher takes.
fs::path plan_image_stages(const YAML::Node& root, const std::string& where, fs::path image,
                           CasePlan& plan) {
  if (present(root["interpolate"])) {
    InterpolateSettings settings;
    settings.table.read(root["interpolate"], where + ": interpolate");
    auto job = std::make_shared<InterpolateJob>(settings.resolve());
    job->input = image;
    job->output = image = plan.out / "interpolated.nrrd";
    plan.stages.push_back(
        {"interpolate", {job->input}, {job->output}, dump(root["interpolate"]), [job] {
           return format_interpolate_summary(*job, run_interpolate_job(*job));
         }});
  }
  if (present(root["segment"])) {
    SegmentSettings settings;
    settings.table.read(root["segment"], where + ": segment");
    auto job = std::make_shared<SegmentJob>(settings.resolve());
    job->input = image;
    job->output = plan.airway = image = plan.out / "airway.nrrd";
    plan.stages.push_back({"segment", {job->input}, {job->output}, dump(root["segment"]), [job] {
                             return format_segment_summary(*job, run_segment_job(*job));
                           }});
  }
  return image;
}

// mesh → mesh/mesh.h5 and its companions; solve → solution/ (when the case has it).
void plan_flow_stages(const YAML::Node& root, const std::string& where, const fs::path& base,
                      const fs::path& image, CasePlan& plan) {
  const fs::path mesh_file = plan.out / "mesh" / "mesh.h5";
  MeshSettings mesh;
  mesh.table.read(root["mesh"], where + ": mesh");
  auto mesh_job = std::make_shared<MeshJob>(mesh.resolve());
  mesh_job->input = image;
  mesh_job->output = mesh_file;
  plan.stages.push_back(
      {"mesh", {mesh_job->input}, {mesh_job->output}, dump(root["mesh"]), [job = mesh_job] {
         MeshJobResult r = run_mesh_job(*job);
         write_mesh_outputs(*job, r);
         return format_mesh_summary(*job, r);
       }});
  if (!present(root["solve"])) {
    for (const char* stage : {"trace", "planes"})
      if (present(root[stage])) fail("{}: the {} stage needs a solve section", where, stage);
    return;
  }
  SolveSettings solve;
  solve.table.read(root["solve"], where + ": solve");
  auto job = std::make_shared<airflow::AirflowJob>(solve.resolve(base));
  job->mesh = mesh_file;
  job->output = plan.out / "solution";
  plan.stages.push_back({"solve",
                         {job->mesh},
                         {job->output / "summary.json"},
                         dump(root["solve"]),
                         [job, petsc_options = solve.petsc] {
                           petsc::Session session;
                           insert_petsc_options(petsc_options);
                           return solve_and_summarize(*job);
                         }});
  const fs::path solution = job->output / "solution.h5";
  fs::path crossings;
  if (present(root["trace"])) {
    auto trace = std::make_shared<TraceSettings>();
    trace->table.read(root["trace"], where + ": trace");
    auto trace_job = std::make_shared<particles::TraceJob>(trace->resolve(base));
    trace_job->solution = solution;
    trace_job->output = plan.out / "trace";
    crossings = trace_job->output / "crossings.csv";
    std::vector<fs::path> trace_inputs{trace_job->solution};
    if (!trace_job->points.empty()) trace_inputs.push_back(trace_job->points);
    if (trace_job->mesh) trace_inputs.push_back(*trace_job->mesh);
    plan.stages.push_back({"trace",
                           trace_inputs,
                           {trace_job->output / "summary.json"},
                           dump(root["trace"]),
                           [trace_job, figures = trace->figures] {
                             const particles::TraceResult r = particles::run_trace_job(*trace_job);
                             if (figures) write_trace_figures(r, trace_job->output);
                             return particles::format_trace_summary(*trace_job, r);
                           }});
  }
  if (!present(root["planes"])) return;
  PlanesSettings planes;
  planes.table.read(root["planes"], where + ": planes");
  auto planes_job = std::make_shared<planes::PlanesJob>(planes.resolve(base));
  planes_job->solution = solution;
  planes_job->output = plan.out / "planes";
  // The trace's crossings are drawn on the planes unless the section names another file.
  if (!planes.crossings && !crossings.empty()) planes_job->crossings = crossings;
  std::vector<fs::path> planes_inputs{solution};
  if (!planes_job->crossings.empty()) planes_inputs.push_back(planes_job->crossings);
  if (!planes_job->mesh.empty()) planes_inputs.push_back(planes_job->mesh);
  plan.stages.push_back({"planes",
                         planes_inputs,
                         {planes_job->output / "summary.json"},
                         dump(root["planes"]),
                         [planes_job] {
                           return planes::format_planes_summary(
                               *planes_job, planes::run_planes_job(*planes_job));
                         }});
  // The report gathers the stages' tables and figures with the case file: any change to the
  // case file reruns it.
  std::vector<fs::path> report_inputs{plan.case_file, job->output / "summary.json",
                                      planes_job->output / "summary.json"};
  const bool traced = !crossings.empty();
  if (traced) report_inputs.push_back(plan.out / "trace" / "summary.json");
  plan.stages.push_back(
      {"report",
       report_inputs,
       {plan.out / "report.html"},
       dump(root),
       [out = plan.out, name = plan.name, case_file = plan.case_file, traced] {
         std::ifstream in(case_file);
         std::stringstream text;
         text << in.rdbuf();
         report::write_report(report::case_report(out, name, text.str(), NARIS_VERSION, traced),
                              out);
         return fmt::format("naris report: {} and report.md", (out / "report.html").string());
       }});
}

// Every setting of every stage read and checked, before anything runs.
CasePlan plan_case(const fs::path& case_file) {
  const YAML::Node root = load_case(case_file);
  const std::string where = case_file.filename().string();
  const fs::path base = fs::absolute(case_file).parent_path();
  CasePlan plan;
  plan.case_file = fs::absolute(case_file);
  Section top(root, where);
  std::string output = "results", input;
  plan.name = case_file.parent_path().filename().string();
  top.get("name", plan.name);
  top.get("output", output);
  top.get("input", input);
  Section phantom(root["phantom"], where + ": phantom");
  for (const char* key : {"phantom", "interpolate", "segment", "mesh", "solve", "trace", "planes"})
    top.allow(key);
  top.finish();
  if (phantom.present() == !input.empty())
    fail("{}: give either 'input' (a CT volume or DICOM folder) or a 'phantom' section", where);
  if (!present(root["mesh"])) fail("{}: the case has no 'mesh' section", where);
  plan.out = resolve_path(base, output);
  const fs::path ct = input.empty() ? plan.out / "ct.nrrd" : resolve_path(base, input);
  if (!input.empty() && !fs::exists(ct)) fail("{}: input {} does not exist", where, ct.string());
  if (phantom.present()) plan_phantom(phantom, root["phantom"], ct, plan);
  const fs::path image = plan_image_stages(root, where, ct, plan);
  plan_flow_stages(root, where, base, image, plan);
  return plan;
}

// Each stage in order, skipped when up to date and nothing before it ran.
std::vector<StageOutcome> run_stages(const CasePlan& plan, bool force) {
  const fs::path stamps = plan.out / ".naris-run";
  fs::create_directories(stamps);
  std::vector<StageOutcome> outcomes;
  bool upstream_ran = false;
  const std::size_t n = plan.stages.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Stage& s = plan.stages[i];
    const fs::path stamp = stamps / (s.name + ".settings");
    StageOutcome outcome{s.name, false, 0.0, s.outputs.front()};
    if (!force && !upstream_ran && up_to_date(s, stamp)) {
      log_line(fmt::format("[{}/{}] {}: up to date, skipped", i + 1, n, s.name));
    } else {
      log_line(fmt::format("[{}/{}] {}", i + 1, n, s.name));
      fs::remove(stamp);  // a stage that fails half-way must not look up to date
      Stopwatch clock;
      const std::string summary = s.run();
      outcome.ran = upstream_ran = true;
      outcome.seconds = clock.seconds();
      log_line(summary);
      write_stamp(s, stamp);
    }
    outcomes.push_back(outcome);
  }
  return outcomes;
}

// The ranks of an MPI launch, from the launcher's environment (1 without one).
int launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* v = std::getenv(name)) return std::max(1, std::atoi(v));
  return 1;
}

void run_case(const RunOptions& o) {
  // Every rank would write the image stages' files at once.
  if (const int ranks = launched_ranks(); ranks > 1)
    fail(
        "naris run is one process, launched here as {} MPI ranks: run the case without mpirun, "
        "then naris solve under mpirun on its mesh",
        ranks);
  const CasePlan plan = plan_case(o.case_file);
  // Every setting is checked: only now does the case touch the disk.
  ensure_writable_folder(plan.out);
  log_line(fmt::format("naris run: case '{}' ({}), {} stage(s), output {}", plan.name,
                       o.case_file.string(), plan.stages.size(), plan.out.string()));
  Stopwatch total;
  const std::vector<StageOutcome> outcomes = run_stages(plan, o.force);
  std::string table =
      fmt::format("naris run: case '{}' done in {:.1f} s\n", plan.name, total.seconds());
  for (const auto& oc : outcomes)
    table += fmt::format("  {:<12} {:<8} {:>9}  {}\n", oc.name, oc.ran ? "ran" : "skipped",
                         oc.ran ? fmt::format("{:.2f} s", oc.seconds) : "-", oc.output.string());
  if (plan.phantom_subject && !plan.airway.empty()) {
    // The phantom knows its exact airway: score the segmentation on its own grid.
    const Volume<std::uint8_t> mask = to_mask(read_volume(plan.airway));
    const double d = dice(mask, phantom_mask(NasalPhantom(*plan.phantom_subject), mask.frame));
    table += fmt::format("  segmentation vs the phantom's exact airway: Dice {:.4f}\n", d);
  }
  table += fmt::format("  peak memory {:.0f} MB", megabytes(peak_memory_bytes()));
  log_line(table);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto [o, cmd] = add_stage<RunOptions>(
      app, "run",
      "Run a case file: phantom or input CT → interpolate → segment → mesh → solve → trace → "
      "planes → report, "
      "each stage writing its files in the case's output folder and skipped when its outputs "
      "are newer than its inputs and its settings are unchanged");
  cmd->add_option("case", o->case_file, "case file (YAML), e.g. cases/phantom/case.yaml")
      ->required();
  cmd->add_flag("--force", o->force, "run every stage, even those that are up to date");
  cmd->callback([o] { run_case(*o); });
}

}  // namespace naris::app
