#include "ns/airflow_job.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/error.h"
#include "core/log.h"
#include "io/atomic_file.h"
#include "io/mesh_h5.h"
#include "io/write_vtk.h"
#include "ns/inlet_expression.h"
#include "ns/patch_integrals.h"
#include "ns/solution_file.h"
#include "ns/wall_stress.h"
#include "parallel/partition.h"
#include "patches/patches.h"
#include "quality/check.h"
#include "refine/subdivide.h"

namespace naris::ns {
namespace fs = std::filesystem;

namespace {

void check_job(const AirflowJob& job) {
  if (!(job.reynolds > 0.0) || !std::isfinite(job.reynolds))
    fail("the Reynolds number must be positive and finite (got {})", job.reynolds);
  if (job.inlet_speed && (!(*job.inlet_speed > 0.0) || !std::isfinite(*job.inlet_speed)))
    fail("the inlet speed must be positive and finite (got {} m/s)", *job.inlet_speed);
  if (!(job.viscosity > 0.0) || !std::isfinite(job.viscosity))
    fail("the viscosity must be positive and finite (got {} m²/s)", job.viscosity);
  if (!(job.density > 0.0) || !std::isfinite(job.density))
    fail("the density must be positive and finite (got {} kg/m³)", job.density);
  if (!(job.start_reynolds > 0.0)) fail("the starting Reynolds number must be positive");
  // A typo in the expression is an input error: caught here, before any output.
  if (job.profile == InletProfile::expression) (void)InletExpression(job.inlet_expression);
}

std::string profile_name(const AirflowJob& job) {
  switch (job.profile) {
    case InletProfile::uniform:
      return "uniform";
    case InletProfile::developed:
      return "developed";
    case InletProfile::expression:
      return "expression " + job.inlet_expression;
  }
  return {};
}

// A JSON string literal: quotes, backslashes and control characters escaped.
std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\u{:04x}", static_cast<int>(c));
    } else {
      out += c;
    }
  }
  return out + '"';
}

// Before a run writes its volume as `vtu` (ranks == 1) or as `pvtu` with `ranks` pieces: the
// files of the other form, and pieces beyond the new count, from an earlier run.
void remove_stale_volume_files(const fs::path& vtu, const fs::path& pvtu, int ranks) {
  std::error_code ignored;  // absent is the usual case
  if (ranks > 1)
    fs::remove(vtu, ignored);
  else
    fs::remove(pvtu, ignored);
  for (int k = ranks > 1 ? ranks : 0; fs::exists(pvtu_piece_path(pvtu, k)); ++k)
    fs::remove(pvtu_piece_path(pvtu, k), ignored);
}

// The boundary faces of `mesh` and their nodes only, in the same face order: boundary.vtp
// without the interior points, and what the rank that writes it keeps of the whole mesh.
HybridMesh boundary_surface(const HybridMesh& mesh) {
  HybridMesh s;
  s.patch_names = mesh.patch_names;
  std::vector<NodeId> local(mesh.nodes.size(), -1);
  auto take = [&](const auto& faces, auto& out) {
    for (auto f : faces) {
      for (NodeId& v : f) {
        auto& l = local[static_cast<std::size_t>(v)];
        if (l < 0) {
          l = static_cast<NodeId>(s.nodes.size());
          s.nodes.push_back(mesh.nodes[static_cast<std::size_t>(v)]);
        }
        v = l;
      }
      out.push_back(f);
    }
  };
  take(mesh.boundary_tris, s.boundary_tris);
  take(mesh.boundary_quads, s.boundary_quads);
  s.boundary_tri_patch = mesh.boundary_tri_patch;
  s.boundary_quad_patch = mesh.boundary_quad_patch;
  return s;
}

// The per-patch forces of every rank's faces, summed (the maximum shear: the largest).
void reduce_patch_forces(std::vector<PatchForce>& patches, MPI_Comm comm) {
  std::vector<double> sums, maxima;
  for (const auto& p : patches) {
    sums.insert(sums.end(), {p.area, p.mean_shear * p.area});
    for (int c = 0; c < 3; ++c) sums.insert(sums.end(), {p.pressure[c], p.viscous[c]});
    maxima.push_back(p.max_shear);
  }
  MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_DOUBLE, MPI_SUM,
                comm);
  MPI_Allreduce(MPI_IN_PLACE, maxima.data(), static_cast<int>(maxima.size()), MPI_DOUBLE, MPI_MAX,
                comm);
  for (std::size_t k = 0; k < patches.size(); ++k) {
    const double* v = sums.data() + 8 * k;
    auto& p = patches[k];
    p.area = v[0];
    p.mean_shear = p.area > 0.0 ? v[1] / p.area : 0.0;
    for (int c = 0; c < 3; ++c) {
      p.pressure[c] = v[2 + 2 * c];
      p.viscous[c] = v[3 + 2 * c];
    }
    p.max_shear = maxima[k];
  }
}

