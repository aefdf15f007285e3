#pragma once
// Analytic flows for the tracker tests: uniform flow and solid-body rotation in unbounded space,
// and Hagen–Poiseuille flow in a pipe along z from 0 (inlet) to its length (outlet), the wall at
// radius R.
#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/particles/flow_domain.h"

namespace naris::testing {

using particles::Passage;
using particles::Vec3;

class UniformFlow : public particles::FlowDomain {
 public:
  explicit UniformFlow(const Vec3& u) : u_(u) {}
  Vec3 velocity(const Vec3&, int&, const Vec3&) const override { return u_; }
  Passage pass(const Vec3&, const Vec3&, int&, double) const override { return {}; }
  double cell_size(int) const override { return 1.0; }
  int locate(const Vec3&) const override { return 0; }
  const std::vector<std::string>& patch_names() const override { return names_; }

 private:
  Vec3 u_;
  std::vector<std::string> names_;
};

// u = Ω ẑ × x: the air turns about the z axis at Ω; `cell` is the length a step resolves.
class SolidBodyRotation : public particles::FlowDomain {
 public:
  SolidBodyRotation(double omega, double cell) : omega_(omega), cell_(cell) {}
  Vec3 velocity(const Vec3&, int&, const Vec3& x) const override {
    return {-omega_ * x[1], omega_ * x[0], 0.0};
  }
  Passage pass(const Vec3&, const Vec3&, int&, double) const override { return {}; }
  double cell_size(int) const override { return cell_; }
  int locate(const Vec3&) const override { return 0; }
  const std::vector<std::string>& patch_names() const override { return names_; }

 private:
  double omega_, cell_;
  std::vector<std::string> names_;
};

class PoiseuillePipe : public particles::FlowDomain {
 public:
  PoiseuillePipe(double radius, double length, double mean_speed)
      : r_(radius), l_(length), mean_(mean_speed) {}
  Vec3 velocity(const Vec3&, int&, const Vec3& x) const override {
    const double s = (x[0] * x[0] + x[1] * x[1]) / (r_ * r_);
    return {0.0, 0.0, 2.0 * mean_ * std::max(0.0, 1.0 - s)};
  }
  Passage pass(const Vec3& a, const Vec3& b, int&, double radius) const override {
    Passage p;
    const Vec3 d = b - a;
    auto take = [&](double t, int patch, const Vec3& n) {
      if (t >= 0.0 && t <= 1.0 && t < p.t) p = {true, t, patch, n, 1};
    };
    if (d[2] > 0.0) take((l_ - a[2]) / d[2], 1, Vec3::UnitZ());
    if (d[2] < 0.0) take(-a[2] / d[2], 0, -Vec3::UnitZ());
    // |a + t d|² = (R − radius)² in the plane, the outward root.
    const double rr = r_ - radius, qa = d[0] * d[0] + d[1] * d[1],
                 qb = 2.0 * (a[0] * d[0] + a[1] * d[1]), qc = a[0] * a[0] + a[1] * a[1] - rr * rr;
    if (qa > 0.0) {
      const double disc = qb * qb - 4.0 * qa * qc;
      if (disc >= 0.0) {
        const double t = (-qb + std::sqrt(disc)) / (2.0 * qa);
        const Vec3 x = a + t * d;
        take(std::max(t, 0.0), 2, Vec3(x[0], x[1], 0.0).normalized());
      }
    }
    if (!p.left) p.t = 1.0;
    return p;
  }
  double cell_size(int) const override { return r_ / 10.0; }
  int locate(const Vec3&) const override { return 0; }
  const std::vector<std::string>& patch_names() const override { return names_; }

 private:
  double r_, l_, mean_;
  std::vector<std::string> names_{"inlet", "outlet", "wall"};
};

}  // namespace naris::testing
