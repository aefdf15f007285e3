#!/usr/bin/env bash
# naris trace of 10⁴ flux-weighted release points as tracers and as 10 µm particles through a solved case on
# one rank and on two: every particle ends with one fate, none is lost, and both runs write the
# same particles and crossings (the crossings to 15 significant digits).
# Usage: trace_ranks.sh NARIS MPIEXEC SOLUTION OUT [PLANES]
set -euo pipefail
naris=$1 mpiexec=$2 solution=$3 out=$4 planes=${5:-33.5,44,54.5,65,75.5,85}
if [ ! -f "$solution" ]; then
  echo "skipping: $solution is absent"
  exit 77
fi
rm -rf "$out"
args=(trace "$solution" --release random --count 10000 --diameter 0,10 --planes "$planes"
  --no-figures)
"$naris" "${args[@]}" -o "$out/one"
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
  "$mpiexec" -n 2 --oversubscribe "$naris" "${args[@]}" -o "$out/two"
for f in particles.csv crossings.csv fates.csv; do
  cmp "$out/one/$f" "$out/two/$f" || { echo "FAIL: $f differs between 1 and 2 ranks"; exit 1; }
done
# fates.csv: released = the sum of the six fates, in every row; lost = 0.
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  { s = $c["outlet"] + $c["inlet"] + $c["wall"] + $c["max-time"] + $c["stagnated"] + $c["lost"]
    if (s != $c["released"] || $c["lost"] != 0) { print "FAIL: " $0; bad = 1 }
    n += $c["released"] }
  END { if (bad || n != 20000) { print "FAIL: " n " particles"; exit 1 } }' "$out/one/fates.csv"
echo "PASS: 20000 particles, every fate accounted for, none lost; 1 and 2 ranks identical"
cat "$out/one/fates.csv"
