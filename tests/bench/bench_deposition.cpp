// Inertial impaction in a 90° bend against Pui, Romay-Novas & Liu (1987), laminar (VERIFICATION.md
// §6): a tube of diameter D bent at R_b = 5.7 D/2, meshed by MVE from the sampled torus at
// several resolutions, the steady laminar flow solved by naris at Re 1000 with a developed inlet
// profile, flux-weighted particles, Stokes drag. Stk = ρ_p d² C_c Ū / (9 μ D) = τ Ū / (D/2).
// Prints one row per resolution and Stokes number, with the correlation read with this Stk and
// with τŪ/D (VERIFICATION.md's convention, half of it). With --uniform-inlet the air enters the
// bend with a flat profile instead (a bend fed by a short straight tube). With --inlet-tube L a
// straight tube of L diameters feeds the bend, the developed profile entering the tube, and only
// deposits in the bend count. --diameter sets the
// particles' diameter in µm (2 by default: d/D = 0.002 as in Pui's tubes; the density follows
// from Stk), in a tube 1 mm across, since deposition reaches d/2 from the wall.
// For the comparison with another solver (tests/bench/bend_openfoam.sh): --binary meshes the
// tube's 0/1 indicator, as from a labelmap (isopoints at edge midpoints: a chamfered wall
// whose cells OpenFOAM accepts, where the signed distance leaves slivers); --write-msh FILE
// writes the (last) mesh in Gmsh 2.2; --field FILE traces through the velocities it lists
// (one node per line, in units of Ū, in the mesh's node order) instead of solving.
// --drag schiller-naumann drags the particles by Schiller–Naumann instead of Stokes, at the
// experiment's scale: air at Re 1000 in the 1 mm tube (Ū ≈ 15 m/s), so that the particle
// Reynolds numbers are those of Pui's laminar runs (0.6–3.9 at d/D = 0.002); Stk keeps its
// Stokes τ.
//
//   bench_deposition [--uniform-inlet] [--inlet-tube L] [--diameter µm] [--binary]
//                    [--drag LAW] [--write-msh FILE] [--field FILE]
//                    [particles = 10000] [cells across D ...]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "mesh/io/write_gmsh.h"
#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/ns/boundary_conditions.h"
#include "solver/parallel/petsc.h"
#include "solver/particles/mesh_flow.h"
#include "solver/particles/release.h"
#include "solver/particles/tracker.h"
#include "tests/solver/meshes.h"

using namespace naris;
using namespace naris::particles;

namespace {

// One velocity per line, three numbers each.
std::vector<Vec3> read_velocities(const std::string& path) {
  std::vector<Vec3> u;
  if (std::FILE* f = std::fopen(path.c_str(), "r")) {
    Vec3 v;
    while (std::fscanf(f, "%lf %lf %lf", &v[0], &v[1], &v[2]) == 3) u.push_back(v);
    std::fclose(f);
  }
  return u;
}

}  // namespace

