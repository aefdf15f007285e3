#include "postproc/planes/outline.h"

#include <algorithm>
#include <cmath>

namespace naris::planes {

double loop_length(const Loop& loop) {
  double length = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i)
    length += (loop[(i + 1) % loop.size()] - loop[i]).norm();
  return length;
}

double smoothed_loop_length(const Loop& loop, double sigma) {
  const double length = loop_length(loop);
  if (loop.size() < 3 || !(length > 0.0)) return length;
  sigma = std::min(sigma, length / 16.0);
  if (!(sigma > 0.0)) return length;
  // Resample at a quarter of σ along the loop.
  const int n = std::max(64, static_cast<int>(std::ceil(4.0 * length / sigma)));
  const double ds = length / n;
  std::vector<Eigen::Vector3d> p(static_cast<std::size_t>(n));
  std::size_t edge = 0;
  double edge_start = 0.0, edge_length = (loop[1] - loop[0]).norm();
  for (int i = 0; i < n; ++i) {
    const double s = i * ds;
    while (edge + 1 < loop.size() && s > edge_start + edge_length) {
      edge_start += edge_length;
      ++edge;
      edge_length = (loop[(edge + 1) % loop.size()] - loop[edge]).norm();
    }
    const double t = edge_length > 0.0 ? std::clamp((s - edge_start) / edge_length, 0.0, 1.0) : 0.0;
    p[static_cast<std::size_t>(i)] = (1.0 - t) * loop[edge] + t * loop[(edge + 1) % loop.size()];
  }
  // Gaussian weights to 4σ (at most half the loop).
  const int half = std::min(n / 2 - 1, static_cast<int>(std::ceil(4.0 * sigma / ds)));
  std::vector<double> w(static_cast<std::size_t>(half) + 1);
  double total = 0.0;
  for (int k = 0; k <= half; ++k) {
    w[static_cast<std::size_t>(k)] = std::exp(-0.5 * std::pow(k * ds / sigma, 2));
    total += (k == 0 ? 1.0 : 2.0) * w[static_cast<std::size_t>(k)];
  }
  std::vector<Eigen::Vector3d> q(p.size());
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d sum = w[0] * p[static_cast<std::size_t>(i)];
    for (int k = 1; k <= half; ++k)
      sum += w[static_cast<std::size_t>(k)] * (p[static_cast<std::size_t>((i + k) % n)] +
                                               p[static_cast<std::size_t>((i - k + n) % n)]);
    q[static_cast<std::size_t>(i)] = sum / total;
  }
  return loop_length(q);
}

}  // namespace naris::planes
