#include "solver/particles/particle_physics.h"

#include <cmath>

#include "core/error.h"

namespace naris::particles {

DragLaw parse_drag_law(const std::string& text) {
  if (text == "stokes") return DragLaw::stokes;
  if (text == "schiller-naumann") return DragLaw::schiller_naumann;
  fail("unknown drag law '{}' (stokes or schiller-naumann)", text);
}

double cunningham_factor(double diameter, double mean_free_path) {
  const double kn = 2.0 * mean_free_path / diameter;
  return 1.0 + kn * (1.257 + 0.4 * std::exp(-1.1 / kn));
}

double relaxation_time(const ParticleKind& kind, const Air& air) {
  const double d = kind.diameter;
  return kind.density * d * d * cunningham_factor(d, air.mean_free_path) / (18.0 * air.viscosity);
}

double drag_factor(DragLaw law, double particle_reynolds) {
  if (law == DragLaw::stokes) return 1.0;
  return 1.0 + 0.15 * std::pow(particle_reynolds, 0.687);
}

double settling_speed(const ParticleKind& kind, const Air& air, double g) {
  return relaxation_time(kind, air) * g * (1.0 - air.density / kind.density);
}

}  // namespace naris::particles
