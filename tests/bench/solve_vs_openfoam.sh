#!/usr/bin/env bash
# naris solve on 1 and 2 MPI ranks against OpenFOAM's simpleFoam on the very same mesh (the
# .msh export through gmshToFoam), laminar, same boundary conditions: uniform velocity normal
# to the inlet, zero-gradient (traction-free) outlet at p = 0, no-slip walls. Prints the time to
# solution of each (simpleFoam's: until its Δp settled, which ends its run), its peak memory,
# the ratios and the two inlet→outlet pressure drops (area averages).
# Usage: solve_vs_openfoam.sh NARIS MESH_H5 RE [WORK]
#   MESH_H5: made by naris mesh, with mesh.msh beside it.
# shellcheck disable=SC2154 # the foam_ variables come from simplefoam.sh's simplefoam.env
set -euo pipefail
naris=$1
mesh=$2
re=$3
work=${4:-$(mktemp -d)}
mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# Elapsed seconds and peak resident memory (KB) of a command, into file $1.
seconds() { /usr/bin/time -f "%e %M" -o "$1" "${@:2}"; }
# The last line: a failed command's file starts with its exit status.
elapsed() { tail -1 "$1" | awk '{print $1}'; }
field() { sed -n "s/.*\"$2\": \\([-0-9.e+]*\\).*/\\1/p" "$1" | head -1; }

declare -A time dp steps memory per_unknown balance
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
  per_unknown[$ranks]=$(field "$out/summary.json" peak_bytes_per_unknown)
  balance[$ranks]=$(field "$out/summary.json" momentum_balance)
  steps[$ranks]=$(grep -o 'nonlinear_iterations": [0-9]*' "$out/summary.json" 2>/dev/null |
    awk '{s += $2} END {print s + 0}')
done
u_in=$(field "$work/naris-1/summary.json" inlet_speed_m_s)

# OpenFOAM on the same mesh with the same scales.
"$(dirname "$0")/simplefoam.sh" "$mesh" "$u_in" "$work" "Re $re"
# shellcheck source=/dev/null
source "$work/simplefoam.env"
time[openfoam]=$foam_total_time
memory[openfoam]=$foam_memory
dp[openfoam]=$foam_dp

echo
echo "Re $re on $(basename "$(dirname "$mesh")")/$(basename "$mesh"), U_in $u_in m/s"
printf '%-22s %10s %12s %20s %14s\n' solver "time (s)" "Δp (Pa)" "peak memory (MB)" "steps"
printf '%-22s %10s %12s %20s %14s\n' "naris, 1 rank" "${time[1]}" "${dp[1]}" "${memory[1]}" \
  "${steps[1]} nonlinear"
printf '%-22s %10s %12s %20s %14s\n' "naris, 2 ranks" "${time[2]}" "${dp[2]}" "${memory[2]}" \
  "${steps[2]} nonlinear"
printf '%-22s %10s %12s %20s   %s\n' "simpleFoam, 1 core" "${foam_settled_time:-?}" "${dp[openfoam]}" \
  "${memory[openfoam]}" "$foam_settled SIMPLE (Δp within 0.1 % from there on)"
echo "  simpleFoam ran $foam_iterations iterations in ${time[openfoam]} s, stopped after its Δp had" \
  "held for $foam_settle_window; $foam_converged; last $foam_residuals"
echo "  naris: ${per_unknown[1]} and ${per_unknown[2]} bytes per unknown (1 and 2 ranks, all ranks);" \
  "momentum balance of the consistent forces ${balance[1]} of the wall force"
awk -v a="${foam_settled_time:-nan}" -v b="${time[1]}" -v c="${time[2]}" -v p="${dp[1]}" \
  -v q="${dp[openfoam]}" 'BEGIN {
    printf "simpleFoam / naris (1 rank): %.2f;  naris 1 rank / 2 ranks: %.2f;  Δp naris vs simpleFoam: %+.1f %%\n",
      a / b, b / c, 100 * (p / q - 1) }'
