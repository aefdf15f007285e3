#!/usr/bin/python3
"""The end-to-end table of scripts/bench mesh: one row per `naris mesh` run, from its mesh.json
and the wall time and peak memory /usr/bin/time recorded (-f "%e %M").

Usage: mesh_rows.py "NAME|RESULTS_FOLDER[|TIME_FILE]" ...
"""
import json
import sys

print("| input | cells (hex / pyramid / tet) | worst tet min dihedral | worst min dihedral (all) "
      "| scaled Jacobian min | edge ratio max | read | mve | improve | quality | check | write | MVE Mcells/s "
      "| naris mesh wall (s) | peak MB |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for arg in sys.argv[1:]:
    name, folder, time_file = (arg.split("|") + [""])[:3]
    m = json.load(open(folder + "/mesh.json"))
    c, s, q = m["cells"], m["seconds"], m["quality_after"]["all"]
    tet_dihedral = m["quality_after"]["tet"]["min_dihedral_deg"]["min"]
    cells = c["hex"] + c["pyramid"] + c["tet"]
    wall, peak = "-", m["peak_memory_mb"]
    if time_file:
        seconds, kb = open(time_file).read().split()
        wall, peak = seconds, float(kb) / 1024
    print("| %s | %d (%d / %d / %d) | %.2f° | %.2f° | %.3f | %.3g | %.2f | %.2f | %.2f | %.2f | %.2f "
          "| %.2f | %.1f | %s | %.0f |" % (
              name, cells, c["hex"], c["pyramid"], c["tet"], tet_dihedral,
              q["min_dihedral_deg"]["min"], q["scaled_jacobian"]["min"], q["edge_ratio"]["max"],
              s["read"], s["mve"], s.get("improve", 0.0), s["quality"], s.get("check", 0.0),
              s["write"], cells / s["mve"] / 1e6, wall, peak))
