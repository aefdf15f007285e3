#include "postproc/olfaction/identify.h"

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>

#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"

namespace naris::olfaction {
namespace {

// Filters x by 1/A(q): w(k) = x(k) − Σ a_j w(k−j).
void inverse_a(const std::vector<double>& a, const std::vector<double>& x, std::vector<double>& w) {
  w.resize(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    double v = x[k];
    for (std::size_t j = 1; j <= a.size() && j <= k; ++j) v -= a[j - 1] * w[k - j];
    w[k] = v;
  }
}

double cost(const std::vector<double>& y, const std::vector<double>& yhat) {
  double s = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) s += (y[k] - yhat[k]) * (y[k] - yhat[k]);
  return s;
}

// Least-squares ARX: y(k) + Σ a_j y(k−j) = Σ b_j u(k−nd−j+1) + e(k).
OeModel fit_arx(const std::vector<double>& u, const std::vector<double>& y, int na, int nb,
                int nd) {
  const int p = na + nb;
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(p);
  Eigen::VectorXd phi(p);
  const long start = std::max<long>(na, nd + nb - 1);
  for (long k = start; k < static_cast<long>(y.size()); ++k) {
    for (int j = 1; j <= na; ++j) phi[j - 1] = -y[static_cast<std::size_t>(k - j)];
    for (int j = 1; j <= nb; ++j) phi[na + j - 1] = u[static_cast<std::size_t>(k - nd - j + 1)];
    normal.selfadjointView<Eigen::Lower>().rankUpdate(phi);
    rhs += phi * y[static_cast<std::size_t>(k)];
  }
  normal = normal.selfadjointView<Eigen::Lower>();
  normal.diagonal().array() += 1e-12 * (normal.diagonal().maxCoeff() + 1.0);
  const Eigen::VectorXd theta = normal.ldlt().solve(rhs);
  OeModel m;
  m.nd = nd;
  m.a.assign(theta.data(), theta.data() + na);
  m.b.assign(theta.data() + na, theta.data() + p);
  return m;
}

// Steiglitz–McBride: refit ARX on input and output prefiltered by 1/A of the previous estimate.
// For white output noise its fixed point is the OE estimate, so it gives Levenberg–Marquardt a
// start in the right basin where the plain (noise-biased) ARX start often does not.
OeModel steiglitz_mcbride(const std::vector<double>& u, const std::vector<double>& y, OeModel m,
                          int iterations) {
  std::vector<double> uf, yf;
  for (int it = 0; it < iterations; ++it) {
    if (!is_stable(m)) m = stabilized(m);
    inverse_a(m.a, u, uf);
    inverse_a(m.a, y, yf);
    OeModel next = fit_arx(uf, yf, m.na(), m.nb(), m.nd);
    const bool converged = [&] {
      double d = 0.0, n = 0.0;
      for (int j = 0; j < m.na(); ++j) {
        d += std::abs(next.a[static_cast<std::size_t>(j)] - m.a[static_cast<std::size_t>(j)]);
        n += std::abs(m.a[static_cast<std::size_t>(j)]);
      }
      return d <= 1e-9 * (n + 1.0);
    }();
    m = next;
    if (converged) break;
  }
  if (!is_stable(m)) m = stabilized(m);
  return m;
}

OeModel levenberg_marquardt(const std::vector<double>& u, const std::vector<double>& y, OeModel m,
                            const FitOptions& options, double& final_cost);

}  // namespace

double mean_square_error(const std::vector<double>& y, const std::vector<double>& yhat) {
  return y.empty() ? 0.0 : cost(y, yhat) / static_cast<double>(y.size());
}

double fit_percent(const std::vector<double>& y, const std::vector<double>& yhat) {
  double mean = 0.0;
  for (double v : y) mean += v;
  mean /= static_cast<double>(y.size());
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    num += (y[k] - yhat[k]) * (y[k] - yhat[k]);
    den += (y[k] - mean) * (y[k] - mean);
  }
  return den > 0.0 ? 100.0 * (1.0 - std::sqrt(num / den)) : 0.0;
}

OeModel fit_oe(const std::vector<double>& u, const std::vector<double>& y, int na, int nb, int nd,
               const FitOptions& options) {
  if (u.size() != y.size())
    fail("input and output records differ in length ({} and {})", u.size(), y.size());
  if (static_cast<long>(y.size()) <= 2L * (na + nb) + nd)
    fail("the record ({} samples) is too short for orders na={}, nb={}, nd={}", y.size(), na, nb,
         nd);
  OeModel arx = fit_arx(u, y, na, nb, nd);
  if (!is_stable(arx)) arx = stabilized(arx);
  // Two starts, the plain ARX estimate and its Steiglitz–McBride refinement; the better wins.
  double cost_arx = 0.0, cost_sm = 0.0;
  OeModel from_arx = levenberg_marquardt(u, y, arx, options, cost_arx);
  OeModel from_sm = levenberg_marquardt(u, y, steiglitz_mcbride(u, y, arx, 30), options, cost_sm);
  OeModel& best = cost_sm <= cost_arx ? from_sm : from_arx;
  best.name = "fitted";
  return best;
}