// The wall shear of every boundary face of the whole mesh on `root`, from the faces each rank
// owns (`face_index`: their places in the whole mesh's order).
std::vector<Eigen::Vector3d> gather_face_shear(const std::vector<Eigen::Vector3d>& shear,
                                               const std::vector<std::size_t>& face_index,
                                               std::size_t faces, MPI_Comm comm, int root) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  std::vector<double> mine;  // index, then the three components, per face
  mine.reserve(4 * shear.size());
  for (std::size_t f = 0; f < shear.size(); ++f)
    mine.insert(mine.end(),
                {static_cast<double>(face_index[f]), shear[f][0], shear[f][1], shear[f][2]});
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(counts.size(), 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(rank == root ? 4 * faces : 0);
  MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE,
              root, comm);
  std::vector<Eigen::Vector3d> whole(rank == root ? faces : 0, Eigen::Vector3d::Zero());
  for (std::size_t k = 0; k + 3 < all.size(); k += 4)
    whole[static_cast<std::size_t>(all[k])] = {all[k + 1], all[k + 2], all[k + 3]};
  return whole;
}

// A solution on the mesh `coarse_file` prolonged onto the mesh of `fingerprint`, which must be
// that mesh subdivided one to three times.
void prolong_solution(SolutionState& s, const fs::path& restart, const fs::path& coarse_file,
                      const fs::path& mesh_file, std::uint64_t fingerprint, std::size_t nodes) {
  HybridMesh coarse = read_mesh_h5(coarse_file);
  if (mesh_fingerprint(coarse) != s.mesh_fingerprint)
    fail("{}: the checkpoint belongs to another mesh than {}", restart.string(),
         coarse_file.string());
  std::vector<Prolongation> levels;
  while (coarse.nodes.size() < nodes && levels.size() < 3) {
    levels.emplace_back();
    coarse = subdivide(coarse, &levels.back());
  }
  if (mesh_fingerprint(coarse) != fingerprint)
    fail(
        "{} is not {} subdivided: mesh both from the same image and settings, the finer with "
        "--subdivide",
        mesh_file.string(), coarse_file.string());
  for (const Prolongation& p : levels) {
    s.field.velocity = p.apply(s.field.velocity);
    s.field.pressure = p.apply(s.field.pressure);
  }
  s.mesh_fingerprint = fingerprint;
  s.continuation = {};  // the coarse mesh's path does not carry over
}

// a + t (b − a), node by node: the secant predictor (t beyond 1) and the chord (t in [0, 1]).
FlowField blend(const FlowField& a, const FlowField& b, double t) {
  FlowField out = a;
  for (std::size_t k = 0; k < out.pressure.size(); ++k) {
    out.velocity[k] += t * (b.velocity[k] - a.velocity[k]);
    out.pressure[k] += t * (b.pressure[k] - a.pressure[k]);
  }
  return out;
}

}  // namespace

