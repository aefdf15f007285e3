#pragma once
// Output-error identification by the prediction-error method (dissertation 5.3): for an OE
// model the prediction error is the simulation error, minimized by Levenberg–Marquardt from a
// least-squares ARX start; orders (na, nb, nd) chosen by the mean-square error of the
// simulated response on a separate validation record.
#include <vector>

#include "postproc/olfaction/oe_model.h"

namespace naris::olfaction {

struct FitOptions {
  int max_iterations = 40;
  double tolerance = 1e-10;  // relative decrease of the cost that ends the iteration
};

// Fits one OE model of the given orders to input u and output y (same sampling).
OeModel fit_oe(const std::vector<double>& u, const std::vector<double>& y, int na, int nb, int nd,
               const FitOptions& options = {});

double mean_square_error(const std::vector<double>& y, const std::vector<double>& yhat);
// NRMSE fit: 100 (1 − ‖y − ŷ‖ / ‖y − mean(y)‖), in percent.
double fit_percent(const std::vector<double>& y, const std::vector<double>& yhat);

struct OrderSearchOptions {
  int max_na = 10, max_nb = 10, min_nd = 1, max_nd = 60;
  int threads = 0;  // 0: every core
  FitOptions fit;
};

struct OrderCandidate {
  int na = 0, nb = 0, nd = 0;
  double validation_mse = 0.0;
  bool stable = false;
};

struct OrderSearchResult {
  OeModel best;
  double validation_mse = 0.0;
  double validation_fit_percent = 0.0;
  double fit_fit_percent = 0.0;
  std::vector<OrderCandidate> tried;
  double seconds = 0.0;
};

// Every na ≤ max_na, nb ≤ min(na, max_nb), min_nd ≤ nd ≤ max_nd; unstable fits are skipped.
OrderSearchResult search_orders(const std::vector<double>& u_fit, const std::vector<double>& y_fit,
                                const std::vector<double>& u_val, const std::vector<double>& y_val,
                                const OrderSearchOptions& options = {});

}  // namespace naris::olfaction
