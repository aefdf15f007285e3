#include "solver/airflow/airflow_outputs.h"

#include <fmt/format.h>
#include <petscsys.h>

#include <algorithm>
#include <span>

#include "core/error.h"
#include "core/json.h"
#include "core/log.h"
#include "core/units.h"
#include "mesh/io/write_vtk.h"
#include "solver/ns/reaction_force.h"
#include "solver/ns/subgrid_velocity.h"
#include "solver/ns/wall_stress.h"

namespace naris::airflow {
namespace fs = std::filesystem;
using ns::PatchForce;

namespace {

std::string profile_name(const AirflowJob& job) {
  switch (job.profile) {
    case ns::InletProfile::uniform:
      return "uniform";
    case ns::InletProfile::developed:
      return "developed";
    case ns::InletProfile::expression:
      return "expression " + job.inlet_expression;
  }
  return {};
}

const char* drive_name(const AirflowJob& job) {
  return job.drive == ns::DrivenPatch::outlet ? "outlet" : "inlet";
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

// The wall shear stress of every boundary face (on the first rank), in units of ρU_in²: from the
// consistent traction, and from the near-wall cells' gradients to compare.
struct BoundaryShear {
  std::vector<Eigen::Vector3d> consistent, cell;
};

// Per patch, the area-weighted mean and the largest |τ_w| of `shear` over the piece's faces.
void patch_shear(const HybridMesh& piece, const std::vector<Eigen::Vector3d>& shear,
                 std::vector<PatchForce>& patches) {
  for (auto& p : patches) p.mean_shear = p.max_shear = 0.0;
  std::size_t f = 0;
  for_each_boundary_face(piece, [&](std::span<const NodeId> v, int patch) {
    PatchForce& p = patches[static_cast<std::size_t>(patch)];
    const double s = shear[f++].norm();
    p.mean_shear += polygon_area(piece, v) * s;
    p.max_shear = std::max(p.max_shear, s);
  });
  for (auto& p : patches)
    if (p.area > 0.0) p.mean_shear /= p.area;
}

// The flow's numbers in SI into r, and the wall shear stress.
BoundaryShear flow_results(const AirflowJob& job, const Partition& part, const PieceSolves& solves,
                           const ns::FlowField& field, const PatchOpenings& openings,
                           AirflowResult& r) {
  const double u = r.u_in, pscale = job.density * u * u;
  const double flow_scale = u * r.d_in_mm * r.d_in_mm;  // m/s × mm² = 1e-6 m³/s = mL/s
  r.flow_ml_s = u * r.inlet_area_mm2;
  const HybridMesh& piece = part.piece.mesh;
  r.inlet_flow_ml_s = -solves.flux_out(field, piece.patch_id("inlet")) * flow_scale;
  r.outlet_flow_ml_s = solves.flux_out(field, piece.patch_id("outlet")) * flow_scale;
  const std::vector<double> inflows =
      solves.opening_inflows(field, openings.of_face, openings.area.size(), part.piece.face_index);
  r.openings.clear();
  for (std::size_t k = 0; k < inflows.size(); ++k)
    r.openings.push_back({openings.area[k], openings.centroid[k], inflows[k] * flow_scale});
  r.pressure_drop_pa = solves.pressure_drop(field) * pscale;
  if (job.drive == ns::DrivenPatch::outlet)
    r.ambient_drop_pa = -solves.outlet_pressure(field) * pscale;
  r.resistance = r.pressure_drop_pa / r.flow_ml_s;
  r.max_speed = solves.max_speed(field) * u;
  // Stresses on the boundary, while the geometry is still nondimensional.
  ns::WallStress stress = ns::wall_stress(part.piece.mesh, field, r.reynolds);
  const ns::Reactions reactions = solves.reaction_forces(field, r.reynolds);
  const std::vector<Eigen::Vector3d>& forces = reactions.patches;
  const std::vector<ns::PatchKind> kinds = ns::airflow_patch_kinds(part.piece.mesh, job.drive);
  BoundaryShear shear{ns::consistent_wall_shear(part.piece.mesh, reactions, kinds),
                      std::move(stress.shear)};
  patch_shear(part.piece.mesh, shear.consistent, stress.patches);
  int ranks = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  if (ranks > 1) {
    reduce_patch_forces(stress.patches, PETSC_COMM_WORLD);
    for (auto* s : {&shear.consistent, &shear.cell})
      *s = gather_face_shear(*s, part.piece.face_index, part.boundary_faces, PETSC_COMM_WORLD, 0);
  }
  Eigen::Vector3d balance = solves.momentum_outflow(field);
  double largest_wall = 0.0;
  for (std::size_t q = 0; q < forces.size(); ++q) {
    balance += forces[q];
    if (kinds[q] == ns::PatchKind::wall) largest_wall = std::max(largest_wall, forces[q].norm());
  }
  r.momentum_balance = largest_wall > 0.0 ? balance.norm() / largest_wall : 0.0;
  const double d_in = r.d_in_mm * kMm, force_scale = pscale * d_in * d_in;
  for (std::size_t q = 0; q < stress.patches.size(); ++q) {
    const PatchForce& p = stress.patches[q];
    r.patches.push_back({p.name, p.area * r.d_in_mm * r.d_in_mm, forces[q] * force_scale,
                         p.pressure * force_scale, p.viscous * force_scale, p.mean_shear * pscale,
                         p.max_shear * pscale});
  }
  return shear;
}

// The volume: one file from a serial run; under MPI a .pvtu whose pieces the ranks write at
// once, each its own cells. Files of the other form left by an earlier run are removed, so the
// folder never offers two different answers.
void write_volume(const AirflowJob& job, const Partition& part, const ns::FlowField& field,
                  const AirflowResult& r, std::vector<std::string>& written) {
  const double u = r.u_in, pscale = job.density * u * u;
  PointFields fields;
  auto vector_field = [&](double scale) {
    FieldArray f{3, {}};
    f.values.reserve(3 * field.velocity.size());
    for (const auto& v : field.velocity)
      for (int c = 0; c < 3; ++c) f.values.push_back(v[c] * scale);
    return f;
  };
  auto scalar_field = [&](double scale) {
    FieldArray f{1, {}};
    for (double p : field.pressure) f.values.push_back(p * scale);
    return f;
  };
  fields["velocity"] = vector_field(u);
  fields["pressure"] = scalar_field(pscale);
  fields["velocity_nondimensional"] = vector_field(1.0);
  fields["pressure_nondimensional"] = scalar_field(1.0);
  // Each cell's mean fine-scale velocity (ns/subgrid_velocity.h): large against the velocity
  // where the mesh does not resolve the flow.
  CellFields cells;
  FieldArray& fine = cells["subgrid_velocity"];
  fine.components = 3;
  fine.values.reserve(3 * part.piece.mesh.cell_count());
  for (const Eigen::Vector3d& v :
       ns::subgrid_velocity(part.piece.mesh, field, 1.0 / r.reynolds, r.d_in_mm))
    for (int c = 0; c < 3; ++c) fine.values.push_back(v[c] * u);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  const fs::path vtu = job.output / "solution.vtu", pvtu = job.output / "solution.pvtu";
  if (rank == 0) remove_stale_volume_files(vtu, pvtu, ranks);
  if (ranks == 1) {
    write_vtu(part.piece.mesh, vtu, cells, fields);
    written.push_back(vtu.string());
    return;
  }
  // A rank that cannot write its piece (disk full) must not leave the others waiting in the
  // reductions that follow: every rank learns that one failed.
  std::string failure;
  try {
    write_pvtu_piece(
        part.piece.mesh, pvtu, rank, ranks,
        [&](std::span<const NodeId> cell) { return part.piece.numbering.owns_cell(cell); }, cells,
        fields);
  } catch (const Error& e) {
    failure = e.what();
  }
  int failed = failure.empty() ? 0 : 1, any_failed = 0;
  MPI_Allreduce(&failed, &any_failed, 1, MPI_INT, MPI_MAX, PETSC_COMM_WORLD);
  if (failed) fail("{}", failure);
  if (any_failed) fail("{}: another rank could not write its piece", pvtu.string());
  written.push_back(pvtu.string() + fmt::format(" (+ {} pieces)", ranks));
}

// boundary.vtp with the wall shear stress of every face (first rank).
void write_boundary(const AirflowJob& job, const Partition& part, const BoundaryShear& shear,
                    double pscale, std::vector<std::string>& written) {
  PointFields faces;
  FieldArray vec{3, {}}, mag{1, {}}, cell{3, {}};
  for (const auto& s : shear.consistent) {
    for (int c = 0; c < 3; ++c) vec.values.push_back(s[c] * pscale);
    mag.values.push_back(s.norm() * pscale);
  }
  for (const auto& s : shear.cell)
    for (int c = 0; c < 3; ++c) cell.values.push_back(s[c] * pscale);
  faces["wall_shear_stress"] = std::move(vec);
  faces["wall_shear_stress_magnitude"] = std::move(mag);
  faces["wall_shear_stress_cell"] = std::move(cell);
  const fs::path vtp = job.output / "boundary.vtp";
  int ranks = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &ranks);
  write_boundary_vtp(ranks > 1 ? part.surface : part.piece.mesh, vtp, faces);
  written.push_back(vtp.string());
}

}  // namespace

Partition partition(HybridMesh mesh, int rank, int ranks) {
  Partition p;
  p.counts = mesh_counts(mesh);
  p.boundary_faces = mesh.boundary_tris.size() + mesh.boundary_quads.size();
  if (ranks == 1) {
    p.piece.numbering = parallel::whole_numbering(mesh.nodes.size());
    p.piece.mesh = std::move(mesh);
  } else {
    p.piece = parallel::mesh_piece(mesh, rank, ranks);
    if (rank == 0) p.surface = boundary_surface(mesh);
  }
  return p;
}

void write_airflow_outputs(const AirflowJob& job, Partition& part, const PieceSolves& solves,
                           const ns::FlowField& field, const PatchOpenings& openings,
                           AirflowResult& r) {
  const BoundaryShear shear = flow_results(job, part, solves, field, openings, r);
  // Files, in millimetres again.
  for (auto& x : part.piece.mesh.nodes) x *= r.d_in_mm;
  for (auto& x : part.surface.nodes) x *= r.d_in_mm;
  write_volume(job, part, field, r, r.written);
  // Memory: the largest rank's peak is what each machine of a cluster must have, the sum what
  // the run took in all.
  const auto mine = static_cast<unsigned long long>(peak_memory_bytes());
  unsigned long long largest = mine, sum = mine;
  MPI_Allreduce(&mine, &largest, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, PETSC_COMM_WORLD);
  MPI_Allreduce(&mine, &sum, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, PETSC_COMM_WORLD);
  MPI_Comm_size(PETSC_COMM_WORLD, &r.ranks);
  r.peak_memory = largest;
  r.total_peak_memory = sum;
  const SolutionState final_state = solves.state_at(field, r.reynolds);  // collective
  if (!solves.writer()) return;
  write_boundary(job, part, shear, job.density * r.u_in * r.u_in, r.written);
  const fs::path h5 = job.output / "solution.h5";
  write_solution_h5(final_state, h5, &part.counts, job.mesh);
  r.written.push_back(h5.string());
  r.written.push_back(fs::path(h5).replace_extension(".xdmf").string());
  const fs::path csv = job.output / "residuals.csv";
  write_residual_history(r.steps, csv);
  r.written.push_back(csv.string());
  // The first rank also wrote the files: its own peak may have grown since (a peak only grows).
  const std::size_t own = peak_memory_bytes();
  r.total_peak_memory += own - std::min<std::size_t>(own, mine);
  r.peak_memory = std::max(r.peak_memory, own);
}

namespace {

// All ranks' peak memory over the unknowns, four per node.
double bytes_per_unknown(const AirflowResult& r) {
  return r.nodes > 0
             ? static_cast<double>(r.total_peak_memory) / (4.0 * static_cast<double>(r.nodes))
             : 0.0;
}

}  // namespace

void write_summary_json(const AirflowJob& job, AirflowResult& r) {
  Json patches = Json::array(), steps = Json::array();
  for (const auto& p : r.patches) {
    Json force = Json::array(), pressure = Json::array(), viscous = Json::array();
    for (int c = 0; c < 3; ++c) {
      force.push_back(significant(p.force[c]));
      pressure.push_back(significant(p.pressure_force[c]));
      viscous.push_back(significant(p.viscous_force[c]));
    }
    patches.push_back({{"name", p.name},
                       {"area_mm2", significant(p.area_mm2)},
                       {"force_n", force},
                       {"pressure_force_n", pressure},
                       {"viscous_force_n", viscous},
                       {"mean_wall_shear_pa", significant(p.mean_shear)},
                       {"max_wall_shear_pa", significant(p.max_shear)}});
  }
  for (const auto& s : r.steps)
    steps.push_back({{"reynolds", significant(s.reynolds)},
                     {"converged", s.converged},
                     {"arclength", s.arclength},
                     {"nonlinear_iterations", s.iterations},
                     {"linear_iterations", s.linear_iterations},
                     {"preconditioner_builds", s.preconditioner_builds},
                     {"residual", significant(s.residual, 7)},
                     {"seconds", significant(s.seconds, 6)}});
  Json openings = Json::array();
  for (const auto& o : r.openings)
    openings.push_back(
        {{"area_mm2", significant(o.area_mm2)},
         {"centroid_mm",
          {significant(o.centroid_mm[0]), significant(o.centroid_mm[1]),
           significant(o.centroid_mm[2])}},
         {"flow_ml_s", significant(o.flow_ml_s)},
         {"share", significant(r.inlet_flow_ml_s != 0.0 ? o.flow_ml_s / r.inlet_flow_ml_s : 0.0)}});
  // A perturbation grows like exp(−λ t) (linear_stability.h); t in d_in/U_in.
  Json modes = Json::array();
  for (const auto& m : r.modes)
    modes.push_back(
        {{"eigenvalue_real", significant(m.eigenvalue.real())},
         {"eigenvalue_imag", significant(m.eigenvalue.imag())},
         {"growth_rate_per_s", significant(-m.eigenvalue.real() * r.u_in / (r.d_in_mm * kMm))},
         {"relative_residual", significant(m.residual, 3)}});
  const Json summary = {
      {"mesh", job.mesh.string()},
      {"cells", r.cells},
      {"nodes", r.nodes},
      {"reynolds", significant(r.reynolds)},
      {"inlet_speed_m_s", significant(r.u_in)},
      {"inlet_hydraulic_diameter_mm", significant(r.d_in_mm)},
      {"inlet_area_mm2", significant(r.inlet_area_mm2)},
      {"inlet_perimeter_mm", significant(r.inlet_perimeter_mm)},
      // naris planes also reports the inlet's perimeter smoothed at the voxel scale.
      {"reynolds_defined_on", "d_in = 4A/P with P the inlet outline as meshed (raw)"},
      {"viscosity_m2_s", significant(job.viscosity)},
      {"density_kg_m3", significant(job.density)},
      {"drive", drive_name(job)},
      {"inlet_profile", profile_name(job)},
      {"flow_ml_s", significant(r.flow_ml_s)},
      {"inlet_flow_ml_s", significant(r.inlet_flow_ml_s)},
      {"outlet_flow_ml_s", significant(r.outlet_flow_ml_s)},
      {"openings", openings},
      {"pressure_drop_pa", significant(r.pressure_drop_pa)},
      // Driven at the outlet: from the still air (total pressure 0) to the outlet's mean.
      {"pressure_drop_from_ambient_pa",
       job.drive == ns::DrivenPatch::outlet ? significant(r.ambient_drop_pa) : Json(nullptr)},
      {"resistance_pa_s_ml", significant(r.resistance)},
      {"max_speed_m_s", significant(r.max_speed)},
      {"patches", patches},
      {"momentum_balance", significant(r.momentum_balance, 3)},
      {"stability", modes},
      {"continuation", steps},
      {"mpi_ranks", r.ranks},
      {"seconds", significant(r.seconds)},
      {"peak_memory_mb", significant(megabytes(r.peak_memory), 5)},
      {"peak_memory_all_ranks_mb", significant(megabytes(r.total_peak_memory), 5)},
      {"peak_bytes_per_unknown", significant(bytes_per_unknown(r), 4)}};
  const fs::path json = job.output / "summary.json";
  write_json_file(json, summary);
  r.written.push_back(json.string());
  r.written.push_back((job.output / "checkpoint.h5").string());
}

std::string format_airflow_summary(const AirflowJob& job, const AirflowResult& r) {
  AirflowResult::Patch wall;
  for (const auto& p : r.patches)
    if (p.name == "wall") wall = p;
  int picard = 0;
  for (const auto& s : r.steps) picard += s.iterations;
  std::string openings;
  if (r.openings.size() > 1) {
    openings = "\n  openings ";
    for (std::size_t k = 0; k < r.openings.size(); ++k) {
      const auto& o = r.openings[k];
      openings += fmt::format(
          "{}{}: {:.1f} mm² at ({:.1f}, {:.1f}, {:.1f}) mm, {:.2f} mL/s ({:.1f} %)", k ? "; " : " ",
          k + 1, o.area_mm2, o.centroid_mm[0], o.centroid_mm[1], o.centroid_mm[2], o.flow_ml_s,
          r.inlet_flow_ml_s != 0.0 ? 100.0 * o.flow_ml_s / r.inlet_flow_ml_s : 0.0);
    }
  }
  std::string stability;
  if (!r.modes.empty()) {
    std::vector<std::string> values;
    bool stable = true;
    for (const auto& m : r.modes) {
      values.push_back(
          m.eigenvalue.imag() == 0.0
              ? fmt::format("{:.4g}", m.eigenvalue.real())
              : fmt::format("{:.4g} {:+.4g}i", m.eigenvalue.real(), m.eigenvalue.imag()));
      stable = stable && m.eigenvalue.real() > 0.0;
    }
    stability = fmt::format(
        "\n  stability λ nearest 0 (U_in/d_in): {}; {}", fmt::join(values, ", "),
        stable ? "none grows" : "a perturbation grows (Re λ < 0): the steady flow is unstable");
  }
  const bool outlet_driven = job.drive == ns::DrivenPatch::outlet;
  return fmt::format(
      "naris solve: {} ({} cells, {} nodes)\n"
      "  inlet     A {:.2f} mm², P {:.2f} mm, d_in = 4A/P {:.3f} mm; {} profile at the {}\n"
      "  scales    Re {:.1f}, U_in {:.4f} m/s, ν {:.3g} m²/s, ρ {:.3g} kg/m³\n"
      "  flow      {:.2f} mL/s in, {:.2f} mL/s out; {:.2f} mL/s imposed {} the {}{}\n"
      "  pressure  drop inlet→outlet {:.3f} Pa; resistance {:.4f} Pa·s/mL{}\n"
      "  speed     max {:.3f} m/s\n"
      "  wall      shear stress mean {:.4f} Pa, max {:.4f} Pa; force {:.3e} N (surface "
      "integral {:.3e} N); momentum balance {:.1e}\n"
      "  solve     {} continuation steps, {} nonlinear steps, {:.1f} s, peak {} ({:.0f} bytes "
      "per unknown){}\n"
      "  wrote     {}",
      job.mesh.filename().string(), r.cells, r.nodes, r.inlet_area_mm2, r.inlet_perimeter_mm,
      r.d_in_mm, profile_name(job), drive_name(job), r.reynolds, r.u_in, job.viscosity, job.density,
      r.inlet_flow_ml_s, r.outlet_flow_ml_s, r.flow_ml_s, outlet_driven ? "out of" : "into",
      drive_name(job), openings, r.pressure_drop_pa, r.resistance,
      outlet_driven ? fmt::format("; from the still air {:.3f} Pa", r.ambient_drop_pa) : "",
      r.max_speed, wall.mean_shear, wall.max_shear, wall.force.norm(),
      (wall.pressure_force + wall.viscous_force).norm(), r.momentum_balance, r.steps.size(), picard,
      r.seconds,
      r.ranks > 1 ? fmt::format("{:.0f} MB per rank, {:.0f} MB on {} ranks",
                                megabytes(r.peak_memory), megabytes(r.total_peak_memory), r.ranks)
                  : fmt::format("{:.0f} MB", megabytes(r.peak_memory)),
      bytes_per_unknown(r), stability, fmt::join(r.written, "\n            "));
}

}  // namespace naris::airflow