AirflowResult run_airflow_job(const AirflowJob& job) {
  check_job(job);
  Stopwatch total;
  AirflowResult r;
  HybridMesh mesh = read_mesh_h5(job.mesh);
  const std::uint64_t fingerprint = mesh_fingerprint(mesh);
  r.cells = mesh.cell_count();
  r.nodes = mesh.nodes.size();
  const int inlet = mesh.patch_id("inlet"), outlet = mesh.patch_id("outlet");
  if (inlet < 0 || outlet < 0)
    fail("{}: the mesh has no '{}' patch; mesh it with --inlet and --outlet", job.mesh.string(),
         inlet < 0 ? "inlet" : "outlet");
  const MeshCheck check = check_mesh(mesh);
  if (check.nonpositive_cells)
    fail("{}: {} inverted or flat cells (smallest volume {:.3g} mm³); remesh it with naris mesh",
         job.mesh.string(), check.nonpositive_cells, check.min_volume);
  if (!check.valid())
    fail("{}: the mesh is not valid ({}); remesh it with naris mesh", job.mesh.string(),
         check.describe());
  for (const auto& p : patch_report(mesh))
    if (p.name == "inlet") {
      r.inlet_area_mm2 = p.area;
      r.inlet_perimeter_mm = p.perimeter;
      r.d_in_mm = p.hydraulic_diameter();
    }
  if (!(r.d_in_mm > 0.0)) fail("{}: the inlet patch has no area", job.mesh.string());
  const double d_in = r.d_in_mm * 1e-3;
  r.u_in = job.inlet_speed ? *job.inlet_speed : job.reynolds * job.viscosity / d_in;
  r.reynolds = r.u_in * d_in / job.viscosity;

  // The inlet velocity (mean 1 in units of U_in) from the geometry in mm, where a user's
  // expression is written.
  ProfileShape shape;
  std::optional<InletExpression> expression;
  if (job.profile == InletProfile::expression) {
    expression.emplace(job.inlet_expression);
    shape = [&](const Eigen::Vector3d& x, double distance) { return (*expression)(x, distance); };
  }
  const DirichletConditions whole_bc = airflow_conditions(mesh, job.profile, 1.0, nullptr, shape);

  std::optional<SolutionState> resume;
  if (job.restart) {
    resume = read_solution_h5(*job.restart);
    if (job.restart_mesh)
      prolong_solution(*resume, *job.restart, *job.restart_mesh, job.mesh, fingerprint, r.nodes);
    if (resume->mesh_fingerprint != fingerprint || resume->field.pressure.size() != r.nodes)
      fail("{}: the checkpoint belongs to another mesh than {} ({} nodes vs {})",
           job.restart->string(), job.mesh.string(), resume->field.pressure.size(), r.nodes);
    if (std::abs(resume->d_in_mm - r.d_in_mm) > 1e-9 * r.d_in_mm)
      fail("{}: the checkpoint was scaled with d_in {} mm, this mesh has {} mm",
           job.restart->string(), resume->d_in_mm, r.d_in_mm);
    r.restarted_from = resume->reynolds;
    const bool at_target = job.restart_mesh && resume->reynolds == r.reynolds;
    if (resume->reynolds >= r.reynolds && !at_target)
      fail("{}: the checkpoint is at Re {:.1f}, at or past the target {:.1f}: nothing to continue",
           job.restart->string(), resume->reynolds, r.reynolds);
  }
  // Every input is checked: only now does the job touch the output folder.
  ensure_writable_folder(job.output);
  // Under MPI every rank keeps its piece of the mesh and of the fields (parallel/partition.h)
  // and shares the solves; the first gathers what it writes.
  int rank = 0, ranks = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  const bool writer = rank == 0;
  log_line(fmt::format("naris solve: {} ({} cells), Re {:.1f} on d_in {:.3f} mm, U_in {:.4f} m/s",
                       job.mesh.string(), r.cells, r.reynolds, r.d_in_mm, r.u_in));

  // Nondimensional geometry: lengths in units of d_in.
  for (auto& x : mesh.nodes) x /= r.d_in_mm;
  // The pieces; the whole mesh goes (the first rank keeps its boundary for boundary.vtp).
  const MeshCounts counts = mesh_counts(mesh);
  const std::size_t boundary_faces = mesh.boundary_tris.size() + mesh.boundary_quads.size();
  parallel::MeshPiece piece;
  HybridMesh surface;
  if (ranks == 1) {
    piece.numbering = parallel::whole_numbering(mesh.nodes.size());
    piece.mesh = std::move(mesh);
  } else {
    piece = parallel::mesh_piece(mesh, rank, ranks);
    if (writer) surface = boundary_surface(mesh);
  }
  mesh = HybridMesh{};
  const HybridMesh& local = piece.mesh;
  const parallel::NodeNumbering& numbering = piece.numbering;
  const DirichletConditions bc = local_conditions(whole_bc, numbering);
  if (resume) {
    resume->field = local_field(resume->field, numbering);
    if (resume->continuation.earlier_reynolds > 0.0)
      resume->continuation.earlier = local_field(resume->continuation.earlier, numbering);
  }

  // Reynolds-number continuation: each step warm-started from the last converged one; the
  // step grows after an easy step and is halved after a failed one.
  // `reached` is the last converged Re (0: none yet); `last_good` its field; `earlier` the
  // converged field before it, at Re `earlier_re` (0: none).
  FlowField field, last_good, earlier, predicted;
  double earlier_re = 0.0;
  double re = std::min(job.start_reynolds, r.reynolds), step = re;
  double reached = 0.0;
  // The method the last converged step needed goes first (pseudo-time from rest).
  bool pseudo_first = true;
  double resume_arclength = 0.0;  // > 0: the checkpoint was on a branch followed by arclength
  if (resume) {
    last_good = resume->field;
    reached = resume->reynolds;
    ContinuationState& c = resume->continuation;
    if (c.next_step > 0.0) {
      // Where the interrupted run stood: the restart takes the path it would have taken.
      step = c.next_step;
      pseudo_first = c.pseudo_time;
      resume_arclength = c.arclength_step;
      earlier_re = c.earlier_reynolds;
      earlier = std::move(c.earlier);
    } else {
      // A file without the continuation (solution.h5): a quarter of the way so far, grown if
      // easy (a doubling of Re in one step is too much for the constricted jets of real
      // anatomy), Newton first.
      step = std::max(0.25 * reached, 1.0);
      pseudo_first = false;
    }
    re = std::min(r.reynolds, reached + step);
    if (reached >= r.reynolds) {
      // A prolonged field at the target: the target's step starts from it, Newton first.
      re = step = r.reynolds;
      reached = 0.0;
    }
    if (job.restart_mesh)
      log_line(fmt::format("  the solution at Re {:.1f} on {} prolonged onto this mesh",
                           resume->reynolds, job.restart_mesh->string()));
    log_line(fmt::format("  restarting from Re {:.1f} ({}), next Re {:.1f}", resume->reynolds,
                         job.restart->string(), re));
  }
  const fs::path checkpoint = job.output / "checkpoint.h5";
  // The state at `at` on the first rank, the last good field gathered from all.
  auto state_at = [&](double at) {
    SolutionState s;
    s.field = gather_field(last_good, numbering, PETSC_COMM_WORLD, 0);
    s.reynolds = at;
    s.target_reynolds = r.reynolds;
    s.u_in = r.u_in;
    s.d_in_mm = r.d_in_mm;
    s.density = job.density;
    s.viscosity = job.viscosity;
    s.mesh_fingerprint = fingerprint;
    return s;
  };
  // The residual history of every step, converged or not: on failure it is the evidence.
  const fs::path csv = job.output / "residuals.csv";
  auto write_residual_history = [&] {
    AtomicOutput out(csv);
    std::ofstream f(out.temp_path());
    f << "step,reynolds,converged,iteration,residual\n";
    for (std::size_t s = 0; s < r.steps.size(); ++s)
      for (std::size_t i = 0; i < r.steps[s].residuals.size(); ++i)
        f << s << ',' << r.steps[s].reynolds << ',' << r.steps[s].converged << ',' << i << ','
          << fmt::format("{:.6e}", r.steps[s].residuals[i]) << '\n';
    if (!f) fail("{}: write failed", csv.string());
    f.close();
    out.commit();
  };
  PicardOptions picard = job.picard;
  picard.backflow_patch = outlet;
  // The inlet→outlet drop of the area-averaged pressure and the largest speed of a field, both
  // nondimensional (collective).
  auto pressure_drop = [&](const FlowField& f) {
    const PatchIntegral in = patch_integral(local, f.pressure, inlet),
                        out = patch_integral(local, f.pressure, outlet);
    double sums[4] = {in.integral, in.area, out.integral, out.area};
    MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
    return sums[0] / sums[1] - sums[2] / sums[3];
  };
  auto max_speed = [&](const FlowField& f) {
    double m = 0.0;
    for (NodeId k = 0; k < numbering.owned; ++k)
      m = std::max(m, f.velocity[static_cast<std::size_t>(k)].norm());
    MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD);
    return m;
  };

  // Pseudo-arclength continuation along the branch through (earlier, earlier_re) and
  // (last_good, reached), starting with arclength increment `ds` (0: the distance between the
  // two). Returns true when the branch crossed the target and the target itself converged
  // (last_good and reached then hold it); otherwise fails, naming what the branch did.
  // branch.csv records every point — the diagram of Δp against Re that is the evidence.
  const fs::path branch_csv = job.output / "branch.csv";
  std::string branch_rows;
  auto branch_point = [&](double re_point, const FlowField& f, int newton, double s_along) {
    const double u = r.u_in * re_point / r.reynolds;  // U_in at that Re, m/s
    branch_rows += fmt::format("{:.6f},{:.6e},{:.6f},{:.6f},{}\n", re_point, s_along,
                               pressure_drop(f) * job.density * u * u, max_speed(f) * u, newton);
    if (!writer) return;
    write_text_file(branch_csv, "reynolds,arclength,pressure_drop_pa,max_speed_m_s,newton_steps\n" +
                                    branch_rows);
  };
  // One solve of the continuation at Re `re_solve` (with `constraint`: its predictor's), its
  // counts into `cs`, which joins the history (and the whole report into `kept`, if given). A
  // diverged iteration is a failed try; the field is then empty.
  auto solve_step = [&](ContinuationStep& cs, double re_solve, const PicardOptions& options,
                        const FlowField* initial, const ArclengthConstraint* constraint,
                        PicardReport* kept = nullptr) {
    Stopwatch clock;
    PicardReport report;
    FlowField f;
    try {
      f = solve_navier_stokes(local, numbering, 1.0 / re_solve, {}, bc, options, &report, initial,
                              constraint);
      cs.converged = report.converged && (!constraint || report.reynolds > 0.0);
      if (constraint) cs.reynolds = report.reynolds;
    } catch (const Error& e) {
      cs.converged = false;
      log_line(fmt::format("  Re {:.1f}: {}", re_solve, e.what()));
    }
    cs.iterations = report.iterations;
    cs.linear_iterations = report.linear_iterations;
    cs.preconditioner_builds = report.preconditioner_builds;
    cs.residuals = report.residuals;
    cs.residual = report.residuals.empty() ? NAN : report.residuals.back();
    cs.seconds = clock.seconds();
    r.steps.push_back(cs);
    if (kept) *kept = std::move(report);
    return f;
  };
  // Newton alone on a short budget, to the steps' tolerance: the points of the branch.
  auto newton_only = [&] {
    PicardOptions attempt = picard;
    attempt.pseudo_cfl = 0.0;
    attempt.max_iterations = std::min(picard.max_iterations, 25);
    attempt.stall_steps = 5;
    attempt.tolerance = std::max(picard.tolerance, job.step_tolerance);
    return attempt;
  };
  auto point_below = [&] {
    const double re_below = 0.99 * reached;
    const PicardOptions attempt = newton_only();
    ContinuationStep cs;
    cs.reynolds = re_below;
    FlowField below = solve_step(cs, re_below, attempt, &last_good, nullptr);
    log_line(fmt::format(
        "  Re {:8.2f}: {} after {} Newton steps (a second point of the branch, "
        "for its tangent), residual {:.2e}, {:.1f} s",
        re_below, cs.converged ? "converged" : "FAILED", cs.iterations, cs.residual, cs.seconds));
    if (!cs.converged) return;
    earlier = std::move(below);
    earlier_re = re_below;
  };
  auto follow_branch = [&](double ds) -> bool {
    log_line(fmt::format("  following the branch through Re {:.2f} and {:.2f} by arclength",
                         earlier_re, reached));
    const double re_first = reached;
    // The first step goes along the secant through the last two points (unit in the
    // constraint's metric); later ones along the tangent each solve reports.
    ArclengthConstraint c;
    auto aim = [&](const FlowField& from, double re_from, const FlowField& to, double re_to) {
      return aim_along_secant(c, from, re_from, to, re_to, numbering, PETSC_COMM_WORLD);
    };
    const double secant = aim(earlier, earlier_re, last_good, reached);
    if (!(ds > 0.0)) ds = secant;
    const double smallest = ds / 64.0;
    double along = 0.0, lowest = reached, highest = reached;
    std::vector<double> turns;
    if (branch_rows.empty()) {
      branch_point(earlier_re, earlier, 0, -secant);
      branch_point(reached, last_good, 0, 0.0);
    }
    const PicardOptions attempt = newton_only();
    for (int k = 0; k < job.arclength_steps && ds >= smallest; ++k) {
      c.origin = last_good;
      c.origin_reynolds = reached;
      c.step = ds;
      const FlowField guess = arclength_predictor(c);
      const double re_guess = reached + ds * c.tangent_reynolds;
      ContinuationStep cs;
      cs.arclength = true;
      cs.reynolds = re_guess;
      PicardReport report;
      FlowField found = solve_step(cs, re_guess, attempt, &guess, &c, &report);
      log_line(
          fmt::format("  Re {:8.2f}: {} after {} Newton steps on the branch (arclength {:.3g}), "
                      "residual {:.2e}, {:.1f} s",
                      cs.reynolds, cs.converged ? "converged" : "FAILED", cs.iterations, ds,
                      cs.residual, cs.seconds));
      if (!cs.converged) {
        ds *= 0.5;
        continue;
      }
      along += ds;
      const double re_new = cs.reynolds;
      if (re_new >= r.reynolds) {
        // Past the target: the target itself, from the chord between the two points.
        const double t = (r.reynolds - reached) / (re_new - reached);
        const FlowField start = blend(last_good, found, t);
        ContinuationStep last;
        last.reynolds = r.reynolds;
        PicardOptions exact = attempt;
        exact.tolerance = picard.tolerance;
        FlowField at_target = solve_step(last, r.reynolds, exact, &start, nullptr);
        if (last.converged) field = std::move(at_target);
        log_line(fmt::format("  Re {:8.1f}: {} after {} Newton steps, residual {:.2e}, {:.1f} s",
                             r.reynolds, last.converged ? "converged" : "FAILED", last.iterations,
                             last.residual, last.seconds));
        if (last.converged) {
          earlier = std::move(last_good);
          earlier_re = reached;
          last_good = field;
          reached = r.reynolds;
          branch_point(reached, last_good, last.iterations, along - (1.0 - t) * ds);
          return true;
        }
        ds *= 0.5;  // closer to the target next time
        continue;
      }
      // The branch turns where Re, along it, stops growing (or falling): where the tangent at
      // the new point (the secant only if the solve gave none) points back in Re.
      const double previous_direction = c.tangent_reynolds;
      earlier = std::move(last_good);
      earlier_re = reached;
      last_good = std::move(found);
      reached = re_new;
      if (!report.tangent.pressure.empty()) {
        c.tangent = std::move(report.tangent);
        c.tangent_reynolds = report.tangent_reynolds;
      } else {
        aim(earlier, earlier_re, last_good, reached);
      }
      if (previous_direction * c.tangent_reynolds < 0.0) {
        const double turn = previous_direction > 0.0 ? std::max(earlier_re, reached)
                                                     : std::min(earlier_re, reached);
        turns.push_back(turn);
        log_line(fmt::format("  the branch turns back near Re {:.2f} (a turning point)", turn));
      }
      lowest = std::min(lowest, reached);
      highest = std::max(highest, reached);
      branch_point(reached, last_good, cs.iterations, along);
      if (cs.iterations < attempt.max_iterations / 3) ds *= 1.5;
      SolutionState state = state_at(reached);  // collective
      state.continuation.next_step = ds;
      state.continuation.arclength_step = ds;
      state.continuation.earlier_reynolds = earlier_re;
      state.continuation.earlier = gather_field(earlier, numbering, PETSC_COMM_WORLD, 0);
      if (writer) write_solution_h5(state, checkpoint);
    }
    if (writer) write_residual_history();
    const std::string turned =
        turns.empty() ? std::string("no turning point found")
                      : fmt::format("it turns back at Re {:.2f}", fmt::join(turns, ", "));
    fail(
        "the continuation stalled at Re {:.1f} (target {:.1f}); following the steady branch "
        "from there by arclength, {}, and it stayed between Re {:.1f} and {:.1f} ({} holds it, "
        "{} its last point)",
        re_first, r.reynolds, turned, lowest, highest, branch_csv.string(), checkpoint.string());
  };
  // With pseudo-time available, each Re is tried with both methods before the increment is
  // halved: Newton alone (on a short budget) and with pseudo-time, first the one that took the
  // last step. Newton from the last solution follows the steady branch even where that branch
  // is unstable, which time-like steps cannot (on the neonatal airway near Re 600 they wander
  // at residuals of 1e-1 to 1e-2). Where Newton fails — near Re 190 there, where the branch
  // ends — pseudo-time carries the flow across, and Newton keeps failing above: from Re 50 to
  // 300 its tries at 225 and 300 cost 200 of 1130 s before pseudo-time converged. From rest
  // pseudo-time goes first: the Stokes field is far from the first step's solution, where
  // damped Newton steps crawl (on the neonatal airway at Re 50 Newton alone gave up after 10
  // steps and 112 s; pseudo-time took 14 steps and 119 s).
  const bool pseudo_available = job.picard.pseudo_cfl > 0.0;
  bool retry = false;  // the second try at this Re, with the other method
  if (resume_arclength > 0.0) follow_branch(resume_arclength);
  for (int s = 0; s < job.max_steps && reached < r.reynolds; ++s) {
    ContinuationStep cs;
    cs.reynolds = re;
    PicardOptions attempt = picard;
    if (re < r.reynolds) attempt.tolerance = std::max(picard.tolerance, job.step_tolerance);
    const bool pseudo = pseudo_available && (pseudo_first != retry);
    if (pseudo_available && !pseudo) {
      attempt.pseudo_cfl = 0.0;
      attempt.max_iterations = std::min(picard.max_iterations, 25);
      // Where Newton fails on the neonatal airway it crawls (3.9e-2 → 3.3e-2 in five steps at
      // Re 547): five steps without halving the residual hand over to pseudo-time.
      attempt.stall_steps = 5;
    }
    // The first try at each Re starts from the secant predictor through the last two converged
    // fields, u(Re) ≈ u₁ + (u₁ − u₀)(Re − Re₁)/(Re₁ − Re₀) (the boundary data are the same, so
    // it keeps them): on the phantom it takes a Newton step or two off every continuation step.
    // A retry starts from the last converged field itself, as does every step after one that
    // needed pseudo-time (no secant then: `earlier_re` is 0).
    const bool predict = earlier_re > 0.0 && !retry;
    if (predict) {
      const double t = (1.0 / re - 1.0 / reached) / (1.0 / reached - 1.0 / earlier_re);
      predicted = blend(earlier, last_good, 1.0 + t);
    }
    field = solve_step(cs, re, attempt,
                       predict                       ? &predicted
                       : !last_good.pressure.empty() ? &last_good
                                                     : nullptr,
                       nullptr);
    log_line(fmt::format("  Re {:8.1f}: {} after {} nonlinear steps{}, residual {:.2e}, {:.1f} s",
                         re, cs.converged ? "converged" : "FAILED", cs.iterations,
                         pseudo ? " with pseudo-time" : "", cs.residual, cs.seconds));
    if (cs.converged) {
      // A step that needed pseudo-time may have crossed to another branch (the neonatal
      // airway's jet near Re 190): no secant through the two branches.
      earlier_re = 0.0;
      if (reached > 0.0 && !pseudo) {
        earlier = std::move(last_good);
        earlier_re = reached;
      }
      last_good = field;
      reached = re;
      if (cs.iterations < attempt.max_iterations / 3) step *= 1.5;
      re = std::min(r.reynolds, re + step);
      pseudo_first = pseudo;
      retry = false;
      // The last good step on disk, with what comes next.
      SolutionState state = state_at(reached);  // collective
      state.continuation.next_step = step;
      state.continuation.pseudo_time = pseudo;
      state.continuation.earlier_reynolds = earlier_re;
      if (earlier_re > 0.0)
        state.continuation.earlier = gather_field(earlier, numbering, PETSC_COMM_WORLD, 0);
      if (writer) write_solution_h5(state, checkpoint);
    } else if (pseudo_available && !retry) {
      retry = true;  // the same Re again, with the other method
    } else {
      retry = false;
      if (reached == 0.0) {
        step = re *= 0.5;  // the very first step: start lower
      } else {
        step = 0.5 * (re - reached);  // half the increment that failed
        re = reached + step;
      }
      if (step < 1e-3 * r.reynolds) {
        // A stall after Newton steps on one branch: follow the branch instead.
        const bool bordered = picard.newton && picard.scheme == PicardOptions::Scheme::coupled;
        if (job.arclength_steps > 0 && bordered) {
          // After pseudo-time steps there is one point only: the second of the secant by a
          // Newton step back from it, which stays on its branch.
          if (!(earlier_re > 0.0)) point_below();
          if (earlier_re > 0.0 && follow_branch(0.0)) break;
        }
        if (writer) write_residual_history();
        fail("the continuation stalled at Re {:.1f} (target {:.1f}): the step fell below {:.2f}{}",
             reached, r.reynolds, 1e-3 * r.reynolds,
             reached > 0.0 ? "; " + checkpoint.string() + " holds the last converged step" : "");
      }
    }
  }
  if (reached < r.reynolds) {
    if (writer) write_residual_history();
    fail(
        "the continuation reached Re {:.1f} of {:.1f} in {} steps; {} holds that step (resume "
        "with --restart)",
        reached, r.reynolds, job.max_steps, checkpoint.string());
  }

  // SI results.
  const double u = r.u_in, pscale = job.density * u * u;
  r.flow_ml_s = u * r.inlet_area_mm2;  // m/s × mm² = 1e-6 m³/s = mL/s
  // Each rank's faces and nodes, summed over the ranks.
  {
    double flux = patch_flux(local, last_good.velocity, outlet);
    MPI_Allreduce(MPI_IN_PLACE, &flux, 1, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
    r.outlet_flow_ml_s = flux * u * r.d_in_mm * r.d_in_mm;
  }
  r.pressure_drop_pa = pressure_drop(last_good) * pscale;
  r.resistance = r.pressure_drop_pa / r.flow_ml_s;
  r.max_speed = max_speed(last_good) * u;

  // Stresses on the boundary, while the geometry is still nondimensional.
  WallStress stress = wall_stress(local, last_good, reached);
  if (ranks > 1) {
    reduce_patch_forces(stress.patches, PETSC_COMM_WORLD);
    stress.shear =
        gather_face_shear(stress.shear, piece.face_index, boundary_faces, PETSC_COMM_WORLD, 0);
  }
  const double force_scale = pscale * d_in * d_in;
  for (const auto& p : stress.patches)
    r.patches.push_back({p.name, p.area * r.d_in_mm * r.d_in_mm, p.pressure * force_scale,
                         p.viscous * force_scale, p.mean_shear * pscale, p.max_shear * pscale});

  // Files, in millimetres again.
  for (auto& x : piece.mesh.nodes) x *= r.d_in_mm;
  for (auto& x : surface.nodes) x *= r.d_in_mm;
  PointFields fields;
  auto vector_field = [&](double scale) {
    PointField f{3, {}};
    f.values.reserve(3 * last_good.velocity.size());
    for (const auto& v : last_good.velocity)
      for (int c = 0; c < 3; ++c) f.values.push_back(v[c] * scale);
    return f;
  };
  auto scalar_field = [&](double scale) {
    PointField f{1, {}};
    for (double p : last_good.pressure) f.values.push_back(p * scale);
    return f;
  };
  fields["velocity"] = vector_field(u);
  fields["pressure"] = scalar_field(pscale);
  fields["velocity_nondimensional"] = vector_field(1.0);
  fields["pressure_nondimensional"] = scalar_field(1.0);
  // The volume: one file from a serial run; under MPI a .pvtu whose pieces the ranks write at
  // once, each its own cells. Files of the other form left by an earlier run are removed, so
  // the folder never offers two different answers.
  const fs::path vtu = job.output / "solution.vtu", pvtu = job.output / "solution.pvtu";
  if (writer) remove_stale_volume_files(vtu, pvtu, ranks);
  if (ranks == 1) {
    write_vtu(local, vtu, {}, fields);
    r.written.push_back(vtu.string());
  } else {
    // A rank that cannot write its piece (disk full) must not leave the others waiting in the
    // reductions below: every rank learns that one failed.
    std::string failure;
    try {
      write_pvtu_piece(
          local, pvtu, rank, ranks,
          [&](std::span<const NodeId> cell) { return numbering.owns_cell(cell); }, {}, fields);
    } catch (const Error& e) {
      failure = e.what();
    }
    int failed = failure.empty() ? 0 : 1, any_failed = 0;
    MPI_Allreduce(&failed, &any_failed, 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD);
    if (failed) fail("{}", failure);
    if (any_failed) fail("{}: another rank could not write its piece", pvtu.string());
    r.written.push_back(pvtu.string() + fmt::format(" (+ {} pieces)", ranks));
  }
  // Memory: the largest rank's peak is what each machine of a cluster must have, the sum what
  // the run took in all.
  const auto mine = static_cast<unsigned long long>(peak_memory_bytes());
  {
    unsigned long long largest = mine, sum = mine;
    MPI_Allreduce(&mine, &largest, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, PETSC_COMM_WORLD);
    MPI_Allreduce(&mine, &sum, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, PETSC_COMM_WORLD);
    r.ranks = ranks;
    r.peak_memory = largest;
    r.total_peak_memory = sum;
  }
  const SolutionState final_state = state_at(reached);  // collective
  if (!writer) {
    r.seconds = total.seconds();
    return r;
  }
  {
    PointFields faces;
    PointField vec{3, {}}, mag{1, {}};
    for (const auto& s : stress.shear) {
      for (int c = 0; c < 3; ++c) vec.values.push_back(s[c] * pscale);
      mag.values.push_back(s.norm() * pscale);
    }
    faces["wall_shear_stress"] = std::move(vec);
    faces["wall_shear_stress_magnitude"] = std::move(mag);
    const fs::path vtp = job.output / "boundary.vtp";
    write_boundary_vtp(ranks > 1 ? surface : boundary_surface(local), vtp, faces);
    r.written.push_back(vtp.string());
  }
  const fs::path h5 = job.output / "solution.h5";
  write_solution_h5(final_state, h5, &counts, job.mesh);
  r.written.push_back(h5.string());
  r.written.push_back(fs::path(h5).replace_extension(".xdmf").string());

  write_residual_history();
  r.written.push_back(csv.string());
  r.seconds = total.seconds();
  // The first rank also wrote the files: its own peak may have grown since (a peak only grows).
  const std::size_t own = peak_memory_bytes();
  r.total_peak_memory += own - std::min<std::size_t>(own, mine);
  r.peak_memory = std::max(r.peak_memory, own);

  const fs::path json = job.output / "summary.json";
  {
    std::string steps;
    for (const auto& s : r.steps)
      steps += fmt::format(
          "{}{{\"reynolds\": {:.6g}, \"converged\": {}, \"arclength\": {}, "
          "\"nonlinear_iterations\": {}, \"linear_iterations\": {}, \"preconditioner_builds\": "
          "{}, \"residual\": {:.6e}, \"seconds\": {:.3f}}}",
          steps.empty() ? "" : ", ", s.reynolds, s.converged ? "true" : "false",
          s.arclength ? "true" : "false", s.iterations, s.linear_iterations,
          s.preconditioner_builds, s.residual, s.seconds);
    std::string patches;
    for (const auto& p : r.patches)
      patches += fmt::format(
          "{}\n    {{\"name\": \"{}\", \"area_mm2\": {:.6g}, \"pressure_force_n\": [{:.6g}, "
          "{:.6g}, "
          "{:.6g}], \"viscous_force_n\": [{:.6g}, {:.6g}, {:.6g}], \"mean_wall_shear_pa\": {:.6g}, "
          "\"max_wall_shear_pa\": {:.6g}}}",
          patches.empty() ? "" : ",", p.name, p.area_mm2, p.pressure_force[0], p.pressure_force[1],
          p.pressure_force[2], p.viscous_force[0], p.viscous_force[1], p.viscous_force[2],
          p.mean_shear, p.max_shear);
    write_text_file(
        json,
        fmt::format(
            "{{\n  \"mesh\": {},\n  \"cells\": {},\n  \"nodes\": {},\n  \"reynolds\": {:.6g},\n"
            "  \"inlet_speed_m_s\": {:.6g},\n  \"inlet_hydraulic_diameter_mm\": {:.6g},\n"
            "  \"inlet_area_mm2\": {:.6g},\n  \"inlet_perimeter_mm\": {:.6g},\n"
            "  \"viscosity_m2_s\": {:.6g},\n  \"density_kg_m3\": {:.6g},\n  \"inlet_profile\": "
            "{},\n"
            "  \"flow_ml_s\": {:.6g},\n  \"outlet_flow_ml_s\": {:.6g},\n  \"pressure_drop_pa\": "
            "{:.6g},\n"
            "  \"resistance_pa_s_ml\": {:.6g},\n  \"max_speed_m_s\": {:.6g},\n  \"patches\": [{}\n "
            " "
            "],\n"
            "  \"continuation\": [{}],\n"
            "  \"mpi_ranks\": {},\n  \"seconds\": {:.3f},\n  \"peak_memory_mb\": {:.1f},\n"
            "  \"peak_memory_all_ranks_mb\": {:.1f}\n}}\n",
            json_string(job.mesh.string()), r.cells, r.nodes, r.reynolds, r.u_in, r.d_in_mm,
            r.inlet_area_mm2, r.inlet_perimeter_mm, job.viscosity, job.density,
            json_string(profile_name(job)), r.flow_ml_s, r.outlet_flow_ml_s, r.pressure_drop_pa,
            r.resistance, r.max_speed, patches, steps, r.ranks, r.seconds,
            r.peak_memory / 1048576.0, r.total_peak_memory / 1048576.0));
  }
  r.written.push_back(json.string());
  r.written.push_back(checkpoint.string());
  return r;
}

