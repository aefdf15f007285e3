#include "postproc/olfaction/signal.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>

#include "core/error.h"

namespace naris::olfaction {

double Record::sample_rate() const {
  return t.size() > 1 ? static_cast<double>(t.size() - 1) / (t.back() - t.front()) : 0.0;
}

namespace {

bool parse_row(const std::string& line, double& a, double& b, int& columns) {
  std::string s = line;
  for (char& c : s)
    if (c == ',' || c == ';' || c == '\t') c = ' ';
  std::istringstream in(s);
  std::vector<std::string> fields;
  for (std::string f; in >> f;) fields.push_back(f);
  columns = static_cast<int>(fields.size());
  if (fields.size() < 2) return false;
  try {
    std::size_t used = 0;
    a = std::stod(fields[0], &used);
    if (used != fields[0].size()) return false;
    b = std::stod(fields[1], &used);
    if (used != fields[1].size()) return false;
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

}  // namespace

Record read_record(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) fail("{}: cannot open the recording", path.string());
  Record r;
  std::string line, header;
  int number = 0;
  bool milliseconds = false;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    double a = 0, b = 0;
    int columns = 0;
    if (!parse_row(line, a, b, columns)) {
      if (r.t.empty()) {  // header lines before the data
        header += line + "\n";
        continue;
      }
      fail("{}:{}: not two numbers (time, value): '{}'", path.string(), number, line.substr(0, 60));
    }
    if (!std::isfinite(a) || !std::isfinite(b))
      fail("{}:{}: NaN or infinite value in the recording", path.string(), number);
    r.t.push_back(a);
    r.y.push_back(b);
  }
  if (r.t.empty()) fail("{}: no data: expected two numeric columns (time, value)", path.string());
  if (r.t.size() < 3)
    fail("{}: only {} samples; a recording needs many more", path.string(), r.t.size());
  std::string lower = header;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  milliseconds = std::regex_search(lower, std::regex(R"(\(ms\)|\bms\b|msec)"));
  if (milliseconds)
    for (double& t : r.t) t *= 1e-3;
  const double dt = (r.t.back() - r.t.front()) / static_cast<double>(r.t.size() - 1);
  if (!(dt > 0.0)) fail("{}: the time column does not increase", path.string());
  for (std::size_t k = 1; k < r.t.size(); ++k)
    if (!(r.t[k] > r.t[k - 1]))
      fail("{}: time decreases or repeats at sample {} (t = {})", path.string(), k + 1, r.t[k]);
  for (std::size_t k = 1; k < r.t.size(); ++k) {
    const double step = r.t[k] - r.t[k - 1];
    if (std::abs(step - dt) > 0.01 * dt)
      fail(
          "{}: non-uniform sampling at sample {} (step {:.6g} s, mean {:.6g} s); resample the "
          "recording to a uniform rate",
          path.string(), k + 1, step, dt);
  }
  return r;
}

void write_record(const std::filesystem::path& path, const Record& r, const std::string& header) {
  std::ofstream out(path);
  if (!out) fail("{}: cannot write", path.string());
  out << header << "\n";
  out.precision(10);
  for (std::size_t k = 0; k < r.t.size(); ++k) out << r.t[k] << "\t" << r.y[k] << "\n";
  if (!out) fail("{}: write failed", path.string());
}

Pulse parse_pulse(const std::string& text) {
  static const std::regex form(
      R"(^\s*([0-9.eE+-]+)\s*(mM|uM|µM|M)\s*,\s*([0-9.eE+-]+)\s*(ms|s)\s*$)");
  std::smatch m;
  if (!std::regex_match(text, m, form))
    fail("pulse '{}' not understood: give concentration and duration, e.g. 16mM,200ms", text);
  Pulse p;
  p.amplitude = std::stod(m[1].str());
  p.unit = m[2].str() == "µM" ? "uM" : m[2].str();
  p.duration = std::stod(m[3].str()) * (m[4].str() == "ms" ? 1e-3 : 1.0);
  if (!(p.amplitude > 0.0) || !(p.duration > 0.0))
    fail("pulse '{}': concentration and duration must be positive", text);
  return p;
}

std::vector<double> pulse_samples(const Pulse& p, double onset, double length, double rate,
                                  const std::string& unit) {
  auto in_mm = [](const std::string& u) {
    if (u == "mM") return 1.0;
    if (u == "uM") return 1e-3;
    if (u == "M") return 1e3;
    fail("unknown concentration unit '{}' (mM, uM or M)", u);
  };
  const double amplitude = p.amplitude * in_mm(p.unit) / in_mm(unit);
  const auto n = static_cast<std::size_t>(std::llround(length * rate));
  std::vector<double> u(n, 0.0);
  const auto first = static_cast<std::size_t>(std::llround(onset * rate));
  const auto count = static_cast<std::size_t>(std::llround(p.duration * rate));
  for (std::size_t k = first; k < std::min(n, first + count); ++k) u[k] = amplitude;
  return u;
}

std::vector<double> random_pulse_train(unsigned seed, std::size_t samples, double amplitude,
                                       int hold) {
  if (hold < 1) fail("pulse train: the hold must be at least one sample");
  std::mt19937 rng(seed);
  std::bernoulli_distribution on(0.5);
  std::vector<double> u(samples);
  double v = 0.0;
  for (std::size_t k = 0; k < samples; ++k) {
    if (k % static_cast<std::size_t>(hold) == 0) v = on(rng) ? amplitude : 0.0;
    u[k] = v;
  }
  return u;
}

namespace {

// Second-order sections of the 4th-order Bessel low-pass, digital, from its analog poles.
struct Biquad {
  double b0, b1, b2, a1, a2;
};

std::vector<Biquad> bessel_sections(double cutoff_hz, double rate_hz) {
  // Reverse Bessel polynomial of order 4 (unit group delay): s⁴ + 10s³ + 45s² + 105s + 105.
  const double coeffs[4] = {10.0, 45.0, 105.0, 105.0};
  Eigen::Matrix4d c = Eigen::Matrix4d::Zero();
  for (int j = 0; j < 4; ++j) c(0, j) = -coeffs[j];
  for (int i = 1; i < 4; ++i) c(i, i - 1) = 1.0;
  const Eigen::EigenSolver<Eigen::Matrix4d> solver(c, false);
  std::vector<std::complex<double>> p(solver.eigenvalues().begin(), solver.eigenvalues().end());
  // Renormalize so that |H(jω)| = 1/√2 at ω = 1 (bisection on the magnitude).
  auto magnitude = [&](double w) {
    std::complex<double> h = 1.0;
    for (const auto& z : p) h *= -z / (std::complex<double>(0.0, w) - z);
    return std::abs(h);
  };
  double lo = 0.1, hi = 10.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (magnitude(mid) > std::sqrt(0.5) ? lo : hi) = mid;
  }
  const double w3db = 0.5 * (lo + hi);
  // Prewarped analog cutoff, then the bilinear transform s = 2f_s (1 − z⁻¹)/(1 + z⁻¹).
  const double wc = 2.0 * rate_hz * std::tan(M_PI * cutoff_hz / rate_hz);
  const double k = 2.0 * rate_hz;
  std::vector<Biquad> sections;
  for (const auto& z : p) {
    if (z.imag() < 0.0) continue;  // one per conjugate pair
    const std::complex<double> q = z / w3db * wc;
    const double s1 = -2.0 * q.real(), s0 = std::norm(q);  // s² + s1 s + s0
    const double a0 = k * k + s1 * k + s0;
    sections.push_back({s0 / a0, 2.0 * s0 / a0, s0 / a0, (2.0 * s0 - 2.0 * k * k) / a0,
                        (k * k - s1 * k + s0) / a0});
  }
  return sections;
}

void run(const std::vector<Biquad>& sections, std::vector<double>& x) {
  for (const auto& s : sections) {
    // Start from the steady state of the first value to avoid an edge transient.
    double x1 = x.front(), x2 = x.front(), y1 = x.front(), y2 = x.front();
    for (double& v : x) {
      const double y = s.b0 * v + s.b1 * x1 + s.b2 * x2 - s.a1 * y1 - s.a2 * y2;
      x2 = x1;
      x1 = v;
      y2 = y1;
      y1 = y;
      v = y;
    }
  }
}

}  // namespace

