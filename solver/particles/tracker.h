#pragma once
// One particle from its release to its fate (docs/method/particles.md).
//
// Massless tracers: dx/dt = u(x), Dormand–Prince RK45 in time with error control. Inertial
// particles: (x, u_p) with the drag of particle_physics.h, integrated exponentially: over a
// step the fluid velocity varies linearly in time between its values at the two ends (the
// end predicted with the velocity held, which is the embedded first-order solution and gives the
// error estimate), so the drag's own time scale τ never limits the step and a uniform flow is
// integrated exactly. Either way a step moves at most a fraction of the local cell size, and
// the chord of every accepted step is walked through the mesh: the boundary face it meets is
// the particle's fate (an inertial particle deposits when its centre comes within d/2 of a
// wall face). Patches "inlet" and "outlet" are open; every other patch is a wall.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mesh/patches/section_planes.h"
#include "solver/particles/flow_domain.h"
#include "solver/particles/particle_physics.h"

namespace naris::particles {

enum class Fate { outlet, inlet, wall, max_time, stagnated, lost };

inline constexpr int kFates = 6;
const char* fate_name(Fate fate);

// A plane whose crossings are recorded (m; the normal is unit).
struct Plane {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();
};

struct TraceOptions {
  double tolerance = 1e-4;        // local position error per step, in cell sizes
  double max_step = 0.5;          // cell sizes a step may move
  double max_time = 1.0;          // s
  double stagnation_speed = 0.0;  // m/s: a particle slower than this (and its air) stagnates
  double path_spacing = 1e-3;     // m between recorded path points
  Vec3 gravity = Vec3::Zero();    // m/s²
  DragLaw drag = DragLaw::schiller_naumann;
  Air air;
  long max_steps = 10'000'000;
  // Boxes (lo, hi) whose visits are recorded: bit i of ParticleResult::visited.
  std::vector<std::array<Vec3, 2>> regions;
};

struct ParticleStart {
  Vec3 x = Vec3::Zero();
  std::optional<Vec3> velocity;  // of an inertial particle; without it, the air's at x
  int cell = -1;                 // holding x
};

struct Crossing {
  int plane = 0;
  Vec3 x = Vec3::Zero();
  double time = 0.0;
};

struct PathPoint {
  Vec3 x = Vec3::Zero();
  double time = 0.0, speed = 0.0;
};

struct ParticleResult {
  Fate fate = Fate::lost;
  int patch = -1;               // the boundary patch met (outlet, inlet, wall)
  double time = 0.0;            // residence time (s)
  double length = 0.0;          // path length (m)
  Vec3 end = Vec3::Zero();      // where it ended (centre)
  Vec3 contact = Vec3::Zero();  // a deposited particle's point on the wall
  Vec3 end_velocity = Vec3::Zero();
  long steps = 0, rejected = 0, cell_tests = 0;
  std::uint32_t visited = 0;  // the regions passed through
  std::vector<Crossing> crossings;
  std::vector<PathPoint> path;  // empty unless asked for
};

ParticleResult track(const FlowDomain& flow, const ParticleStart& start, const ParticleKind& kind,
                     const TraceOptions& options, std::span<const Plane> planes, bool record_path);

}  // namespace naris::particles