std::string format_airflow_summary(const AirflowJob& job, const AirflowResult& r) {
  AirflowResult::Patch wall;
  for (const auto& p : r.patches)
    if (p.name == "wall") wall = p;
  int picard = 0;
  for (const auto& s : r.steps) picard += s.iterations;
  return fmt::format(
      "naris solve: {} ({} cells, {} nodes)\n"
      "  inlet     A {:.2f} mm², P {:.2f} mm, d_in = 4A/P {:.3f} mm; {} profile\n"
      "  scales    Re {:.1f}, U_in {:.4f} m/s, ν {:.3g} m²/s, ρ {:.3g} kg/m³\n"
      "  flow      {:.2f} mL/s in, {:.2f} mL/s out\n"
      "  pressure  drop inlet→outlet {:.3f} Pa; resistance {:.4f} Pa·s/mL\n"
      "  speed     max {:.3f} m/s\n"
      "  wall      shear stress mean {:.4f} Pa, max {:.4f} Pa; force {:.3e} N\n"
      "  solve     {} continuation steps, {} nonlinear steps, {:.1f} s, peak {}\n"
      "  wrote     {}",
      job.mesh.filename().string(), r.cells, r.nodes, r.inlet_area_mm2, r.inlet_perimeter_mm,
      r.d_in_mm, profile_name(job), r.reynolds, r.u_in, job.viscosity, job.density, r.flow_ml_s,
      r.outlet_flow_ml_s, r.pressure_drop_pa, r.resistance, r.max_speed, wall.mean_shear,
      wall.max_shear, (wall.pressure_force + wall.viscous_force).norm(), r.steps.size(), picard,
      r.seconds,
      r.ranks > 1 ? fmt::format("{:.0f} MB per rank, {:.0f} MB on {} ranks",
                                r.peak_memory / 1048576.0, r.total_peak_memory / 1048576.0, r.ranks)
                  : fmt::format("{:.0f} MB", r.peak_memory / 1048576.0),
      fmt::join(r.written, "\n            "));
}

}  // namespace naris::ns
