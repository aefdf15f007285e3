// Benchmark of `naris eog fit`: the full order search (na, nb ≤ 10, na ≥ nb, nd ≤ 60: 3,300
// models) on 10 s records at 200 Hz simulated from the stable preset with white output noise,
// for a single 16 mM, 500 ms pulse (the dissertation's stimulus) and for a train of random
// pulses. Prints time, selected orders, fit on the noisy and on the noise-free validation
// record, and the largest relative coefficient error.
#include <cmath>
#include <cstdio>
#include <random>

#include "core/log.h"
#include "postproc/olfaction/identify.h"
#include "postproc/olfaction/oe_model.h"
#include "postproc/olfaction/signal.h"

using namespace naris;
using namespace naris::olfaction;

namespace {

std::vector<double> with_noise(std::vector<double> y, double snr_db, unsigned seed) {
  double power = 0.0;
  for (double v : y) power += v * v;
  std::normal_distribution<double> e(
      0.0, std::sqrt(power / static_cast<double>(y.size()) / std::pow(10.0, snr_db / 10.0)));
  std::mt19937 rng(seed);
  for (double& v : y) v += e(rng);
  return y;
}

}  // namespace

int main() {
  set_verbosity(Verbosity::quiet);
  const OeModel truth = rat_single_cell();
  std::printf("truth: %s na=%d nb=%d nd=%d (the only preset stable as printed)\n\n",
              truth.name.c_str(), truth.na(), truth.nb(), truth.nd);
  std::printf("%-24s %6s %8s %8s %12s %11s %15s %16s\n", "stimulus", "SNR dB", "threads", "time s",
              "selected", "fit % noisy", "fit % noise-free", "max coef error %");
  struct Case {
    const char* name;
    bool train;
    double snr;
    int threads;
  };
  const Case cases[] = {{"pulse 16mM,500ms", false, 20, 2},
                        {"pulse 16mM,500ms", false, 20, 1},
                        {"pulse 16mM,500ms", false, 40, 2},
                        {"random pulse train", true, 20, 2},
                        {"random pulse train", true, 40, 2}};
  for (const Case& c : cases) {
    const auto make_u = [&](unsigned seed) {
      return c.train ? random_pulse_train(seed, 2000, 16.0, 4)
                     : pulse_samples(parse_pulse("16mM,500ms"), 0.5, 10.0, 200.0, "mM");
    };
    const auto u_fit = make_u(1), u_val = make_u(2);
    const auto clean_fit = simulate(truth, u_fit), clean_val = simulate(truth, u_val);
    OrderSearchOptions o;
    o.threads = c.threads;
    const auto r = search_orders(u_fit, with_noise(clean_fit, c.snr, 11), u_val,
                                 with_noise(clean_val, c.snr, 12), o);
    double worst = NAN;
    if (r.best.na() == truth.na() && r.best.nb() == truth.nb()) {
      worst = 0.0;
      for (int j = 0; j < truth.na(); ++j)
        worst = std::max(worst, std::abs(r.best.a[j] - truth.a[j]) / std::abs(truth.a[j]));
      worst = std::max(worst, std::abs(r.best.b[0] - truth.b[0]) / std::abs(truth.b[0]));
    }
    std::printf(
        "%-24s %6.0f %8d %8.1f %4d,%2d,%3d   %11.2f %15.2f %16s\n", c.name, c.snr, c.threads,
        r.seconds, r.best.na(), r.best.nb(), r.best.nd, r.validation_fit_percent,
        fit_percent(clean_val, simulate(r.best, u_val)),
        std::isnan(worst) ? "(other orders)" : std::to_string(100 * worst).substr(0, 6).c_str());
    std::fflush(stdout);
  }
  std::printf(
      "\nselected: na, nb, nd; fit %%: NRMSE fit of the simulated response on the validation "
      "record, noisy\nand noise-free; coefficient error only when the selected orders "
      "equal the truth's.\n");
  return 0;
}
