#include "postproc/olfaction/oe_model.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace naris::olfaction {

std::vector<std::complex<double>> poles(const OeModel& m) {
  const int n = m.na();
  if (n == 0) return {};
  // Companion matrix of the monic polynomial z^n + a_1 z^(n−1) + … + a_n.
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) c(0, j) = -m.a[static_cast<std::size_t>(j)];
  for (int i = 1; i < n; ++i) c(i, i - 1) = 1.0;
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(c, false);
  std::vector<std::complex<double>> out(solver.eigenvalues().begin(), solver.eigenvalues().end());
  std::sort(out.begin(), out.end(), [](auto x, auto y) { return std::abs(x) > std::abs(y); });
  return out;
}

double spectral_radius(const OeModel& m) {
  const auto p = poles(m);
  return p.empty() ? 0.0 : std::abs(p.front());
}

bool is_stable(const OeModel& m) {
  return spectral_radius(m) < 1.0;
}

void require_stable(const OeModel& m) {
  const auto p = poles(m);
  if (p.empty() || std::abs(p.front()) < 1.0) return;
  const auto z = p.front();
  const double f = std::abs(std::arg(z)) * m.sample_rate / (2.0 * M_PI);
  fail(
      "model '{}' is unstable: pole z = {:.5f}{:+.5f}i has |z| = {:.5f} ≥ 1 ({}); its response "
      "grows without bound (use --stabilize to reflect unstable poles inside the unit circle, or "
      "--force to simulate anyway)",
      m.name, z.real(), z.imag(), std::abs(z),
      z.imag() == 0.0 ? std::string("a real pole") : fmt::format("an oscillation at {:.2f} Hz", f));
}

OeModel stabilized(const OeModel& m) {
  OeModel out = m;
  auto p = poles(m);
  bool changed = false;
  for (auto& z : p)
    if (std::abs(z) >= 1.0) {
      z = 1.0 / std::conj(z);
      changed = true;
    }
  if (!changed) return out;
  // Rebuild the monic polynomial from its roots.
  std::vector<std::complex<double>> c{1.0};
  for (const auto& z : p) {
    std::vector<std::complex<double>> next(c.size() + 1, 0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
      next[i] += c[i];
      next[i + 1] -= z * c[i];
    }
    c = next;
  }
  for (int j = 0; j < m.na(); ++j)
    out.a[static_cast<std::size_t>(j)] = c[static_cast<std::size_t>(j) + 1].real();
  // Keep the steady-state gain B(1)/A(1) of the original.
  double a1_old = 1.0, a1_new = 1.0;
  for (int j = 0; j < m.na(); ++j) {
    a1_old += m.a[static_cast<std::size_t>(j)];
    a1_new += out.a[static_cast<std::size_t>(j)];
  }
  if (std::abs(a1_old) > 1e-12)
    for (double& bj : out.b) bj *= a1_new / a1_old;
  out.name = m.name + " (stabilized)";
  return out;
}

std::vector<double> simulate(const OeModel& m, const std::vector<double>& u) {
  const std::size_t n = u.size();
  std::vector<double> y(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    double v = 0.0;
    for (int j = 1; j <= m.na(); ++j)
      if (k >= static_cast<std::size_t>(j))
        v -= m.a[static_cast<std::size_t>(j - 1)] * y[k - static_cast<std::size_t>(j)];
    for (int j = 1; j <= m.nb(); ++j) {
      const long idx = static_cast<long>(k) - m.nd - j + 1;
      if (idx >= 0) v += m.b[static_cast<std::size_t>(j - 1)] * u[static_cast<std::size_t>(idx)];
    }
    y[k] = v;
  }
  return y;
}

OeModel rat_single_cell() {
  return {"rat-single-cell",
          {-0.2264, -0.7116, -0.7817, 0.5265, 0.1942},
          {-0.2392},
          52,
          200.0,
          "mM",
          "a.u."};
}
OeModel rat_eog() {
  return {"rat-eog",
          {-2.0612, 1.2455, -1.8707, 3.2592, -1.7635, 1.3074, -2.0357, 0.9192},
          {-0.0629, 0.0515},
          50,
          200.0,
          "uM",
          "a.u."};
}
OeModel dog_eog() {
  return {"dog-eog",
          {-1.8212, -0.3223, 0.4379, 3.2789, -2.4238, -0.8460, -0.3558, 1.7538, -0.7016},
          {-0.0087, 0.0306, 0.0297, -0.0794},
          11,
          200.0,
          "uM",
          "a.u."};
}
std::vector<OeModel> presets() {
  return {rat_single_cell(), rat_eog(), dog_eog()};
}

OeModel preset(const std::string& name) {
  for (auto& m : presets())
    if (m.name == name) return m;
  fail(
      "unknown model preset '{}' (presets: rat-single-cell, rat-eog, dog-eog; or give a model "
      "YAML file)",
      name);
}

}  // namespace naris::olfaction
