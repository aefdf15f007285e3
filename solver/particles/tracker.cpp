#include "solver/particles/tracker.h"

#include <algorithm>
#include <cmath>

namespace naris::particles {
namespace {

// Dormand & Prince (1980), RK5(4)7M: the nodes, the stages and the error weights b − b̂.
constexpr double kC[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
constexpr double kA[7][6] = {
    {},
    {1.0 / 5},
    {3.0 / 40, 9.0 / 40},
    {44.0 / 45, -56.0 / 15, 32.0 / 9},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
    {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
constexpr double kE[7] = {71.0 / 57600,      0.0,        -71.0 / 16695, 71.0 / 1920,
                          -17253.0 / 339200, 22.0 / 525, -1.0 / 40};

struct Step {
  Vec3 x, v, u;  // the new position, particle velocity and air velocity there
  double error;  // in units of the tolerance
};

// A tracer's step from x (air velocity u there, in `cell`).
Step tracer_step(const FlowDomain& flow, const Vec3& x, const Vec3& u, int cell, double h,
                 double tolerance) {
  Vec3 k[7];
  k[0] = u;
  for (int s = 1; s < 7; ++s) {
    Vec3 y = x;
    for (int j = 0; j < s; ++j) y += h * kA[s][j] * k[j];
    int c = cell;
    k[s] = flow.velocity(x, c, y);
  }
  Vec3 x5 = x, e = Vec3::Zero();
  for (int j = 0; j < 6; ++j) x5 += h * kA[6][j] * k[j];  // b₇ = 0
  for (int j = 0; j < 7; ++j) e += h * kE[j] * k[j];
  return {x5, k[6], k[6], e.norm() / tolerance};
}

// An inertial particle's step (exponential integration of the drag; see tracker.h).
Step inertial_step(const FlowDomain& flow, const Vec3& x, const Vec3& v, const Vec3& u, int cell,
                   double h, double tau, const Vec3& g, const ParticleKind& kind,
                   const TraceOptions& o, double tolerance) {
  const double re_scale = o.air.density * kind.diameter / o.air.viscosity;
  // Held air velocity: the first-order end point.
  const double te1 = tau / drag_factor(o.drag, re_scale * (u - v).norm());
  const double decay1 = -std::expm1(-h / te1);
  const Vec3 w = u + g * te1;
  const Vec3 x1 = x + w * h + (v - w) * (te1 * decay1);
  const Vec3 v1 = w + (v - w) * (1.0 - decay1);
  int c = cell;
  const Vec3 u1 = flow.velocity(x, c, x1);
  // Air velocity linear in time from u to u1.
  const Vec3 s = (u1 - u) / h;
  const double te = tau / drag_factor(o.drag, re_scale * 0.5 * (u + u1 - v - v1).norm());
  const double decay = -std::expm1(-h / te);
  const Vec3 base = u + (g - s) * te;
  const Vec3 C = v - base;
  const Vec3 x2 = x + base * h + 0.5 * h * h * s + C * (te * decay);
  const Vec3 v2 = base + s * h + C * (1.0 - decay);
  return {x2, v2, Vec3::Zero(), (x2 - x1).norm() / tolerance};
}

Fate fate_of_patch(const FlowDomain& flow, int patch) {
  if (patch < 0) return Fate::lost;
  const std::string& name = flow.patch_names()[static_cast<std::size_t>(patch)];
  if (!is_open_patch(name)) return Fate::wall;
  return name == "outlet" ? Fate::outlet : Fate::inlet;
}

void record_crossings(std::span<const Plane> planes, const Vec3& a, const Vec3& b, double ta,
                      double tb, std::vector<Crossing>& out) {
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const double sa = planes[i].normal.dot(a - planes[i].point);
    const double sb = planes[i].normal.dot(b - planes[i].point);
    if ((sa < 0.0) == (sb < 0.0)) continue;
    const double f = sa / (sa - sb);
    out.push_back({static_cast<int>(i), a + f * (b - a), ta + f * (tb - ta)});
  }
}

}  // namespace

const char* fate_name(Fate fate) {
  switch (fate) {
    case Fate::outlet:
      return "outlet";
    case Fate::inlet:
      return "inlet";
    case Fate::wall:
      return "wall";
    case Fate::max_time:
      return "max-time";
    case Fate::stagnated:
      return "stagnated";
    case Fate::lost:
      return "lost";
  }
  return "lost";
}

ParticleResult track(const FlowDomain& flow, const ParticleStart& start, const ParticleKind& kind,
                     const TraceOptions& o, std::span<const Plane> planes, bool record_path) {
  ParticleResult r;
  const bool tracer = kind.tracer();
  const double tau = tracer ? 0.0 : relaxation_time(kind, o.air);
  const double radius = tracer ? 0.0 : 0.5 * kind.diameter;
  const Vec3 g = tracer ? Vec3::Zero() : Vec3(o.gravity * (1.0 - o.air.density / kind.density));
  // Error estimates of order h⁵ (tracers) and h² (the exponential step).
  const double exponent = tracer ? 0.2 : 0.5;

  int cell = start.cell;
  Vec3 x = start.x;
  Vec3 u = flow.velocity(x, cell, x);
  Vec3 v = tracer ? u : start.velocity.value_or(u);
  double t = 0.0, h = 0.0;
  int failures = 0;  // consecutive steps that had to be retried for a failure
  Vec3 last_recorded = x;
  auto record = [&](bool always) {
    if (!record_path) return;
    if (!always && (x - last_recorded).norm() < o.path_spacing) return;
    r.path.push_back({x, t, v.norm()});
    last_recorded = x;
  };
  record(true);
  auto finish = [&](Fate fate) {
    r.fate = fate;
    r.time = t;
    r.end = x;
    r.end_velocity = v;
    if (record_path && (r.path.empty() || r.path.back().time != t))
      r.path.push_back({x, t, v.norm()});
  };
  // Halves the step after a failure; after 60 in a row the particle is lost (false).
  auto retry_shorter = [&] {
    if (++failures > 60) {
      finish(Fate::lost);
      return false;
    }
    h *= 0.5;
    ++r.rejected;
    return true;
  };
  for (;;) {
    const double speed = std::max(u.norm(), v.norm());
    if (o.stagnation_speed > 0.0 && speed < o.stagnation_speed) {
      finish(Fate::stagnated);
      return r;
    }
    if (t >= o.max_time || r.steps >= o.max_steps) {
      finish(Fate::max_time);
      return r;
    }
    const double size = flow.cell_size(cell);
    const double h_max = speed > 0.0 ? o.max_step * size / speed : o.max_time;
    if (h == 0.0) h = 0.1 * h_max;
    h = std::min({h, h_max, o.max_time - t});
    const double tolerance = o.tolerance * size;
    const Step s = tracer ? tracer_step(flow, x, u, cell, h, tolerance)
                          : inertial_step(flow, x, v, u, cell, h, tau, g, kind, o, tolerance);
    // A step that produced no number (a degenerate cell's inverse map) is retried shorter.
    if (!std::isfinite(s.error) || !s.x.allFinite() || !s.v.allFinite()) {
      if (!retry_shorter()) return r;
      continue;
    }
    if (s.error > 1.0 && h > 1e-9 * h_max) {
      h *= std::max(0.2, 0.9 * std::pow(s.error, -exponent));
      ++r.rejected;
      continue;
    }
    int next = cell;
    const Passage p = flow.pass(x, s.x, next, radius);
    r.cell_tests += p.cell_tests;
    // A walk that circled along a face or an edge: a shorter chord takes another way.
    if (p.stuck) {
      if (!retry_shorter()) return r;
      continue;
    }
    failures = 0;
    // A chord that meets a wall may only cut a corner the path itself rounds: the contact
    // counts once a step of a thousandth of the cell confirms it.
    if (p.left && fate_of_patch(flow, p.patch) == Fate::wall && h * speed > 1e-3 * size) {
      h *= 0.5;
      ++r.rejected;
      continue;
    }
    ++r.steps;
    if (p.left) {
      const Vec3 end = x + p.t * (s.x - x);
      record_crossings(planes, x, end, t, t + p.t * h, r.crossings);
      r.length += (end - x).norm();
      t += p.t * h;
      x = end;
      v = (1.0 - p.t) * v + p.t * s.v;
      r.patch = p.patch;
      r.contact = x + radius * p.normal;
      finish(fate_of_patch(flow, p.patch));
      return r;
    }
    record_crossings(planes, x, s.x, t, t + h, r.crossings);
    r.length += (s.x - x).norm();
    x = s.x;
    v = s.v;
    t += h;
    cell = next;
    u = tracer ? s.u : flow.velocity(x, cell, x);
    if (tracer) v = u;
    record(false);
    for (std::size_t i = 0; i < o.regions.size() && i < 32; ++i)
      if ((x.array() >= o.regions[i][0].array()).all() &&
          (x.array() <= o.regions[i][1].array()).all())
        r.visited |= 1u << i;
    h *= std::min(5.0, 0.9 * std::pow(std::max(s.error, 1e-12), -exponent));
  }
}

}  // namespace naris::particles
