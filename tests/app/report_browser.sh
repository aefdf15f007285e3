#!/usr/bin/env bash
# The case report in a real headless browser (Debian's chromium): the page renders, every figure
# decodes, and a screenshot of it is not blank.
# Usage: report_browser.sh REPORT_HTML WORK_DIR   (exit 77: skipped, no chromium)
set -euo pipefail
report=$1 work=$2
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
  echo "SKIP: no chromium (scripts/setup installs it)"
  exit 77
fi
[ -f "$report" ] || { echo "FAIL: $report is missing"; exit 1; }
rm -rf "$work" && mkdir -p "$work"
flags=(--headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$work/profile")
timeout 120 "$browser" "${flags[@]}" --virtual-time-budget=10000 --dump-dom "file://$(realpath "$report")" \
  > "$work/dom.html" 2> "$work/browser.log"
loaded=$(grep -o 'data-figures-loaded="[0-9]*/[0-9]*"' "$work/dom.html" | head -1 | grep -o '[0-9]*/[0-9]*' || true)
[ -n "$loaded" ] || { echo "FAIL: the page's script did not run (no data-figures-loaded)"; exit 1; }
shown=${loaded%/*} total=${loaded#*/}
[ "$total" -gt 0 ] && [ "$shown" = "$total" ] || { echo "FAIL: $loaded figures decoded"; exit 1; }
timeout 120 "$browser" "${flags[@]}" --window-size=1200,1600 --screenshot="$work/shot.png" \
  "file://$(realpath "$report")" >> "$work/browser.log" 2>&1
/usr/bin/python3 - "$work/shot.png" <<'PY'
import sys, vtk
r = vtk.vtkPNGReader()
r.SetFileName(sys.argv[1])
r.Update()
image = r.GetOutput()
scalars = image.GetPointData().GetScalars()
n, inked = image.GetNumberOfPoints(), 0
for i in range(0, n, 7):
    if min(scalars.GetTuple(i)[:3]) < 200:
        inked += 1
share = inked / len(range(0, n, 7))
print(f"screenshot: {image.GetDimensions()[0]}x{image.GetDimensions()[1]}, {100 * share:.1f} % inked")
sys.exit(0 if share > 0.02 else 1)
PY
echo "PASS: the report renders, $loaded figures decoded, the screenshot is not blank"
