#!/usr/bin/env bash
# Independent check of naris's Gmsh export: OpenFOAM's gmshToFoam must import the mesh with its
# patches and checkMesh must pass. Skips (exit 77) when OpenFOAM is not installed; scripts/bench
# solve installs it (Debian package openfoam).
set -uo pipefail
naris=$1
input=$2
if [ ! -f /usr/share/openfoam/etc/bashrc ] || ! command -v gmshToFoam >/dev/null; then
  echo "OpenFOAM not installed: skipping the gmshToFoam/checkMesh round trip"
  exit 77
fi
if [ ! -f "$input" ]; then
  echo "shared data absent ($input): skipping"
  exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$naris" --quiet mesh "$input" --inlet j=19 --outlet j=285 --no-improve -o "$work/mesh/mesh.h5" || exit 1
mkdir -p "$work/case/system" "$work/case/constant"
cd "$work/case"
cat > system/controlDict <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object controlDict; }
application simpleFoam; startFrom startTime; startTime 0; stopAt endTime; endTime 1; deltaT 1;
writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 8;
writeCompression off; timeFormat general; timePrecision 6; runTimeModifiable false;
DICT
cat > system/fvSchemes <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object fvSchemes; }
ddtSchemes { default steadyState; } gradSchemes { default Gauss linear; }
divSchemes { default none; } laplacianSchemes { default Gauss linear corrected; }
interpolationSchemes { default linear; } snGradSchemes { default corrected; }
DICT
cat > system/fvSolution <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object fvSolution; }
solvers {} SIMPLE {}
DICT
set +u
source /usr/share/openfoam/etc/bashrc >/dev/null 2>&1
set -u
gmshToFoam "$work/mesh/mesh.msh" > gmshToFoam.log 2>&1 || { tail -20 gmshToFoam.log; exit 1; }
checkMesh > checkMesh.log 2>&1 || { tail -40 checkMesh.log; exit 1; }
grep -q "^Mesh OK." checkMesh.log || { sed -n '/Checking topology/,$p' checkMesh.log; exit 1; }
for patch in wall inlet outlet; do
  grep -q "^    $patch " checkMesh.log || { echo "patch $patch missing after gmshToFoam"; exit 1; }
done
ours=$(grep -o '"tet": [0-9]*' "$work/mesh/mesh.json" | grep -o '[0-9]*$')
theirs=$(sed -n 's/^    tetrahedra: *//p' checkMesh.log)
[ "$ours" = "$theirs" ] || { echo "tetrahedra: naris $ours, OpenFOAM $theirs"; exit 1; }
grep -E "cells:|Mesh non-orthogonality|Max skewness|Total volume" checkMesh.log
echo "gmshToFoam + checkMesh: Mesh OK"
