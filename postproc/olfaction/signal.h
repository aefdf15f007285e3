#pragma once
// Records and stimuli for the olfactory models: reading recordings (time, value), square
// pulses, the zero-phase Bessel low-pass and the resampling of dissertation 5.3.
#include <filesystem>
#include <string>
#include <vector>

namespace naris::olfaction {

struct Record {
  std::vector<double> t;  // seconds, uniform and increasing
  std::vector<double> y;
  double sample_rate() const;  // Hz
};

// Two columns, time and value, separated by spaces, tabs, commas or semicolons, with or
// without header lines (pCLAMP's ASCII export). Time in seconds, or in ms when the header says
// so. Throws naris::Error for an empty or non-numeric file, NaN, or a time column that is not
// uniform and increasing.
Record read_record(const std::filesystem::path& path);
void write_record(const std::filesystem::path& path, const Record& r, const std::string& header);

// A square pulse "16mM,200ms" (concentration with unit, duration with unit).
struct Pulse {
  double amplitude = 0.0;
  std::string unit = "mM";
  double duration = 0.0;  // seconds
};
Pulse parse_pulse(const std::string& text);
// Samples of a pulse starting at `onset` seconds in a record of `length` seconds at `rate` Hz,
// in `unit` (mM or uM; converted).
std::vector<double> pulse_samples(const Pulse& p, double onset, double length, double rate,
                                  const std::string& unit);

// A train of pulses of random timing: every `hold` samples the stimulus is switched on (at
// `amplitude`) or off with equal odds. Persistently exciting, unlike a single pulse.
std::vector<double> random_pulse_train(unsigned seed, std::size_t samples, double amplitude,
                                       int hold);

// Zero-phase low-pass: a 4th-order Bessel filter (−3 dB at the cutoff), run forwards and
// backwards, so the delay cancels and the attenuation at the cutoff is −6 dB.
std::vector<double> bessel_lowpass(const std::vector<double>& x, double cutoff_hz, double rate_hz);

// Linear interpolation onto a uniform grid at `to_rate` Hz from t0 (apply the low-pass first).
Record resample(const Record& r, double to_rate);

}  // namespace naris::olfaction
