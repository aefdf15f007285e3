#!/usr/bin/env bash
# The real neonatal airway: meshed, solved at a Reynolds number that converges quickly (20) to
# the continuation's step tolerance (what the tracking needs, in fewer Newton steps), then
# trace_ranks.sh on its flow (2 × 10⁴ particles, 1 and 2 ranks identical, none lost).
# Usage: neonate_trace.sh NARIS MPIEXEC NEONATE_NRRD OUT
set -euo pipefail
naris=$1 mpiexec=$2 neonate=$3 out=$4
if [ ! -f "$neonate" ]; then
  echo "skipping: $neonate is absent"
  exit 77
fi
rm -rf "$out"
"$naris" --quiet mesh "$neonate" --inlet j=19 --outlet j=285 --no-msh -o "$out/mesh/mesh.h5"
"$naris" --quiet solve "$out/mesh/mesh.h5" --re 20 --tolerance 1e-5 --progress 0 -o "$out/solution"
"$(dirname "$0")/trace_ranks.sh" "$naris" "$mpiexec" "$out/solution/solution.h5" "$out/trace" 5,10,20,40