int main(int argc, char** argv) {
  petsc::Session session;
  set_verbosity(Verbosity::quiet);
  bool uniform = false, binary = false;
  DragLaw drag = DragLaw::stokes;
  double diameter = 2e-6, inlet_tube = 0.0;
  std::string write_msh, field_file;
  std::vector<int> numbers;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--uniform-inlet")
      uniform = true;
    else if (arg == "--drag" && i + 1 < argc) {
      try {
        drag = parse_drag_law(argv[++i]);
      } catch (const Error& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
      }
    } else if (arg == "--binary")
      binary = true;
    else if (arg == "--diameter" && i + 1 < argc)
      diameter = std::atof(argv[++i]) * 1e-6;
    else if (arg == "--write-msh" && i + 1 < argc)
      write_msh = argv[++i];
    else if (arg == "--field" && i + 1 < argc)
      field_file = argv[++i];
    else if (arg == "--inlet-tube" && i + 1 < argc)
      inlet_tube = std::atof(argv[++i]);
    else
      numbers.push_back(std::atoi(argv[i]));
  }
  const int n = numbers.empty() ? 10000 : numbers.front();
  std::vector<int> resolutions(numbers.begin() + (numbers.empty() ? 0 : 1), numbers.end());
  if (resolutions.empty()) resolutions = {14, 20, 28};
  auto pui = [](double stokes) {  // the correlation at θ = π/2
    const double q = stokes / 0.171;
    return 1.0 - std::pow(1.0 + std::pow(q, 0.452 * q + 2.242), -1.0);
  };
  // Lengths in units of D (read as millimetres), the velocity in units of Ū (read as m/s).
  const double a = 0.5, bend = 2.85, re = 1000.0;
  TraceOptions o;
  o.drag = drag;
  // The mean speed in m/s: 1 under Stokes drag (only τŪ matters), else Re ν / D.
  const double mean_speed =
      drag == DragLaw::stokes ? 1.0 : re * o.air.viscosity / (o.air.density * 2.0 * a * 1e-3);
  std::printf(
      "| cells across D | cells | Stk = τŪ/(D/2) | deposited | Pui et al., this Stk | difference | "
      "Pui et al., Stk = τŪ/D | difference | particles | lost | trace (s) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int across : resolutions) {
    mve::MveOptions options;
    options.side_patch[0] = "outlet";
    options.side_patch[2] = "inlet";
    // The torus for y ≥ 0; below, the straight tube that feeds it along y.
    auto s = [&](const Vec3& x) {
      return x[1] >= 0.0 ? std::hypot(std::hypot(x[0], x[1]) - bend, x[2])
                         : std::hypot(x[0] - bend, x[2]);
    };
    const HybridMesh m = testing::mve_mesh_box(
        [&](const Vec3& x) { return binary ? (s(x) < a ? 0.5 : -0.5) : a - s(x); },
        {0.0, -inlet_tube, -0.6}, {3.5, 3.5, 0.6}, 1.0 / across, options);
    if (!write_msh.empty()) write_gmsh22(m, write_msh);
    const ns::DirichletConditions bc = ns::airflow_conditions(
        m, uniform ? ns::InletProfile::uniform : ns::InletProfile::developed, 1.0);
    ns::FlowField field;
    if (!field_file.empty()) {
      field.velocity = read_velocities(field_file);
      if (field.velocity.size() != m.nodes.size()) {
        std::fprintf(stderr, "%s lists %zu velocities for a mesh of %zu nodes\n",
                     field_file.c_str(), field.velocity.size(), m.nodes.size());
        return 1;
      }
    } else {
      for (double step : {100.0, 300.0, 600.0, re}) {
        nonlinear::NonlinearReport report;
        const ns::FlowField earlier = field;
        field = nonlinear::solve_navier_stokes(m, ns::FlowProblem{step, {}, bc}, {}, &report,
                                               step == 100.0 ? nullptr : &earlier);
        if (!report.converged) {
          std::fprintf(stderr, "the bend's flow did not converge at Re %g\n", step);
          return 1;
        }
      }
    }
    for (Vec3& u : field.velocity) u *= mean_speed;
    const MeshFlow flow(m, field.velocity, {m.patch_id("inlet"), m.patch_id("outlet")});
    const ReleaseSet seeds = flux_weighted_release(m, m.patch_id("inlet"), field.velocity, n, 1987);
    for (double stk : {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 1.0}) {
      const double d = diameter, cc = cunningham_factor(d, o.air.mean_free_path);
      const double tau = stk * a * 1e-3 / mean_speed;
      const ParticleKind kind{d, 18.0 * o.air.viscosity * tau / (d * d * cc)};
      Stopwatch clock;
      int counts[kFates] = {}, in_bend = 0;
      for (const Vec3& x : seeds.points) {
        const ParticleResult r = track(flow, {x, std::nullopt, flow.locate(x)}, kind, o, {}, false);
        ++counts[static_cast<int>(r.fate)];
        in_bend += r.fate == Fate::wall && r.contact[1] >= 0.0;
      }
      const double eta = in_bend / double(n);
      std::printf("| %d | %zu | %.1f | %.3f | %.3f | %+.3f | %.3f | %+.3f | %d | %d | %.1f |\n",
                  across, m.cell_count(), stk, eta, pui(stk), eta - pui(stk), pui(0.5 * stk),
                  eta - pui(0.5 * stk), n, counts[static_cast<int>(Fate::lost)], clock.seconds());
      std::fflush(stdout);
    }
  }
}
