#!/usr/bin/python3
"""Prints whether a mesh.json's final mesh meets issue 30's quality targets: every tetrahedron's
minimum dihedral angle at least 12°, every cell's scaled Jacobian at least 0.1 and edge ratio at
most 10.

Usage: mesh_targets.py MESH_JSON
"""
import json
import sys

quality = json.load(open(sys.argv[1]))["quality_after"]
dihedral = quality["tet"]["min_dihedral_deg"]["min"]
jacobian = quality["all"]["scaled_jacobian"]["min"]
ratio = quality["all"]["edge_ratio"]["max"]
met = dihedral >= 12.0 and jacobian >= 0.1 and ratio <= 10.0
print("worst tet min dihedral %.2f deg, scaled Jacobian min %.3f, edge ratio max %.2f: "
      "quality targets %s" % (dihedral, jacobian, ratio, "met" if met else "missed"))
sys.exit(0 if met else 1)
