#pragma once
// The motion of a small sphere in air: Stokes drag with the Schiller–Naumann correction and
// the Cunningham slip correction, gravity with buoyancy (docs/method/particles.md).
//
//   du_p/dt = f(Re_p) (u − u_p) / τ + g (1 − ρ/ρ_p),   τ = ρ_p d² C_c / (18 μ),
//   f = 1 + 0.15 Re_p^0.687 (Schiller–Naumann; 1 for Stokes drag),   Re_p = ρ |u − u_p| d / μ,
//   C_c = 1 + Kn (1.257 + 0.4 e^(−1.1/Kn)),   Kn = 2λ/d.
#include <string>

namespace naris::particles {

// Air at 20 °C unless the solution says otherwise.
struct Air {
  double density = 1.204;            // kg/m³
  double viscosity = 1.81e-5;        // Pa·s
  double mean_free_path = 0.066e-6;  // m
};

enum class DragLaw { stokes, schiller_naumann };
DragLaw parse_drag_law(const std::string& text);  // "stokes" or "schiller-naumann"

// A particle species; diameter 0 is a massless tracer.
struct ParticleKind {
  double diameter = 0.0;                           // m
  double density = 1000.0;                         // kg/m³
  bool tracer() const { return diameter == 0.0; }  // whatever the density
};

double cunningham_factor(double diameter, double mean_free_path);
// τ (s), including the slip correction.
double relaxation_time(const ParticleKind& kind, const Air& air);
// f(Re_p): the drag over Stokes drag.
double drag_factor(DragLaw law, double particle_reynolds);
// The settling speed in still air under gravity g (m/s²), Stokes regime: τ g (1 − ρ/ρ_p).
double settling_speed(const ParticleKind& kind, const Air& air, double g);

}  // namespace naris::particles
