#!/usr/bin/env bash
# A mesh-convergence study on one geometry: the mesh as naris mesh makes it and the same mesh
# subdivided once (every cell into 8 filling the same volume: the same wall, inlet and outlet),
# each solved by naris and by simpleFoam at the same Re. The subdivided naris solve starts from
# the coarse solution prolonged onto it (--restart-mesh). Prints Δp of each code on each mesh,
# how far each moved, and the gap between the codes on each mesh.
# Usage: grid_convergence.sh NARIS MESH_H5 RE WORK
#   MESH_H5: made by naris mesh (with mesh.msh beside it); WORK/fine/ receives it subdivided,
#   remade by naris mesh from NARIS_GRID_IMAGE with the options NARIS_GRID_CUTS (those that
#   made MESH_H5, e.g. "--inlet j=19 --outlet j=285").
# shellcheck disable=SC2154 # the foam_ variables come from simplefoam.sh's simplefoam.env
set -euo pipefail
naris=$1
mesh=$2
re=$3
work=$4
mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
field() { sed -n "s/.*\"$2\": \\([-0-9.e+]*\\).*/\\1/p" "$1" | head -1; }
fine=$work/fine/mesh.h5
if [ ! -f "$fine" ]; then
  echo "subdividing $mesh ..." >&2
  # shellcheck disable=SC2086 # the cuts are several words
  "$naris" --quiet mesh "$NARIS_GRID_IMAGE" $NARIS_GRID_CUTS --subdivide 1 -o "$fine"
fi

declare -A naris_dp naris_seconds naris_memory cells steps of_dp of_time of_iterations
for level in coarse fine; do
  m=$mesh
  restart=()
  if [ "$level" = fine ]; then
    m=$fine
    restart=(--restart "$work/naris-coarse/checkpoint.h5" --restart-mesh "$mesh")
  fi
  out=$work/naris-$level
  echo "naris solve, $level mesh, Re $re ..." >&2
  # GMRES(60) on the subdivided mesh: GMRES(200)'s Krylov vectors alone would take 9 GB there.
  /usr/bin/time -f "%e %M" -o "$work/time-$level" "$naris" solve "$m" --re "$re" \
    --pseudo-cfl 5 --max-iterations 150 --petsc "-ns_ksp_gmres_restart 60" "${restart[@]}" \
    -o "$out" > "$work/naris-$level.log" 2>&1 ||
    { tail -5 "$work/naris-$level.log" >&2; echo "naris solve failed on the $level mesh" >&2; exit 1; }
  naris_dp[$level]=$(field "$out/summary.json" pressure_drop_pa)
  naris_seconds[$level]=$(field "$out/summary.json" seconds)
  naris_memory[$level]=$(field "$out/summary.json" peak_memory_mb)
  cells[$level]=$(field "$out/summary.json" cells)
  steps[$level]=$(grep -o 'nonlinear_iterations": [0-9]*' "$out/summary.json" |
    awk '{s += $2} END {print s + 0}')
  u_in=$(field "$out/summary.json" inlet_speed_m_s)
  "$(dirname "$0")/simplefoam.sh" "$m" "$u_in" "$work/simplefoam-$level" "Re $re, $level mesh"
  # shellcheck source=/dev/null
  source "$work/simplefoam-$level/simplefoam.env"
  of_dp[$level]=$foam_dp
  of_time[$level]=$foam_settled_time
  of_iterations[$level]=$foam_settled
done

echo
echo "Re $re: $(basename "$(dirname "$mesh")") and it subdivided once (the same geometry)"
printf '%-10s %10s %14s %10s %8s %10s %16s %10s %8s\n' mesh cells "naris Δp (Pa)" "time (s)" \
  steps "MB" "simpleFoam Δp" "time (s)" its
for level in coarse fine; do
  printf '%-10s %10s %14s %10.1f %8s %10.0f %16s %10s %8s\n' "$level" "${cells[$level]}" \
    "${naris_dp[$level]}" "${naris_seconds[$level]}" "${steps[$level]}" "${naris_memory[$level]}" \
    "${of_dp[$level]}" "${of_time[$level]:-?}" "${of_iterations[$level]:-?}"
done
awk -v a="${naris_dp[coarse]}" -v b="${naris_dp[fine]}" -v c="${of_dp[coarse]}" -v d="${of_dp[fine]}" 'BEGIN {
  printf "naris moved %+.1f %%, simpleFoam %+.1f %% with the refinement\n", 100 * (b / a - 1),
    100 * (d / c - 1)
  printf "naris vs simpleFoam: %+.1f %% on the coarse mesh, %+.1f %% on the fine one\n",
    100 * (a / c - 1), 100 * (b / d - 1) }'
