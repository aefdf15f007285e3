#include "app/stage_settings.h"

#include <sstream>

#include "core/error.h"

namespace naris::app {

std::filesystem::path resolve_path(const std::filesystem::path& base,
                                   const std::filesystem::path& p) {
  return base.empty() || p.is_absolute() ? p : base / p;
}

InterpolateSettings::InterpolateSettings() {
  table.add("method", method, "hsr, linear or shape").one_of({"hsr", "linear", "shape"});
  table.add("axis", job.axis, "slice axis: i, j, k, or auto (the coarsest)")
      .one_of({"auto", "i", "j", "k"});
  table.add("insert", job.insert, "slices to insert between each pair").non_negative();
  table
      .add("spacing", job.spacing,
           "target spacing along the axis (mm); default: the finest in-plane spacing")
      .positive();
  table.add("block", job.hsr.block, "HSR control-grid block size (pixels)").range(2, 256);
  table.add("levels", job.hsr.levels, "HSR pyramid levels").range(1, 12);
  table.add("iterations", job.hsr.iterations, "HSR iterations per level").range(1, 1000);
  table.add("threads", job.threads, "threads over slice pairs (0: every core)").non_negative();
}

InterpolateJob InterpolateSettings::resolve() const {
  if (table.given("insert") && table.given("spacing"))
    fail("give either insert or spacing, not both");
  InterpolateJob j = job;
  j.method = parse_slice_method(method);
  return j;
}

SegmentSettings::SegmentSettings() {
  table.add("threshold", job.threshold, "HU threshold, or 'auto'");
  table.add("inside", inside, "the airway is 'below' or 'above' the threshold")
      .one_of({"below", "above"});
  table.add("seed", job.seeds,
            "seed voxel i,j,k or point x,y,z mm in the airway; repeatable (with airway nasal, "
            "points the airway must hold)");
  table.add("all_components", all_components, "keep every component (default: the largest)");
  table.add("rotate", job.rotate,
            "rotate the volume first, AXIS:DEGREES about image axis i, j or k (e.g. i:30); "
            "seeds in voxels then refer to the rotated grid, seeds in mm do not change");
  table.add("decimate", job.decimate, "average N×N blocks of each slice first").range(1, 16);
  table
      .add("airway", job.airway,
           "'any': the region grown from the seeds; 'nasal': the nasal airway of a head CT, "
           "without seeds (room air cut at the nares, sinuses left out, inlet and outlet planes "
           "written to OUTPUT.json for the mesher's 'auto')")
      .one_of({"any", "nasal"});
  table.add("side", side, "with airway nasal: the right or left cavity to its choana, or both")
      .one_of({"right", "left", "both"});
  table
      .add("nasopharynx", nasopharynx,
           "with airway nasal: 'cut' at the choana (both sides: just behind it) or 'keep' it")
      .one_of({"cut", "keep"});
}

SegmentJob SegmentSettings::resolve() const {
  SegmentJob j = job;
  j.inside = parse_threshold_side(inside);
  j.keep_largest = !all_components;
  j.side = parse_nasal_side(side);
  j.keep_nasopharynx = nasopharynx == "keep";
  if (j.airway != "nasal" && (table.given("side") || table.given("nasopharynx")))
    fail("side and nasopharynx belong to airway nasal");
  return j;
}

MeshSettings::MeshSettings() {
  table.add("threshold", job.threshold, "inside is below T (CT air; see inside)");
  table.add("label", job.label,
            "inside is the voxels with label L, or any of L1,L2,… (a union), by value or by the "
            "segment names of a 3D Slicer segmentation (default for 0/1 labelmaps: 1)");
  table.add("inside", inside, "with a threshold: inside is 'below' or 'above' T")
      .one_of({"below", "above"});
  table.add("inlet", job.inlet,
            "inlet cut plane: voxel index (e.g. j=19) or physical p=x,y,z;n=nx,ny,nz (mm), or "
            "'auto' (the naris plane of segment --airway nasal); with an outlet, the part between "
            "the two is kept; alone, the side towards the object's centre");
  table.add("outlet", job.outlet, "outlet cut plane, same forms as inlet ('auto': the choana)");
  table
      .add("outlet_extension", job.outlet_extension,
           "a straight tube of the outlet's section, this many mm long, added beyond an outlet "
           "along an image axis, so that the flow leaves where the outlet is traction-free (0: "
           "none)")
      .non_negative();
  table.add("patch", job.regions,
            "carve a named patch out of the wall: name:box=x0,y0,z0,x1,y1,z1 or "
            "name:sphere=x,y,z,r (mm); repeatable");
  table
      .add("smooth", job.smooth,
           "a labelmap's wall on a smooth surface: its signed distance smoothed by a Gaussian "
           "this many voxels wide, every voxel kept on its side (0: the staircase)")
      .range(0.0, 3.0);
  table.add("improve", job.improve, "the quality improvement of section 3.3");
  table
      .add("min_edge", job.improve_options.min_edge_fraction,
           "improvement: collapse edges shorter than this fraction of the voxel size")
      .range(0.0, 0.5);
  table.add("relocate", job.relocate,
            "after the collapses, move the nodes of cells below the quality targets (wall nodes "
            "sliding on the surface, cut-plane nodes in their plane) and remove wall slivers");
  table
      .add("subdivide", job.subdivisions,
           "refine N times after the improvement, each time every cell into 8 of half its size "
           "filling the same volume (same wall, inlet and outlet; for mesh-convergence studies)")
      .range(0, 3);
  table.add("all_components", all_components,
            "keep every connected component (default: the largest only)");
  table.add("check", job.check, "the conformity/watertightness check");
  table.add("threads", job.threads, "threads for the quality report and the check (0: every core)")
      .non_negative();
  table.add("msh", job.write_msh, "the Gmsh file");
}

MeshJob MeshSettings::resolve() const {
  if (table.given("threshold") && table.given("label"))
    fail("give either threshold or label, not both");
  MeshJob j = job;
  j.inside = parse_threshold_side(inside);
  j.keep_largest = !all_components;
  return j;
}

SolveSettings::SolveSettings() {
  nonlinear::NonlinearOptions& n = job.nonlinear;
  table.add("re", job.reynolds, "target Reynolds number on the inlet's d_in = 4A/P").positive();
  table.add("inlet_speed", job.inlet_speed,
            "mean inlet speed (m/s) instead of re; Re then follows from it");
  table
      .add("drive", drive,
           "inlet: the flow blown into the inlet, the outlet traction-free (the dissertation's "
           "models); outlet: the same flow drawn out of the outlet, the inlet open to still air "
           "at zero total pressure, so that its openings (both nares) share the flow as the flow "
           "decides")
      .one_of({"inlet", "outlet"});
  table
      .add("inlet_profile", inlet_profile,
           "uniform or developed (laminar, any shape): the velocity's shape on the driven patch")
      .one_of({"uniform", "developed"});
  table.add("inlet_expression", job.inlet_expression,
            "inlet profile as an expression of x, y, z and r (mm; r from the inlet's centroid), "
            "e.g. \"1-(r/1.5)^2\"; scaled to the mean inlet speed");
  table
      .add("backflow_smoothing", job.backflow_smoothing,
           "width of the smoothing of the outlet's backflow switch (u·n)₋, in mean inlet speeds, "
           "so that Newton's derivative is continuous where the flow through the outlet turns "
           "(0: the exact switch)")
      .non_negative();
  table
      .add("stability", job.stability_modes,
           "after the solve, the N eigenvalues λ of the steady flow's linearization nearest zero "
           "(J v = λ M v, SLEPc; one more to keep a complex pair whole, and any other growing "
           "one found): a perturbation grows where Re λ < 0 (0: none)")
      .non_negative();
  table.add("nu", job.viscosity, "kinematic viscosity (m²/s)");
  table.add("rho", job.density, "density (kg/m³)");
  table.add("re_start", job.start_reynolds, "first Reynolds number of the continuation");
  table.add("max_steps", job.max_steps, "continuation steps at most").positive();
  table
      .add("max_iterations", n.max_iterations,
           "nonlinear (Picard or Newton) iterations per continuation step at most (500 with the "
           "segregated scheme unless given)")
      .positive();
  table
      .add("scheme", scheme,
           "coupled (Picard then Newton, GMRES on ILU), segregated (FiDAP's momentum / "
           "pressure-correction sweeps on algebraic multigrid; Picard only) or segregated-gmres "
           "(GMRES on the whole system preconditioned by one such sweep)")
      .one_of({"coupled", "segregated", "segregated-gmres"});
  table
      .add("velocity_relaxation", n.velocity_relaxation,
           "segregated: momentum under-relaxation α_u")
      .range(0.01, 1.0);
  table
      .add("pressure_relaxation", n.pressure_relaxation,
           "segregated: pressure-correction relaxation α_p")
      .range(0.01, 1.0);
  table.add("picard_steps", n.picard_steps, "Picard steps before Newton's method takes over")
      .non_negative();
  table.add("newton", n.newton, "Newton's method after the Picard steps (off: Picard only)");
  table
      .add("linear_tolerance", n.linear_tolerance,
           "each linear solve's residual reduction, at the tightest")
      .range(1e-14, 0.5);
  table
      .add("linear_tolerance_max", n.loosest_linear_tolerance,
           "the loosest reduction, where the nonlinear residual falls slowly (Eisenstat–Walker; "
           "equal to linear_tolerance: fixed)")
      .range(1e-14, 0.5);
  table
      .add("tolerance", n.tolerance,
           "nonlinear residual relative to the load, per step (0: the absolute tolerance only)")
      .non_negative();
  table
      .add("step_tolerance", job.step_tolerance,
           "nonlinear residual of the continuation steps before the target (the target's is "
           "tolerance)")
      .positive();
  table
      .add("pseudo_cfl", n.pseudo_cfl,
           "pseudo-transient continuation: first Courant number, grown as the residual falls "
           "(0: off)")
      .non_negative();
  table
      .add("arclength_steps", job.arclength_steps,
           "where the continuation in Re stalls at a turning point, follow the steady branch by "
           "pseudo-arclength continuation for at most N points (0: stop there)")
      .non_negative();
  table.add("rebuild_preconditioner", rebuild_preconditioner,
            "set the linear solver's preconditioner up anew for every nonlinear step (by default "
            "it is kept while that saves work)");
  table
      .add("relaxation", n.relaxation,
           "largest step fraction (0, 1]; the step is cut back while the residual grows")
      .range(0.01, 1.0);
  table.add("restart", restart,
            "resume the continuation from a checkpoint (the output folder's checkpoint.h5 is "
            "rewritten after every converged step)");
  table.add("restart_mesh", restart_mesh,
            "the mesh the restart file belongs to, when the mesh solved is that mesh subdivided "
            "(naris mesh --subdivide): its field is prolonged onto this one and may be at the "
            "target Re itself");
  table.add("verbose", verbose, "a line per nonlinear (Picard or Newton) step");
  table
      .add("progress", n.progress_seconds,
           "seconds between progress lines in a long solve: a nonlinear step's line, and within "
           "a linear solve that runs longer, its residual (0: none)")
      .non_negative();
  table.add("petsc", petsc,
            "PETSc options for the linear solves (prefix ns_), e.g. \"-ns_ksp_monitor\"");
}

airflow::AirflowJob SolveSettings::resolve(const std::filesystem::path& base) const {
  if (table.given("inlet_expression") && table.given("inlet_profile"))
    fail("give either inlet_profile or inlet_expression, not both");
  if (restart_mesh && !restart) fail("restart_mesh needs restart (the checkpoint to prolong)");
  airflow::AirflowJob j = job;
  using Scheme = nonlinear::NonlinearOptions::Scheme;
  j.nonlinear.scheme = scheme == "segregated"         ? Scheme::segregated
                       : scheme == "segregated-gmres" ? Scheme::segregated_krylov
                                                      : Scheme::coupled;
  // Linear convergence, a few percent per sweep: many more steps than Newton's.
  if (j.nonlinear.scheme == Scheme::segregated && !table.given("max_iterations"))
    j.nonlinear.max_iterations = 500;
  j.nonlinear.reuse_preconditioner = !rebuild_preconditioner;
  j.nonlinear.log_iterations = verbose;
  j.drive = drive == "outlet" ? ns::DrivenPatch::outlet : ns::DrivenPatch::inlet;
  j.profile = table.given("inlet_expression") ? ns::InletProfile::expression
              : inlet_profile == "developed"  ? ns::InletProfile::developed
                                              : ns::InletProfile::uniform;
  if (restart) j.restart = resolve_path(base, *restart);
  if (restart_mesh) j.restart_mesh = resolve_path(base, *restart_mesh);
  return j;
}

namespace {
// Planes by point and normal, and the anterior–posterior axis of planes by distance (trace and
// planes alike).
void add_plane_settings(Settings& table, std::vector<std::string>& planes, std::string& axis) {
  table.add("plane", planes, "a plane by point and normal p=x,y,z;n=nx,ny,nz (mm); repeatable");
  table
      .add("axis", axis,
           "the anterior–posterior axis of planes by distance: inlet-outlet (from the inlet's "
           "centroid to the outlet's) or an image axis x, y, z, -x, -y, -z")
      .one_of({"inlet-outlet", "x", "y", "z", "-x", "-y", "-z"});
}
}  // namespace

TraceSettings::TraceSettings() {
  table.add("mesh", mesh, "the mesh.h5 solved on (default: the one the solution names)");
  table
      .add("release", job.release,
           "where particles start: dissertation (section 4.3.1's three groups on the naris: "
           "ventral tip, midline, dorsal tip), grid (a regular grid on the naris), random "
           "(flux-weighted on the naris), line (see line) or points (see points)")
      .one_of({"dissertation", "grid", "random", "line", "points"});
  table
      .add("count", job.count,
           "particles per group (dissertation), points across the naris (grid), particles "
           "(random, line)")
      .positive();
  table.add("offset", job.offset_mm, "distance of release points from the naris wall (mm)")
      .non_negative();
  table.add("random_seed", job.seed, "seed of the random release (the same seed, the same points)");
  table.add("line", job.line, "release line x0,y0,z0;x1,y1,z1 (mm)");
  table.add("points", points, "release points: a CSV file of x,y,z (mm)[,group]");
  table.add("diameter", diameter,
            "particle diameters (µm), comma-separated, e.g. 0,1,5,10; 0 or none: massless tracers");
  table.add("density", density, "particle density (kg/m³), one for all or one per diameter");
  table.add("planes", planes,
            "cross-section planes as distances (mm) from the airway's most anterior point along "
            "the axis, comma-separated, e.g. 33.5,44,54.5,65,75.5,85");
  add_plane_settings(table, job.planes, job.plane_axis);
  table.add("gravity", job.gravity,
            "down (−z: the patient's inferior in LPS, for an upright subject), none, or gx,gy,gz "
            "(m/s²)");
  table.add("drag", job.drag, "stokes or schiller-naumann").one_of({"stokes", "schiller-naumann"});
  table.add("tolerance", job.tolerance, "local position error per step, in cell sizes").positive();
  table.add("max_step", job.max_step, "cell sizes a step may move").positive();
  table.add("max_time", job.max_time, "residence time at most (s)").positive();
  table
      .add("stagnation", job.stagnation, "a particle slower than this (in units of U_in) stagnates")
      .non_negative();
  table.add("path_spacing", job.path_spacing_mm, "spacing of recorded path points (mm)").positive();
  table.add("max_paths", job.max_paths, "paths written for the first N particles").non_negative();
  table.add("figures", figures, "the PNG figures of the paths and the crossings");
}

namespace {
std::vector<double> number_list(const std::string& text, const char* what) {
  std::vector<double> v;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ','))
    if (!item.empty()) v.push_back(parse_setting_double(item, what));
  return v;
}
}  // namespace