std::vector<double> bessel_lowpass(const std::vector<double>& x, double cutoff_hz, double rate_hz) {
  if (x.empty()) return x;
  if (!(cutoff_hz > 0.0) || cutoff_hz >= 0.5 * rate_hz)
    fail("low-pass cutoff {} Hz must lie between 0 and half the sampling rate ({} Hz)", cutoff_hz,
         0.5 * rate_hz);
  const auto sections = bessel_sections(cutoff_hz, rate_hz);
  std::vector<double> y = x;
  run(sections, y);
  std::reverse(y.begin(), y.end());
  run(sections, y);
  std::reverse(y.begin(), y.end());
  return y;
}

Record resample(const Record& r, double to_rate) {
  Record out;
  const double t0 = r.t.front(), t1 = r.t.back();
  const auto n = static_cast<std::size_t>(std::floor((t1 - t0) * to_rate + 1e-9)) + 1;
  out.t.resize(n);
  out.y.resize(n);
  const double dt = (t1 - t0) / static_cast<double>(r.t.size() - 1);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = t0 + static_cast<double>(k) / to_rate;
    const double pos = (t - t0) / dt;
    const auto i = std::min(static_cast<std::size_t>(pos), r.t.size() - 2);
    const double w = pos - static_cast<double>(i);
    out.t[k] = t;
    out.y[k] = (1.0 - w) * r.y[i] + w * r.y[i + 1];
  }
  return out;
}

}  // namespace naris::olfaction
