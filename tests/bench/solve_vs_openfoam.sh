#!/usr/bin/env bash
# naris solve on 1 and 2 MPI ranks against OpenFOAM's simpleFoam on the very same mesh (the
# .msh export through gmshToFoam), laminar, same boundary conditions: uniform velocity normal
# to the inlet, zero-gradient (traction-free) outlet at p = 0, no-slip walls. Prints the time to
# solution of each (simpleFoam's: until its Δp settled, which ends its run), its peak memory,
# the ratios and the two inlet→outlet pressure drops (area averages).
# Usage: solve_vs_openfoam.sh NARIS MESH_H5 RE [WORK]
#   MESH_H5: made by naris mesh, with mesh.msh beside it.
set -euo pipefail
naris=$1
mesh=$2
re=$3
work=${4:-$(mktemp -d)}
mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
rho=1.2

# Elapsed seconds and peak resident memory (KB) of a command, into file $1.
seconds() { /usr/bin/time -f "%e %M" -o "$1" "${@:2}"; }
# The last line: a failed command's file starts with its exit status.
elapsed() { tail -1 "$1" | awk '{print $1}'; }
field() { sed -n "s/.*\"$2\": \\([-0-9.e+]*\\).*/\\1/p" "$1" | head -1; }

declare -A time dp steps memory
for ranks in 1 2; do
  out="$work/naris-$ranks"
  echo "naris solve, $ranks rank(s), Re $re ..." >&2
  launcher=()
  [ "$ranks" -gt 1 ] && launcher=(mpiexec -n "$ranks" --oversubscribe)
  seconds "$work/time-$ranks" "${launcher[@]}" "$naris" solve "$mesh" --re "$re" \
    --pseudo-cfl 5 --max-iterations 150 -o "$out" > "$work/naris-$ranks.log" 2>&1 ||
    { tail -5 "$work/naris-$ranks.log" >&2; echo "naris solve failed on $ranks rank(s)" >&2; }
  time[$ranks]=$(elapsed "$work/time-$ranks")
  dp[$ranks]=$(field "$out/summary.json" pressure_drop_pa 2>/dev/null || echo nan)
  # Per rank (the largest) and, on several ranks, summed over them: from naris's own summary,
  # since time(1) under mpiexec would measure the launcher.
  memory[$ranks]=$(awk -v m="$(field "$out/summary.json" peak_memory_mb)" \
    -v all="$(field "$out/summary.json" peak_memory_all_ranks_mb)" -v n="$ranks" \
    'BEGIN { if (m == "") print "?"; else if (n > 1) printf "%.0f/rank, %.0f", m, all;
             else printf "%.0f", m }')
  steps[$ranks]=$(grep -o 'nonlinear_iterations": [0-9]*' "$out/summary.json" 2>/dev/null |
    awk '{s += $2} END {print s + 0}')
done
u_in=$(field "$work/naris-1/summary.json" inlet_speed_m_s)

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
cat > "$case/0/U" <<DICT
FoamFile { version 2.0; format ascii; class volVectorField; object U; }
dimensions [0 1 -1 0 0 0 0]; internalField uniform (0 0 0);
boundaryField
{
  inlet { type surfaceNormalFixedValue; refValue uniform -$u_in; value uniform (0 0 0); }
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
  source /usr/share/openfoam/etc/bashrc > /dev/null 2>&1 || true
  set -u
  gmshToFoam "$(dirname "$mesh")/mesh.msh" > gmshToFoam.log 2>&1
  transformPoints -scale '(0.001 0.001 0.001)' > transformPoints.log 2>&1
  echo "simpleFoam, 1 core, Re $re ..." >&2
  # Run in the background and watched: stopped once its Δp has held for settle_window
  # iterations (its residuals stall long before residualControl; see below).
  /usr/bin/time -f "%e %M" -o "$work/time-openfoam" simpleFoam > simpleFoam.log 2>&1 &
  timer=$!
  while kill -0 "$timer" 2>/dev/null; do
    sleep 5
    if [ -n "$(settled_from "$settle_window")" ]; then pkill -TERM -P "$timer" -x simpleFoam || true; fi
  done
  wait "$timer" || true
)
time[openfoam]=$(elapsed "$work/time-openfoam")
memory[openfoam]=$(tail -1 "$work/time-openfoam" | awk '{printf "%.0f", $2 / 1024}')
last() { awk '!/^#/ && NF {v = $2} END {print v}' "$1"; }
p_in=$(last "$case"/postProcessing/inletPressure/0/surfaceFieldValue.dat)
p_out=$(last "$case"/postProcessing/outletPressure/0/surfaceFieldValue.dat)
dp[openfoam]=$(awk -v a="$p_in" -v b="$p_out" -v r=$rho 'BEGIN {printf "%.4g", (a - b) * r}')
converged=$(grep -o 'SIMPLE solution converged in [0-9]* iterations' "$case/simpleFoam.log" ||
  echo "residualControl not met")
residuals=$(grep 'Solving for Ux' "$case/simpleFoam.log" | tail -1 |
  sed 's/.*Initial residual = \([^,]*\),.*/Ux initial residual \1/')

settled=$(settled_from 0)
settled_time=$(awk -v n="$settled" '/^Time = / {t = $3} /^ExecutionTime/ && t == n {print $3; exit}' \
  "$case/simpleFoam.log")
iterations=$(grep -c '^Time = ' "$case/simpleFoam.log")

echo
echo "Re $re on $(basename "$(dirname "$mesh")")/$(basename "$mesh"), U_in $u_in m/s"
printf '%-22s %10s %12s %20s %14s\n' solver "time (s)" "Δp (Pa)" "peak memory (MB)" "steps"
printf '%-22s %10s %12s %20s %14s\n' "naris, 1 rank" "${time[1]}" "${dp[1]}" "${memory[1]}" \
  "${steps[1]} nonlinear"
printf '%-22s %10s %12s %20s %14s\n' "naris, 2 ranks" "${time[2]}" "${dp[2]}" "${memory[2]}" \
  "${steps[2]} nonlinear"
printf '%-22s %10s %12s %20s   %s\n' "simpleFoam, 1 core" "${settled_time:-?}" "${dp[openfoam]}" \
  "${memory[openfoam]}" "$settled SIMPLE (Δp within 0.1 % from there on)"
echo "  simpleFoam ran $iterations iterations in ${time[openfoam]} s, stopped after its Δp had" \
  "held for $settle_window; $converged; last $residuals"
awk -v a="${settled_time:-nan}" -v b="${time[1]}" -v c="${time[2]}" -v p="${dp[1]}" \
  -v q="${dp[openfoam]}" 'BEGIN {
    printf "simpleFoam / naris (1 rank): %.2f;  naris 1 rank / 2 ranks: %.2f;  Δp naris vs simpleFoam: %+.1f %%\n",
      a / b, b / c, 100 * (p / q - 1) }'
