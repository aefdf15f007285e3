#!/usr/bin/env bash
# OpenFOAM's simpleFoam on a mesh made by naris mesh (its .msh export through gmshToFoam),
# laminar, with naris's boundary conditions: uniform velocity U_IN normal to the inlet,
# zero-gradient (traction-free) outlet at p = 0, no-slip walls. Stops it once its Δp has
# settled and writes what it measured to WORK/simplefoam.env as shell assignments: foam_dp (Pa,
# area averages), foam_settled (the iteration from which Δp stayed within 0.1 %),
# foam_settled_time (its execution time there, s), foam_settle_window, foam_iterations,
# foam_total_time (s), foam_memory (peak, MB), foam_converged and foam_residuals (its own
# convergence report).
# Usage: simplefoam.sh MESH_H5 U_IN WORK [LABEL]
# NARIS_FOAM_INLET_U: the inlet's entry of 0/U instead (e.g. a developed profile);
# NARIS_FOAM_CONVERGE=1: run to SIMPLE's residualControl and write the fields there instead of
# stopping once Δp has settled.
set -euo pipefail
mesh=$1
u_in=$2
work=$3
label=${4:-$(basename "$(dirname "$mesh")")}
mkdir -p "$work"
rho=1.2

# OpenFOAM: the same mesh in metres, the same scales.
case=$work/openfoam
# SIMPLE's residuals stall near 2e-5 on these meshes while Δp no longer changes, so
# residualControl may never stop it (at 2 s an iteration, 5000 iterations are about three
# hours). Its time to solution is when its Δp came within 0.1 % of the value it then kept for
# settle_window iterations, after which it is stopped.
settle_window=${NARIS_BENCH_SETTLE_WINDOW:-100}
# The iteration from which simpleFoam's Δp has stayed within 0.1 % of its latest value, if it
# has for at least $1 iterations since (empty otherwise).
settled_from() {
  paste "$case"/postProcessing/inletPressure/0/surfaceFieldValue.dat \
    "$case"/postProcessing/outletPressure/0/surfaceFieldValue.dat 2>/dev/null |
    awk -v window="$1" '!/^#/ && NF >= 4 {it[++n] = $1; dp[n] = $2 - $4} END {
      if (n == 0) exit
      for (i = n; i >= 1 && (dp[i] - dp[n]) ^ 2 <= (1e-3 * dp[n]) ^ 2; --i) first = i
      if (n - first >= window) print it[first] }'
}
rm -rf "$case"
mkdir -p "$case/system" "$case/constant" "$case/0"
cat > "$case/system/controlDict" <<DICT
FoamFile { version 2.0; format ascii; class dictionary; object controlDict; }
application simpleFoam; startFrom startTime; startTime 0; stopAt endTime; endTime 5000;
deltaT 1; writeControl timeStep; writeInterval 5000; writeFormat binary; writePrecision 8;
writeCompression off; timeFormat general; timePrecision 6; runTimeModifiable false;
functions
{
  inletPressure { type surfaceFieldValue; libs ("libfieldFunctionObjects.so"); regionType patch;
    name inlet; operation areaAverage; fields (p); writeFields false; log false; }
  outletPressure { type surfaceFieldValue; libs ("libfieldFunctionObjects.so"); regionType patch;
    name outlet; operation areaAverage; fields (p); writeFields false; log false; }
}
DICT
cat > "$case/system/fvSchemes" <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object fvSchemes; }
ddtSchemes { default steadyState; }
gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) bounded Gauss linearUpwind grad(U);
  div((nuEff*dev2(T(grad(U))))) Gauss linear; }
