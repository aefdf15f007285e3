#include "solver/continuation/arclength.h"

#include <cmath>

namespace naris::continuation {

double aim_along_secant(nonlinear::ArclengthConstraint& c, const ns::FlowField& from,
                        double re_from, const ns::FlowField& to, double re_to,
                        const InnerProduct& inner) {
  c.tangent = to;
  for (std::size_t k = 0; k < to.pressure.size(); ++k) {
    c.tangent.velocity[k] -= from.velocity[k];
    c.tangent.pressure[k] -= from.pressure[k];
  }
  c.tangent_reynolds = re_to - re_from;
  const double length = std::sqrt(inner(c.tangent, c.tangent) +
                                  c.tangent_reynolds * c.tangent_reynolds / (re_to * re_to));
  for (std::size_t k = 0; k < to.pressure.size(); ++k) {
    c.tangent.velocity[k] /= length;
    c.tangent.pressure[k] /= length;
  }
  c.tangent_reynolds /= length;
  return length;
}

ns::FlowField arclength_predictor(const nonlinear::ArclengthConstraint& c) {
  ns::FlowField guess = c.origin;
  for (std::size_t k = 0; k < guess.pressure.size(); ++k) {
    guess.velocity[k] += c.step * c.tangent.velocity[k];
    guess.pressure[k] += c.step * c.tangent.pressure[k];
  }
  return guess;
}

ns::FlowField blend(const ns::FlowField& a, const ns::FlowField& b, double t) {
  ns::FlowField out = a;
  for (std::size_t k = 0; k < out.pressure.size(); ++k) {
    out.velocity[k] += t * (b.velocity[k] - a.velocity[k]);
    out.pressure[k] += t * (b.pressure[k] - a.pressure[k]);
  }
  return out;
}

}  // namespace naris::continuation
