// `naris run case.yaml`: the stages of a case, from the CT (or the phantom) to the mesh, one
// file each. A stage is skipped when its outputs are newer than its inputs and its settings are
// the ones it last ran with (kept in <output>/.naris-run/); `--force` runs everything.
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <sstream>

#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "image/phantom.h"
#include "image/read_volume.h"
#include "io/atomic_file.h"
#include "pipeline/image_jobs.h"
#include "pipeline/mesh_job.h"

namespace naris::app {
namespace fs = std::filesystem;

namespace {

// A case-file section read strictly: every key must be known, every value of the right type.
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
  // The settings as text: a stage reruns when they change.
  std::string fingerprint() const { return present() ? YAML::Dump(node_) : ""; }

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
  fs::file_time_type newest_input = fs::file_time_type::min();
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

void run_case(const RunOptions& o) {
  if (!fs::is_regular_file(o.case_file))
    fail("{}: no such case file (give a case.yaml, e.g. cases/phantom/case.yaml)",
         o.case_file.string());
  YAML::Node root;
  try {
    root = YAML::LoadFile(o.case_file.string());
  } catch (const YAML::Exception& e) {
    fail("{}: not valid YAML: {}", o.case_file.string(), e.what());
  }
  if (!root.IsMap()) fail("{}: a case file is a map of stages", o.case_file.string());
  const std::string where = o.case_file.filename().string();
  const fs::path base = fs::absolute(o.case_file).parent_path();
  auto resolve = [&](const fs::path& p) { return p.is_absolute() ? p : base / p; };

  Section top(root, where);
  std::string name = o.case_file.parent_path().filename().string(), output = "results", input;
  top.get("name", name);
  top.get("output", output);
  top.get("input", input);
  Section phantom_s(root["phantom"], where + ": phantom");
  Section interp_s(root["interpolate"], where + ": interpolate");
  Section segment_s(root["segment"], where + ": segment");
  Section mesh_s(root["mesh"], where + ": mesh");
  for (const char* key : {"phantom", "interpolate", "segment", "mesh"}) top.allow(key);
  top.finish();
  if (phantom_s.present() == !input.empty())
    fail("{}: give either 'input' (a CT volume or DICOM folder) or a 'phantom' section", where);
  if (!mesh_s.present()) fail("{}: the case has no 'mesh' section", where);

  const fs::path out = resolve(output);
  const fs::path stamps = out / ".naris-run";
  std::vector<Stage> stages;
  fs::path ct = input.empty() ? out / "ct.nrrd" : resolve(input);
  if (!input.empty() && !fs::exists(ct)) fail("{}: input {} does not exist", where, ct.string());

  // phantom → ct.nrrd (+ exact.nrrd)
  std::optional<int> phantom_subject;
  fs::path exact;
  if (phantom_s.present()) {
    auto job = std::make_shared<PhantomJob>();
    bool exact_mask = true;
    phantom_s.get("subject", job->subject);
    phantom_s.get("pixel", job->sampling.pixel);
    phantom_s.get("slice", job->sampling.slice);
    phantom_s.get("noise", job->sampling.noise);
    phantom_s.get("exact_mask", exact_mask);
    phantom_s.finish();
    job->output = ct;
    if (exact_mask) job->exact_mask = exact = out / "exact.nrrd";
    phantom_subject = job->subject;
    stages.push_back({"phantom", {}, {job->output}, phantom_s.fingerprint(), [job] {
                        return format_phantom_summary(*job, run_phantom_job(*job));
                      }});
    if (exact_mask) stages.back().outputs.push_back(exact);
  }
  // interpolate → interpolated.nrrd
  fs::path image = ct;
  if (interp_s.present()) {
    auto job = std::make_shared<InterpolateJob>();
    std::string method = "hsr";
    interp_s.get("method", method);
    interp_s.get("axis", job->axis);
    interp_s.get("insert", job->insert);
    interp_s.get("spacing", job->spacing);
    interp_s.get("block", job->hsr.block);
    interp_s.get("levels", job->hsr.levels);
    interp_s.get("iterations", job->hsr.iterations);
    interp_s.get("threads", job->threads);
    interp_s.finish();
    job->method = parse_slice_method(method);
    job->input = image;
    job->output = image = out / "interpolated.nrrd";
    stages.push_back({"interpolate", {job->input}, {job->output}, interp_s.fingerprint(), [job] {
                        return format_interpolate_summary(*job, run_interpolate_job(*job));
                      }});
  }
  // segment → airway.nrrd
  fs::path airway;
  if (segment_s.present()) {
    auto job = std::make_shared<SegmentJob>();
    std::string inside = "below";
    bool all_components = false;
    segment_s.get("threshold", job->threshold);
    segment_s.get("inside", inside);
    segment_s.get("seeds", job->seeds);
    segment_s.get("all_components", all_components);
    segment_s.get("rotate", job->rotate);
    segment_s.get("decimate", job->decimate);
    segment_s.finish();
    if (inside != "below" && inside != "above")
      fail("{}: segment.inside is '{}': give below or above", where, inside);
    job->inside_above = inside == "above";
    job->keep_largest = !all_components;
    job->input = image;
    job->output = airway = image = out / "airway.nrrd";
    stages.push_back({"segment", {job->input}, {job->output}, segment_s.fingerprint(), [job] {
                        return format_segment_summary(*job, run_segment_job(*job));
                      }});
  }
  // mesh → mesh/mesh.h5 and its companions
  {
    auto job = std::make_shared<MeshJob>();
    std::string inlet, outlet;
    std::optional<double> threshold;
    bool improve = true, msh = true;
    mesh_s.get("inlet", inlet);
    mesh_s.get("outlet", outlet);
    mesh_s.get("patches", job->regions);
    mesh_s.get("threshold", threshold);
    mesh_s.get("improve", improve);
    mesh_s.get("min_edge", job->improve_options.min_edge_fraction);
    mesh_s.get("subdivide", job->subdivisions);
    mesh_s.get("msh", msh);
    mesh_s.finish();
    if (!inlet.empty()) job->inlet = inlet;
    if (!outlet.empty()) job->outlet = outlet;
    job->threshold = threshold;
    job->improve = improve;
    job->write_msh = msh;
    job->input = image;
    job->output = out / "mesh" / "mesh.h5";
    stages.push_back({"mesh", {job->input}, {job->output}, mesh_s.fingerprint(), [job] {
                        MeshJobResult r = run_mesh_job(*job);
                        write_mesh_outputs(*job, r);
                        return format_mesh_summary(*job, r);
                      }});
  }

  // Every setting is checked: only now does the case touch the disk.
  ensure_writable_folder(out);
  fs::create_directories(stamps);
  log_line(fmt::format("naris run: case '{}' ({}), {} stage(s), output {}", name,
                       o.case_file.string(), stages.size(), out.string()));
  Stopwatch total;
  std::vector<StageOutcome> outcomes;
  bool upstream_ran = false;
  for (std::size_t i = 0; i < stages.size(); ++i) {
    const Stage& s = stages[i];
    const fs::path stamp = stamps / (s.name + ".settings");
    StageOutcome outcome{s.name, false, 0.0, s.outputs.front()};
    if (!o.force && !upstream_ran && up_to_date(s, stamp)) {
      log_line(fmt::format("[{}/{}] {}: up to date, skipped", i + 1, stages.size(), s.name));
    } else {
      log_line(fmt::format("[{}/{}] {}", i + 1, stages.size(), s.name));
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

  std::string table = fmt::format("naris run: case '{}' done in {:.1f} s\n", name, total.seconds());
  for (const auto& oc : outcomes)
    table += fmt::format("  {:<12} {:<8} {:>9}  {}\n", oc.name, oc.ran ? "ran" : "skipped",
                         oc.ran ? fmt::format("{:.2f} s", oc.seconds) : "-", oc.output.string());
  if (phantom_subject && !airway.empty()) {
    // The phantom knows its exact airway: score the segmentation on its own grid.
    const Volume<std::uint8_t> mask = to_mask(read_volume(airway));
    const double d = dice(mask, phantom_mask(NasalPhantom(*phantom_subject), mask.frame));
    table += fmt::format("  segmentation vs the phantom's exact airway: Dice {:.4f}\n", d);
  }
  table += fmt::format("  peak memory {:.0f} MB", peak_memory_bytes() / 1048576.0);
  log_line(table);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto [o, cmd] = add_stage<RunOptions>(
      app, "run",
      "Run a case file: phantom or input CT → interpolate → segment → mesh, each stage writing "
      "its file in the case's output folder and skipped when its outputs are newer than its "
      "inputs and its settings are unchanged");
  cmd->add_option("case", o->case_file, "case file (YAML), e.g. cases/phantom/case.yaml")
      ->required();
  cmd->add_flag("--force", o->force, "run every stage, even those that are up to date");
  cmd->callback([o] { run_case(*o); });
}

}  // namespace naris::app
