#!/usr/bin/env bash
# The bend of bench_deposition (Pui et al. 1987, laminar, Re 1000) with the flow of two solvers
# on one mesh: naris's, and OpenFOAM's simpleFoam (laminar, the mesh through gmshToFoam) whose
# point field (foamToVTK) naris's tracker then follows. For each inlet profile (developed,
# uniform) it prints two tables of deposition per Stokes number: through naris's flow, then
# through OpenFOAM's. The mesh is the tube's 0/1 indicator (bench_deposition --binary): the
# signed distance's slivers (faces 89.6° non-orthogonal) make simpleFoam diverge.
# Usage: bend_openfoam.sh BENCH_DEPOSITION [CELLS_ACROSS = 20] [PARTICLES = 10000] [WORK]
set -euo pipefail
bench=$1
across=${2:-20}
particles=${3:-10000}
work=${4:-$(mktemp -d)}
here=$(dirname "$0")
# Re 1000 in the tube 1 mm across at simplefoam.sh's ν = 1.5e-5 m²/s.
u_in=15
# Poiseuille's parabola about the tube's axis where it meets the inlet (x = 2.85 mm, z = 0),
# mean U_IN over the circle of radius 0.5 mm.
speed="$((2 * u_in)) * max(0, 1 - (sqr(pos().x() - 2.85e-3) + sqr(pos().z())) / sqr(0.5e-3))"
parabola="inlet { type exprFixedValue; value uniform (0 0 0); valueExpr \"vector(0, $speed, 0)\"; }"
for inlet in developed uniform; do
  dir=$work/$inlet
  mkdir -p "$dir"
  flags=(--binary)
  profile=$parabola
  if [ "$inlet" = uniform ]; then
    flags+=(--uniform-inlet)
    profile=""
  fi
  echo
  echo "Inlet profile $inlet, the flow by naris:"
  "$bench" "${flags[@]}" --write-msh "$dir/mesh.msh" "$particles" "$across"
  NARIS_FOAM_INLET_U=$profile NARIS_FOAM_CONVERGE=1 \
    "$here/simplefoam.sh" "$dir/mesh.h5" "$u_in" "$dir" "the bend, $inlet inlet"
  (
    cd "$dir/openfoam"
    set +u
    # shellcheck source=/dev/null
    source /usr/share/openfoam/etc/bashrc > /dev/null 2>&1 || true
    set -u
    foamToVTK -latestTime > foamToVTK.log 2>&1
  )
  # OpenFOAM's points are the mesh's nodes in their order (gmshToFoam keeps it): checked.
  /usr/bin/python3 - "$dir/openfoam" "$dir/mesh.msh" "$u_in" "$dir/velocity.txt" <<'PY'
import glob, sys
import vtk
case, msh, u_in, out = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
reader = vtk.vtkXMLUnstructuredGridReader()
reader.SetFileName(sorted(glob.glob(case + "/VTK/*/internal.vtu"))[-1])
reader.Update()
grid = reader.GetOutput()
points, velocity = grid.GetPoints(), grid.GetPointData().GetArray("U")
lines = open(msh).read().split("$Nodes\n")[1].split("$EndNodes")[0].split("\n")
n = int(lines[0])
with open(out, "w") as f:
    for i in range(n):
        x = [float(v) * 1e-3 for v in lines[1 + i].split()[1:4]]
        if max(abs(a - b) for a, b in zip(x, points.GetPoint(i))) > 1e-9:
            sys.exit("OpenFOAM's point %d is not the mesh's node %d" % (i, i + 1))
        f.write("%.10g %.10g %.10g\n" % tuple(u / u_in for u in velocity.GetTuple3(i)))
PY
  converged=$(grep -o 'SIMPLE solution converged in [0-9]* iterations' \
    "$dir/openfoam/simpleFoam.log" || echo "residualControl not met")
  echo
  echo "Inlet profile $inlet, the flow by OpenFOAM ($converged):"
  "$bench" "${flags[@]}" --field "$dir/velocity.txt" "$particles" "$across"
done
