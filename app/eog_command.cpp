// `naris eog`: output-error models of electro-olfactogram shapes (dissertation ch. 5).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include "app/commands.h"
#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/log.h"
#include "postproc/figures/line_plot.h"
#include "postproc/olfaction/identify.h"
#include "postproc/olfaction/model_io.h"
#include "postproc/olfaction/oe_model.h"
#include "postproc/olfaction/signal.h"

namespace naris::app {
namespace {

namespace fs = std::filesystem;
using namespace olfaction;

// Responses are compared by shape: each is scaled so that its peak (largest |value|) is −1.
std::vector<double> normalized(const std::vector<double>& y) {
  double peak = 0.0;
  for (double v : y) peak = std::abs(v) > std::abs(peak) ? v : peak;
  std::vector<double> out(y);
  // A negative-going response keeps its sign; a positive one is flipped so its peak is −1.
  if (peak != 0.0)
    for (std::size_t k = 0; k < y.size(); ++k) out[k] = (peak < 0 ? y[k] : -y[k]) / std::abs(peak);
  return out;
}

std::vector<double> times(std::size_t n, double rate, double t0 = 0.0) {
  std::vector<double> t(n);
  for (std::size_t k = 0; k < n; ++k) t[k] = t0 + static_cast<double>(k) / rate;
  return t;
}

OeModel checked(OeModel m, bool stabilize, bool force) {
  if (stabilize && !is_stable(m)) {
    m = stabilized(m);
    log_line(
        fmt::format("stabilized: unstable poles reflected inside the unit circle (spectral "
                    "radius now {:.5f})",
                    spectral_radius(m)));
  }
  if (!force) require_stable(m);
  return m;
}

void write_csv(const fs::path& path, const std::vector<std::string>& names,
               const std::vector<const std::vector<double>*>& columns) {
  CsvTable table(names);
  for (std::size_t k = 0; k < columns.front()->size(); ++k) {
    std::vector<std::string> row;
    for (const auto* c : columns) row.push_back(fmt::format("{:.10g}", (*c)[k]));
    table.add_row(std::move(row));
  }
  table.write(path);
}

struct Common {
  std::string model;
  bool stabilize = false, force = false;
  fs::path output;
};

void add_simulate(CLI::App& eog) {
  struct Options : Common {
    std::string pulse = "16mM,200ms";
    double onset = 0.5, length = 10.0;
  };
  auto o = std::make_shared<Options>();
  auto* cmd =
      eog.add_subcommand("simulate", "Simulate a model's response to a square odorant pulse");
  cmd->add_option("--model", o->model, "preset (rat-single-cell, rat-eog, dog-eog) or model YAML")
      ->required();
  cmd->add_option("--pulse", o->pulse, "concentration and duration")->capture_default_str();
  cmd->add_option("--onset", o->onset, "pulse onset (s)")->capture_default_str();
  cmd->add_option("--length", o->length, "record length (s)")->capture_default_str();
  cmd->add_flag("--stabilize", o->stabilize, "reflect unstable poles inside the unit circle");
  cmd->add_flag("--force", o->force, "simulate an unstable model anyway");
  o->output = "response";
  cmd->add_option("-o,--output", o->output, "output prefix: writes PREFIX.csv and PREFIX.png")
      ->capture_default_str();
  cmd->callback([o] {
    const OeModel m = checked(load_model(o->model), o->stabilize, o->force);
    const Pulse p = parse_pulse(o->pulse);
    if (!(o->length > o->onset)) fail("--length must exceed --onset");
    const auto u = pulse_samples(p, o->onset, o->length, m.sample_rate, m.input_unit);
    const auto y = simulate(m, u);
    const auto t = times(u.size(), m.sample_rate);
    ensure_writable_folder(fs::absolute(o->output).parent_path());
    write_csv(fs::path(o->output).concat(".csv"), {"t_s", fmt::format("u_{}", m.input_unit), "y"},
              {&t, &u, &y});
    const auto yn = normalized(y);
    figures::LinePlot plot{fmt::format("{}: {} pulse", m.name, o->pulse),
                           "time (s)",
                           "response (normalized to peak −1)",
                           {{"simulated", t, yn, true, {0.8, 0.1, 0.1}}},
                           o->onset,
                           "stimulus"};
    figures::write_png(plot, fs::path(o->output).concat(".png"));
    const auto peak = std::min_element(y.begin(), y.end()) - y.begin();
    std::size_t first = 0;
    while (first < y.size() && y[first] == 0.0) ++first;
    log_line(fmt::format(
        "naris eog simulate: {} (na={}, nb={}, nd={}, spectral radius {:.5f})\n"
        "  latency {:.3f} s after onset, peak {:.4g} at {:.3f} s\n  wrote {}.csv, {}.png",
        m.name, m.na(), m.nb(), m.nd, spectral_radius(m),
        static_cast<double>(first) / m.sample_rate - o->onset, y[static_cast<std::size_t>(peak)],
        t[static_cast<std::size_t>(peak)], o->output.string(), o->output.string()));
  });
}

// Reads a response recording and its stimulus (a pulse at an onset, or a stimulus file),
// preprocessed to the model rate.
struct Experiment {
  std::vector<double> u, y, t;
};
Experiment load_experiment(const fs::path& response, const std::string& stimulus_file,
                           const std::string& pulse, double onset, double cutoff, double rate,
                           const std::string& unit) {
  const Record r = preprocess(read_record(response), cutoff, rate);
  Experiment e{{}, r.y, r.t};
  if (!stimulus_file.empty()) {
    const Record s = resample(read_record(stimulus_file), rate);
    e.u.assign(r.y.size(), 0.0);
    for (std::size_t k = 0; k < r.y.size(); ++k) {
      const double t = r.t[k];
      if (t < s.t.front() || t > s.t.back()) continue;
      const auto i = std::min<std::size_t>(static_cast<std::size_t>((t - s.t.front()) * rate + 0.5),
                                           s.y.size() - 1);
      e.u[k] = s.y[i];
    }
  } else {
    e.u = pulse_samples(parse_pulse(pulse), onset - r.t.front(),
                        static_cast<double>(r.y.size()) / rate, rate, unit);
    e.u.resize(r.y.size(), 0.0);
  }
  return e;
}

void add_fit(CLI::App& eog) {
  struct Options : Common {
    fs::path fit, validation;
    std::string fit_stimulus, validation_stimulus, pulse, unit = "mM";
    double onset = 0.0, cutoff = 100.0, rate = 200.0;
    OrderSearchOptions search;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = eog.add_subcommand(
      "fit",
      "Identify an OE model: Bessel low-pass, resampling, prediction-error fits for every order, "
      "the orders chosen on a separate validation record");
  cmd->add_option("--fit", o->fit, "response recording to fit (time, value)")->required();
  cmd->add_option("--validation", o->validation, "response recording to choose the orders on")
      ->required();
  cmd->add_option("--pulse", o->pulse, "stimulus of both records as a pulse, e.g. 16mM,200ms");
  cmd->add_option("--onset", o->onset, "pulse onset in the recordings' time (s)");
  cmd->add_option("--fit-stimulus", o->fit_stimulus, "stimulus time series of the fit record");
  cmd->add_option("--validation-stimulus", o->validation_stimulus,
                  "stimulus of the validation record");
  cmd->add_option("--unit", o->unit, "model input unit (mM or uM)")->capture_default_str();
  cmd->add_option("--cutoff", o->cutoff, "Bessel low-pass cutoff (Hz)")->capture_default_str();
  cmd->add_option("--rate", o->rate, "model sampling rate (Hz)")->capture_default_str();
  cmd->add_option("--max-na", o->search.max_na)->capture_default_str()->check(CLI::Range(1, 20));
  cmd->add_option("--max-nb", o->search.max_nb)->capture_default_str()->check(CLI::Range(1, 20));
  cmd->add_option("--min-nd", o->search.min_nd)->capture_default_str()->check(CLI::Range(0, 1000));
  cmd->add_option("--max-nd", o->search.max_nd)->capture_default_str()->check(CLI::Range(0, 1000));
  o->output = "model.yaml";
  cmd->add_option("-o,--output", o->output,
                  "model YAML (a PNG of the validation fit is written beside it)")
      ->capture_default_str();
  cmd->callback([o] {
    const bool pulse = !o->pulse.empty();
    if (pulse == (!o->fit_stimulus.empty() || !o->validation_stimulus.empty()))
      fail(
          "give the stimulus either as --pulse (with --onset) or as --fit-stimulus and "
          "--validation-stimulus files");
    if (!pulse && (o->fit_stimulus.empty() || o->validation_stimulus.empty()))
      fail("give both --fit-stimulus and --validation-stimulus");
    if (o->search.min_nd > o->search.max_nd) fail("--min-nd exceeds --max-nd");
    ensure_writable_folder(fs::absolute(o->output).parent_path());
    const Experiment fit =
        load_experiment(o->fit, o->fit_stimulus, o->pulse, o->onset, o->cutoff, o->rate, o->unit);
    const Experiment val = load_experiment(o->validation, o->validation_stimulus, o->pulse,
                                           o->onset, o->cutoff, o->rate, o->unit);
    const OrderSearchResult r = search_orders(fit.u, fit.y, val.u, val.y, o->search);
    OeModel m = r.best;
    m.name = o->output.stem().string();
    m.sample_rate = o->rate;
    m.input_unit = o->unit;
    write_model(
        o->output, m,
        fmt::format("fitted by naris eog fit to {} (validation {}): validation fit {:.2f} %",
                    o->fit.filename().string(), o->validation.filename().string(),
                    r.validation_fit_percent));
    const auto sim = simulate(m, val.u);
    figures::LinePlot plot{fmt::format("{}: validation record", m.name),
                           "time (s)",
                           "response (normalized to peak −1)",
                           {{"measured", val.t, normalized(val.y), false, {0.1, 0.1, 0.1}},
                            {"simulated", val.t, normalized(sim), true, {0.8, 0.1, 0.1}}},
                           std::nullopt,
                           ""};
    if (pulse) plot.arrow_at_x = o->onset, plot.arrow_label = "stimulus";
    figures::write_png(plot, fs::path(o->output).replace_extension(".png"));
    log_line(fmt::format(
        "naris eog fit: {} orders tried in {:.1f} s\n  selected na={} nb={} nd={} (spectral radius "
        "{:.5f})\n  fit {:.2f} % on the fit record, {:.2f} % on the validation record (NRMSE)\n"
        "  wrote {}, {}",
        r.tried.size(), r.seconds, m.na(), m.nb(), m.nd, spectral_radius(m), r.fit_fit_percent,
        r.validation_fit_percent, o->output.string(),
        fs::path(o->output).replace_extension(".png").string()));
  });
}

void add_predict(CLI::App& eog) {
  auto o = std::make_shared<Common>();
  auto stimulus = std::make_shared<fs::path>();
  auto* cmd =
      eog.add_subcommand("predict",
                         "Predict the response to a stimulus time series (e.g. odorant flux to the "
                         "olfactory region from particle tracing)");
  cmd->add_option("--model", o->model, "preset or model YAML")->required();
  cmd->add_option("--stimulus", *stimulus,
                  "stimulus recording (time, concentration in the model's unit)")
      ->required();
  cmd->add_flag("--stabilize", o->stabilize, "reflect unstable poles inside the unit circle");
  cmd->add_flag("--force", o->force, "simulate an unstable model anyway");
  o->output = "prediction";
  cmd->add_option("-o,--output", o->output, "output prefix: PREFIX.csv and PREFIX.png")
      ->capture_default_str();
  cmd->callback([o, stimulus] {
    const OeModel m = checked(load_model(o->model), o->stabilize, o->force);
    const Record s = resample(read_record(*stimulus), m.sample_rate);
    const auto y = simulate(m, s.y);
    ensure_writable_folder(fs::absolute(o->output).parent_path());
    write_csv(fs::path(o->output).concat(".csv"), {"t_s", fmt::format("u_{}", m.input_unit), "y"},
              {&s.t, &s.y, &y});
    figures::LinePlot plot{fmt::format("{}: predicted response", m.name),
                           "time (s)",
                           "response (normalized to peak −1)",
                           {{"predicted", s.t, normalized(y), true, {0.8, 0.1, 0.1}}},
                           std::nullopt,
                           ""};
    figures::write_png(plot, fs::path(o->output).concat(".png"));
    log_line(fmt::format("naris eog predict: {} on {} samples at {} Hz\n  wrote {}.csv, {}.png",
                         m.name, s.y.size(), m.sample_rate, o->output.string(),
                         o->output.string()));
  });
}

}  // namespace

void add_eog_command(CLI::App& app) {
  auto* eog =
      app.add_subcommand("eog", "Output-error models of electro-olfactogram shapes (ch. 5)");
  eog->require_subcommand(1);
  add_simulate(*eog);
  add_fit(*eog);
  add_predict(*eog);
}

}  // namespace naris::app