particles::TraceJob TraceSettings::resolve(const std::filesystem::path& base) const {
  particles::TraceJob j = job;
  if (mesh) j.mesh = resolve_path(base, *mesh);
  if (points) j.points = resolve_path(base, *points);
  if (table.given("points") && job.release != "points") fail("points needs release: points");
  if (table.given("line") && job.release != "line") fail("line needs release: line");
  j.diameters_um = number_list(diameter, "diameter");
  j.densities = number_list(density, "density");
  j.plane_distances_mm = number_list(planes, "planes");
  return j;
}

PlanesSettings::PlanesSettings() {
  table.add("mesh", mesh, "the mesh.h5 solved on (default: the one the solution names)");
  table.add("at", at,
            "planes at these distances (mm) from the airway's most anterior point along the axis, "
            "comma-separated; empty: none");
  add_plane_settings(table, job.planes, job.axis);
  table
      .add("smoothing", job.smoothing,
           "width of the Gaussian that smooths the outline before its length is taken, in voxels")
      .positive();
  table.add("levels", job.levels, "speed bands and contour levels, 0 at the wall to the maximum")
      .range(2, 64);
  table.add("arrows", job.arrows_across, "secondary-velocity arrows across the section")
      .range(2, 200);
  table.add("crossings", crossings,
            "crossings.csv of naris trace: the particles' crossing points drawn on the planes");
  table.add("figures", job.figures, "a PNG and an SVG figure per plane");
}

planes::PlanesJob PlanesSettings::resolve(const std::filesystem::path& base) const {
  planes::PlanesJob j = job;
  if (mesh) j.mesh = resolve_path(base, *mesh);
  if (crossings) j.crossings = resolve_path(base, *crossings);
  j.distances_mm = number_list(at, "at");
  return j;
}

}  // namespace naris::app