laplacianSchemes { default Gauss linear limited corrected 0.5; }
interpolationSchemes { default linear; }
snGradSchemes { default limited corrected 0.5; }
DICT
cat > "$case/system/fvSolution" <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object fvSolution; }
solvers
{
  p { solver GAMG; smoother GaussSeidel; tolerance 1e-8; relTol 0.05; }
  U { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-9; relTol 0.1; }
}
SIMPLE { nNonOrthogonalCorrectors 1; consistent yes; residualControl { p 1e-5; U 1e-6; } }
relaxationFactors { equations { U 0.9; ".*" 0.9; } }
DICT
cat > "$case/constant/transportProperties" <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object transportProperties; }
transportModel Newtonian; nu 1.5e-05;
DICT
cat > "$case/constant/turbulenceProperties" <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object turbulenceProperties; }
simulationType laminar;
DICT
inlet_u=${NARIS_FOAM_INLET_U:-}
[ -n "$inlet_u" ] ||
  inlet_u="inlet { type surfaceNormalFixedValue; refValue uniform -$u_in; value uniform (0 0 0); }"
cat > "$case/0/U" <<DICT
FoamFile { version 2.0; format ascii; class volVectorField; object U; }
dimensions [0 1 -1 0 0 0 0]; internalField uniform (0 0 0);
boundaryField
{
  $inlet_u
  outlet { type zeroGradient; }
  wall { type noSlip; }
}
DICT
cat > "$case/0/p" <<'DICT'
FoamFile { version 2.0; format ascii; class volScalarField; object p; }
dimensions [0 2 -2 0 0 0 0]; internalField uniform 0;
boundaryField
{
  inlet { type zeroGradient; }
  outlet { type fixedValue; value uniform 0; }
  wall { type zeroGradient; }
}
DICT
(
  cd "$case"
  set +u
  # shellcheck source=/dev/null
  source /usr/share/openfoam/etc/bashrc > /dev/null 2>&1 || true
  set -u
  gmshToFoam "$(dirname "$mesh")/mesh.msh" > gmshToFoam.log 2>&1
  transformPoints -scale '(0.001 0.001 0.001)' > transformPoints.log 2>&1
  echo "simpleFoam, 1 core, $label ..." >&2
  # Run in the background and watched: stopped once its Δp has held for settle_window
  # iterations (its residuals stall long before residualControl; see below).
  /usr/bin/time -f "%e %M" -o "$work/time-openfoam" simpleFoam > simpleFoam.log 2>&1 &
  timer=$!
  while kill -0 "$timer" 2>/dev/null; do
    sleep 5
    if [ -z "${NARIS_FOAM_CONVERGE:-}" ] && [ -n "$(settled_from "$settle_window")" ]; then
      pkill -TERM -P "$timer" -x simpleFoam || true
    fi
  done
  wait "$timer" || true
)
total_time=$(tail -1 "$work/time-openfoam" | awk '{print $1}')
memory=$(tail -1 "$work/time-openfoam" | awk '{printf "%.0f", $2 / 1024}')
last() { awk '!/^#/ && NF {v = $2} END {print v}' "$1"; }
p_in=$(last "$case"/postProcessing/inletPressure/0/surfaceFieldValue.dat)
p_out=$(last "$case"/postProcessing/outletPressure/0/surfaceFieldValue.dat)
dp=$(awk -v a="$p_in" -v b="$p_out" -v r=$rho 'BEGIN {printf "%.4g", (a - b) * r}')
converged=$(grep -o 'SIMPLE solution converged in [0-9]* iterations' "$case/simpleFoam.log" ||
  echo "residualControl not met")
residuals=$(grep 'Solving for Ux' "$case/simpleFoam.log" | tail -1 |
  sed 's/.*Initial residual = \([^,]*\),.*/Ux initial residual \1/')

settled=$(settled_from 0)
settled_time=$(awk -v n="$settled" '/^Time = / {t = $3} /^ExecutionTime/ && t == n {print $3; exit}' \
  "$case/simpleFoam.log")
iterations=$(grep -c '^Time = ' "$case/simpleFoam.log")

{
  printf 'foam_settle_window=%q\nfoam_dp=%q\nfoam_settled=%q\nfoam_settled_time=%q\n' \
    "$settle_window" "$dp" "$settled" "$settled_time"
  printf 'foam_iterations=%q\nfoam_total_time=%q\nfoam_memory=%q\nfoam_converged=%q\n' \
    "$iterations" "$total_time" "$memory" "$converged"
  printf 'foam_residuals=%q\n' "$residuals"
} > "$work/simplefoam.env"
