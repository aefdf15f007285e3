#include "solver/particles/trace_job.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "core/error.h"
#include "core/log.h"
#include "core/units.h"
#include "mesh/io/mesh_h5.h"
#include "mesh/patches/patches.h"
#include "mesh/patches/section_planes.h"
#include "solver/airflow/solution_file.h"
#include "solver/particles/mesh_flow.h"
#include "solver/particles/trace_outputs.h"

namespace naris::particles {
namespace {

namespace fs = std::filesystem;

Vec3 parse_vector(const std::string& text, const std::string& what) {
  std::string t = text;
  std::replace(t.begin(), t.end(), ',', ' ');
  std::istringstream in(t);
  Vec3 v;
  std::string rest;
  if (!(in >> v[0] >> v[1] >> v[2]) || (in >> rest)) fail("{} '{}': expected x,y,z", what, text);
  return v;
}

Vec3 gravity_of(const std::string& text) {
  if (text == "none") return Vec3::Zero();
  if (text == "down") return Vec3(0.0, 0.0, -9.81);
  return parse_vector(text, "gravity");
}

// The planes (m), each checked to cut the airway.
std::vector<Plane> make_planes(const TraceJob& job, const HybridMesh& m,
                               std::vector<std::string>& labels) {
  const std::vector<SectionPlane> sections = section_planes(
      m, job.plane_distances_mm.empty() ? SectionAxis{} : section_axis(m, job.plane_axis),
      job.plane_distances_mm, job.planes);
  std::vector<Plane> planes;
  for (const SectionPlane& p : sections) {
    planes.push_back({p.point * kMm, p.normal});
    labels.push_back(p.label);
  }
  return planes;
}

ReleaseSet make_release(const TraceJob& job, const HybridMesh& m, int inlet,
                        const std::optional<InletShape>& naris, std::span<const Vec3> velocity,
                        bool& on_inlet) {
  on_inlet = job.release != "points" && job.release != "line";
  if (on_inlet && !naris) fail("release '{}' needs the mesh's inlet patch", job.release);
  if (job.release == "dissertation")
    return dissertation_groups(*naris, job.offset_mm * kMm, job.count);
  if (job.release == "grid") return grid_release(*naris, job.count, job.offset_mm * kMm);
  if (job.release == "random")
    return flux_weighted_release(m, inlet, velocity, job.count,
                                 static_cast<std::uint64_t>(job.seed));
  if (job.release == "line") {
    const auto semi = job.line.find(';');
    if (semi == std::string::npos) fail("release line '{}': expected x0,y0,z0;x1,y1,z1", job.line);
    return line_release(parse_vector(job.line.substr(0, semi), "release line") * kMm,
                        parse_vector(job.line.substr(semi + 1), "release line") * kMm, job.count);
  }
  if (job.release == "points") {
    if (job.points.empty()) fail("release 'points' needs a file of points");
    return read_release_points(job.points.string());
  }
  fail("unknown release '{}' (dissertation, grid, random, line or points)", job.release);
}

// Doubles in, doubles out: a particle's result for the gather to rank 0.
void pack(const ParticleResult& r, int id, std::vector<double>& out) {
  out.insert(out.end(),
             {static_cast<double>(id), static_cast<double>(r.fate), static_cast<double>(r.patch),
              r.time, r.length, r.end[0], r.end[1], r.end[2], r.contact[0], r.contact[1],
              r.contact[2], static_cast<double>(r.steps), static_cast<double>(r.rejected),
              static_cast<double>(r.cell_tests), static_cast<double>(r.visited),
              static_cast<double>(r.crossings.size()), static_cast<double>(r.path.size())});
  for (const Crossing& c : r.crossings)
    out.insert(out.end(), {static_cast<double>(c.plane), c.x[0], c.x[1], c.x[2], c.time});
  for (const PathPoint& p : r.path)
    out.insert(out.end(), {p.x[0], p.x[1], p.x[2], p.time, p.speed});
}

std::size_t unpack(const double* d, std::vector<ParticleResult>& results) {
  const double* start = d;
  const auto id = static_cast<std::size_t>(*d++);
  ParticleResult& r = results[id];
  r.fate = static_cast<Fate>(static_cast<int>(*d++));
  r.patch = static_cast<int>(*d++);
  r.time = *d++;
  r.length = *d++;
  for (int a = 0; a < 3; ++a) r.end[a] = *d++;
  for (int a = 0; a < 3; ++a) r.contact[a] = *d++;
  r.steps = static_cast<long>(*d++);
  r.rejected = static_cast<long>(*d++);
  r.cell_tests = static_cast<long>(*d++);
  r.visited = static_cast<std::uint32_t>(*d++);
  r.crossings.resize(static_cast<std::size_t>(*d++));
  r.path.resize(static_cast<std::size_t>(*d++));
  for (Crossing& c : r.crossings) {
    c.plane = static_cast<int>(*d++);
    c.x = Vec3(d[0], d[1], d[2]);
    d += 3;
    c.time = *d++;
  }
  for (PathPoint& p : r.path) {
    p.x = Vec3(d[0], d[1], d[2]);
    p.time = d[3];
    p.speed = d[4];
    d += 5;
  }
  return static_cast<std::size_t>(d - start);
}

}  // namespace

TraceResult run_trace_job(const TraceJob& job) {
  Stopwatch clock;
  // Under an MPI session the ranks share the particles; without one (or after it), serial.
  int rank = 0, ranks = 1, mpi = 0, finalized = 0;
  MPI_Initialized(&mpi);
  MPI_Finalized(&finalized);
  if (mpi && !finalized) {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  }
  // Inputs, all checked before anything is written.
  const airflow::SolvedMesh solved =
      airflow::read_solved_mesh(job.solution, job.mesh ? *job.mesh : fs::path{});
  const airflow::SolutionState& state = solved.state;
  const HybridMesh& mesh = solved.mesh;
  const std::vector<Vec3>& velocity = solved.velocity;

  TraceOptions o;
  o.tolerance = job.tolerance;
  o.max_step = job.max_step;
  o.max_time = job.max_time;
  o.stagnation_speed = job.stagnation * state.u_in;
  o.path_spacing = job.path_spacing_mm * kMm;
  o.gravity = gravity_of(job.gravity);
  o.drag = parse_drag_law(job.drag);
  o.air.density = state.density;
  o.air.viscosity = state.viscosity * state.density;
  for (double x : {job.tolerance, job.max_step, job.max_time})
    if (!(x > 0.0)) fail("tolerance, max_step and max_time must be positive");

  std::vector<ParticleKind> kinds;
  if (job.diameters_um.empty()) kinds.push_back({});
  if (job.densities.size() != 1 && job.densities.size() != job.diameters_um.size())
    fail("give one density, or one per diameter ({} diameters, {} densities)",
         job.diameters_um.size(), job.densities.size());
  for (std::size_t i = 0; i < job.diameters_um.size(); ++i) {
    const double d = job.diameters_um[i], rho = job.densities[job.densities.size() == 1 ? 0 : i];
    if (!(d >= 0.0)) fail("particle diameter {} µm: must not be negative (0: a tracer)", d);
    if (!(rho > 0.0)) fail("particle density {} kg/m³: must be positive", rho);
    kinds.push_back({d * 1e-6, d > 0.0 ? rho : 0.0});
  }

  std::vector<int> open;
  for (std::size_t p = 0; p < mesh.patch_names.size(); ++p)
    if (is_open_patch(mesh.patch_names[p])) open.push_back(static_cast<int>(p));
  const int inlet = mesh.patch_id("inlet");
  const Vec3 up = o.gravity.norm() > 0.0 ? Vec3(-o.gravity.normalized()) : Vec3::UnitZ();
  std::optional<InletShape> naris;
  if (inlet >= 0) naris = inlet_shape(mesh, inlet, up);
  std::vector<std::string> plane_labels;
  const std::vector<Plane> planes = make_planes(job, mesh, plane_labels);
  bool on_inlet = false;
  ReleaseSet release = make_release(job, mesh, inlet, naris, velocity, on_inlet);
  const MeshFlow flow(mesh, velocity, open);
  // Seeds on the inlet go onto its faces (the patch need not be planar), then just inside.
  std::vector<int> start_cell(release.points.size());
  for (std::size_t i = 0; i < release.points.size(); ++i) {
    start_cell[i] =
        on_inlet ? seed_inside(*naris, flow, release.points[i]) : flow.locate(release.points[i]);
    if (start_cell[i] < 0) {
      const Vec3 x = release.points[i] / kMm;
      fail("release point {} ({:.4g}, {:.4g}, {:.4g} mm) lies outside the airway", i + 1, x[0],
           x[1], x[2]);
    }
  }
  // Region patches: named wall patches (not "wall"), each as the box of its faces.
  TraceResult result;
  result.patch_names = mesh.patch_names;
  for (const RegionBox& box : region_boxes(mesh)) {
    if (o.regions.size() == 32) {
      log_line(
          fmt::format("naris trace: more than 32 region patches; visits to '{}' and later "
                      "ones are not counted",
                      mesh.patch_names[static_cast<std::size_t>(box.patch)]));
      break;
    }
    o.regions.push_back({box.lo * kMm, box.hi * kMm});
    result.region_patches.push_back(box.patch);
  }

  // Every ranks-th particle here; progress from rank 0's share.
  if (release.points.size() * kinds.size() >
      static_cast<std::size_t>(std::numeric_limits<int>::max()))
    fail("{} release points × {} species: too many particles for one run", release.points.size(),
         kinds.size());
  const int per_kind = static_cast<int>(release.points.size());
  const int total = per_kind * static_cast<int>(kinds.size());
  log_line(
      fmt::format("naris trace: {} particles ({} release points × {} species), {} plane(s), "
                  "{} cells{}",
                  total, per_kind, kinds.size(), planes.size(), flow.cells(),
                  ranks > 1 ? fmt::format(", {} ranks", ranks) : ""));
  Stopwatch tracking;
  std::vector<double> mine;
  long steps = 0, tests = 0;
  int done = 0, next_report = 1;
  const int my_total = (total - rank + ranks - 1) / ranks;
  for (int id = rank; id < total; id += ranks) {
    const int p = id % per_kind, k = id / per_kind;
    ParticleStart start{release.points[static_cast<std::size_t>(p)], std::nullopt,
                        start_cell[static_cast<std::size_t>(p)]};
    const ParticleResult r =
        track(flow, start, kinds[static_cast<std::size_t>(k)], o, planes, id < job.max_paths);
    steps += r.steps;
    tests += r.cell_tests;
    pack(r, id, mine);
    ++done;
    // Progress in tenths of rank 0's share, once the run has taken a second.
    if (rank == 0 && done * 10 >= next_report * my_total && done < my_total &&
        tracking.seconds() > 1.0) {
      log_line(fmt::format("  {} %: {} of {} particles here, {:.1f} s", next_report * 10, done,
                           my_total, tracking.seconds()));
      next_report = done * 10 / my_total + 1;
    }
  }
  const double track_seconds = tracking.seconds();

  // Gather on rank 0; MPI counts are int, so every rank first learns whether they fit.
  if (ranks > 1) {
    long long here = static_cast<long long>(mine.size()), sum = 0;
    MPI_Allreduce(&here, &sum, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    if (sum > std::numeric_limits<int>::max())
      fail("the paths are too many to gather ({} values); lower max_paths or raise path_spacing",
           sum);
    const int count = static_cast<int>(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(ranks)),
        offsets(static_cast<std::size_t>(ranks));
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<double> gathered;
    if (rank == 0) {
      for (int r = 1; r < ranks; ++r)
        offsets[static_cast<std::size_t>(r)] =
            offsets[static_cast<std::size_t>(r - 1)] + counts[static_cast<std::size_t>(r - 1)];
      gathered.resize(static_cast<std::size_t>(sum));
    }
    MPI_Gatherv(mine.data(), count, MPI_DOUBLE, gathered.data(), counts.data(), offsets.data(),
                MPI_DOUBLE, 0, MPI_COMM_WORLD);
    long sums[2] = {steps, tests}, totals[2] = {0, 0};
    MPI_Reduce(sums, totals, 2, MPI_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
    steps = totals[0], tests = totals[1];
    mine.swap(gathered);
  }
  result.ranks = ranks;
  result.particles = total;
  result.steps = steps;
  result.cell_tests = tests;
  result.track_seconds = track_seconds;
  if (rank != 0) return result;
  std::vector<ParticleResult> all(static_cast<std::size_t>(total));
  for (std::size_t at = 0; at < mine.size();) at += unpack(mine.data() + at, all);

  // Counts per group and species.
  for (std::size_t k = 0; k < kinds.size(); ++k)
    for (std::size_t g = 0; g < release.groups.size(); ++g) {
      TraceCounts c;
      c.group = release.groups[g];
      c.diameter_um = kinds[k].diameter * 1e6;
      c.density = kinds[k].tracer() ? 0.0 : kinds[k].density;
      c.deposited.assign(mesh.patch_names.size(), 0);
      c.visited.assign(result.region_patches.size(), 0);
      result.counts.push_back(std::move(c));
    }
  for (int id = 0; id < total; ++id) {
    const ParticleResult& r = all[static_cast<std::size_t>(id)];
    const int p = id % per_kind, k = id / per_kind;
    TraceCounts& c =
        result.counts[static_cast<std::size_t>(k) * release.groups.size() +
                      static_cast<std::size_t>(release.group[static_cast<std::size_t>(p)])];
    ++c.released;
    ++c.fates[static_cast<int>(r.fate)];
    if (r.fate == Fate::wall) ++c.deposited[static_cast<std::size_t>(r.patch)];
    for (std::size_t i = 0; i < result.region_patches.size(); ++i)
      if (r.visited & (1u << i)) ++c.visited[i];
    result.lost += r.fate == Fate::lost;
  }
  result.seconds = clock.seconds();
  write_trace_outputs({job, result, release, kinds, planes, plane_labels, all, mesh, state});
  result.seconds = clock.seconds();
  for (int id = 0; id < total; ++id)
    result.track_group.push_back(release.group[static_cast<std::size_t>(id % per_kind)]);
  result.groups = release.groups;
  result.planes = planes;
  result.plane_labels = plane_labels;
  for_each_boundary_face(mesh, [&](std::span<const NodeId> ids, std::int32_t p) {
    if (is_open_patch(mesh.patch_names[static_cast<std::size_t>(p)])) return;
    for (std::size_t k = 1; k + 1 < ids.size(); ++k)
      result.wall.push_back({mesh.nodes[ids[0]], mesh.nodes[ids[k]], mesh.nodes[ids[k + 1]]});
  });
  result.tracks = std::move(all);
  if (result.lost > 0)
    fail("{} of {} particles were lost (the walk found no cell): see {}", result.lost, total,
         (job.output / "particles.csv").string());
  return result;
}

std::string format_trace_summary(const TraceJob& job, const TraceResult& r) {
  int fates[kFates] = {};
  for (const TraceCounts& c : r.counts)
    for (int f = 0; f < kFates; ++f) fates[f] += c.fates[f];
  std::string s = fmt::format(
      "naris trace: {} particles in {:.1f} s ({:.0f} steps/s, {:.2f} cell tests per step)",
      r.particles, r.seconds, r.steps / std::max(r.track_seconds, 1e-9),
      static_cast<double>(r.cell_tests) / std::max(r.steps, 1L));
  s += "\n  fates:";
  for (int f = 0; f < kFates; ++f)
    s += fmt::format(" {} {}", fate_name(static_cast<Fate>(f)), fates[f]);
  for (std::size_t i = 0; i < r.region_patches.size(); ++i) {
    s += fmt::format("\n  through the {} region:",
                     r.patch_names[static_cast<std::size_t>(r.region_patches[i])]);
    for (const TraceCounts& c : r.counts)
      s += fmt::format(" {}{} {}/{}", c.group,
                       c.diameter_um > 0 ? fmt::format(" ({:g} µm)", c.diameter_um) : "",
                       c.visited[i], c.released);
  }
  s += fmt::format("\n  outputs in {}", job.output.string());
  return s;
}

}  // namespace naris::particles