namespace {

OeModel levenberg_marquardt(const std::vector<double>& u, const std::vector<double>& y, OeModel m,
                            const FitOptions& options, double& final_cost) {
  const int na = m.na(), nb = m.nb(), nd = m.nd;
  const int p = na + nb;
  std::vector<double> yhat = simulate(m, u), trial_y, w, v;
  double current = cost(y, yhat);
  final_cost = current;
  double lambda = 1e-3;
  Eigen::MatrixXd jtj(p, p);
  Eigen::VectorXd jtr(p), row(p);
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    // Gradients of ŷ: ∂ŷ/∂a_j = −(1/A) ŷ(k−j), ∂ŷ/∂b_j = (1/A) u(k−nd−j+1).
    inverse_a(m.a, yhat, w);
    inverse_a(m.a, u, v);
    jtj.setZero();
    jtr.setZero();
    for (std::size_t k = 0; k < y.size(); ++k) {
      for (int j = 1; j <= na; ++j)
        row[j - 1] = k >= static_cast<std::size_t>(j) ? -w[k - static_cast<std::size_t>(j)] : 0.0;
      for (int j = 1; j <= nb; ++j) {
        const long idx = static_cast<long>(k) - nd - j + 1;
        row[na + j - 1] = idx >= 0 ? v[static_cast<std::size_t>(idx)] : 0.0;
      }
      jtj.selfadjointView<Eigen::Lower>().rankUpdate(row);
      jtr += row * (y[k] - yhat[k]);
    }
    jtj = jtj.selfadjointView<Eigen::Lower>();
    bool improved = false;
    for (int attempt = 0; attempt < 12 && !improved; ++attempt) {
      Eigen::MatrixXd damped = jtj;
      damped.diagonal().array() += lambda * (jtj.diagonal().array() + 1e-12);
      const Eigen::VectorXd step = damped.ldlt().solve(jtr);
      OeModel trial = m;
      for (int j = 0; j < na; ++j) trial.a[static_cast<std::size_t>(j)] += step[j];
      for (int j = 0; j < nb; ++j) trial.b[static_cast<std::size_t>(j)] += step[na + j];
      if (is_stable(trial)) {
        trial_y = simulate(trial, u);
        const double c = cost(y, trial_y);
        if (c < current) {
          const double decrease = (current - c) / std::max(current, 1e-300);
          m = trial;
          yhat.swap(trial_y);
          current = c;
          final_cost = c;
          lambda = std::max(lambda / 10.0, 1e-12);
          improved = true;
          if (decrease < options.tolerance) return m;
          continue;
        }
      }
      lambda *= 10.0;
    }
    if (!improved) break;
  }
  return m;
}

}  // namespace

OrderSearchResult search_orders(const std::vector<double>& u_fit, const std::vector<double>& y_fit,
                                const std::vector<double>& u_val, const std::vector<double>& y_val,
                                const OrderSearchOptions& o) {
  Stopwatch clock;
  struct Job {
    int na, nb, nd;
  };
  std::vector<Job> jobs;
  for (int na = 1; na <= o.max_na; ++na)
    for (int nb = 1; nb <= std::min(na, o.max_nb); ++nb)
      for (int nd = o.min_nd; nd <= o.max_nd; ++nd) jobs.push_back({na, nb, nd});
  if (jobs.empty()) fail("no model orders to search (check the order ranges)");
  if (u_fit.size() != y_fit.size() || u_val.size() != y_val.size())
    fail("stimulus and response records differ in length");
  const auto needed = static_cast<std::size_t>(2 * 2 + o.min_nd + 1);
  if (y_fit.size() <= needed || y_val.size() <= needed)
    fail(
        "the records ({} and {} samples after preprocessing) are too short for the orders "
        "searched (nd from {})",
        y_fit.size(), y_val.size(), o.min_nd);

  OrderSearchResult result;
  result.tried.resize(jobs.size());
  std::atomic<std::size_t> next{0};
  std::mutex best_lock;
  double best_mse = std::numeric_limits<double>::infinity();
  std::size_t best_index = jobs.size();
  std::vector<OeModel> models(jobs.size());
  Progress progress("orders", jobs.size());
  std::atomic<std::size_t> done{0};
  auto worker = [&] {
    for (std::size_t i; (i = next++) < jobs.size();) {
      const Job& j = jobs[i];
      OrderCandidate& c = result.tried[i];
      c = {j.na, j.nb, j.nd, std::numeric_limits<double>::infinity(), false};
      try {
        models[i] = fit_oe(u_fit, y_fit, j.na, j.nb, j.nd, o.fit);
        c.stable = is_stable(models[i]);
        if (c.stable) c.validation_mse = mean_square_error(y_val, simulate(models[i], u_val));
      } catch (const Error&) {
        continue;  // too short a record for these orders
      }
      std::lock_guard lock(best_lock);
      // The smallest validation error wins; among equals, the simpler model (earlier job).
      if (c.stable &&
          (c.validation_mse < best_mse || (c.validation_mse == best_mse && i < best_index))) {
        best_mse = c.validation_mse;
        best_index = i;
      }
      progress.update(++done);
    }
  };
  const unsigned threads = thread_count(o.threads);
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  progress.finish();
  if (best_index == jobs.size())
    fail(
        "no stable model could be fitted for any order (check that the input excites the "
        "response and that the records are aligned)");
  result.best = models[best_index];
  result.validation_mse = best_mse;
  result.validation_fit_percent = fit_percent(y_val, simulate(result.best, u_val));
  result.fit_fit_percent = fit_percent(y_fit, simulate(result.best, u_fit));
  result.seconds = clock.seconds();
  return result;
}

}  // namespace naris::olfaction
