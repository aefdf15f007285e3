// The default case's planes against the phantom's own sections:
//
//   phantom_sections PLANES_CSV AREA PERIMETER FLUX [SUBJECT]
//
// prints, per plane of planes.csv (coronal, by distance behind the naris), the area and
// perimeter naris measured beside the phantom's analytic ones (marching squares on its section
// field) and the flux through the plane against the inlet's (of u + u', and of the nodal u
// alone), and fails when an area misses by more than AREA, a smoothed perimeter by more than
// PERIMETER or the flux of u + u' by more than FLUX (fractions).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "mesh/image/phantom.h"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: phantom_sections PLANES_CSV AREA PERIMETER FLUX [SUBJECT]\n");
    return 2;
  }
  const double area_tolerance = std::atof(argv[2]), perimeter_tolerance = std::atof(argv[3]),
               flux_tolerance = std::atof(argv[4]);
  const naris::NasalPhantom phantom(argc > 5 ? std::atoi(argv[5]) : 1);
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "%s: cannot read\n", argv[1]);
    return 2;
  }
  auto split = [](const std::string& line) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    return f;
  };
  std::string line;
  std::getline(in, line);
  std::map<std::string, std::size_t> column;
  const auto header = split(line);
  for (std::size_t i = 0; i < header.size(); ++i) column[header[i]] = i;
  std::printf(
      "| plane (mm) | area (mm²) | phantom | difference | perimeter smoothed (mm) | raw | phantom "
      "| difference | flux / inlet | nodal u alone |\n|---|---|---|---|---|---|---|---|---|---|\n");
  int failures = 0, rows = 0;
  while (std::getline(in, line)) {
    const auto f = split(line);
    if (f.size() < header.size() || f[column["piece"]] != "all" || f[column["distance_mm"]].empty())
      continue;
    const double s = std::stod(f[column["distance_mm"]]);
    const double area = std::stod(f[column["area_mm2"]]),
                 perimeter = std::stod(f[column["perimeter_mm"]]),
                 raw = std::stod(f[column["raw_perimeter_mm"]]),
                 flux = std::stod(f[column["flux_to_inlet"]]),
                 nodal = std::stod(f[column["resolved_flux_to_inlet"]]);
    const auto exact = phantom.section_area_perimeter(s);
    const double da = area / exact[0] - 1.0, dp = perimeter / exact[1] - 1.0;
    std::printf("| %g | %.1f | %.1f | %+.1f %% | %.1f | %.1f | %.1f | %+.1f %% | %.4f | %.4f |\n",
                s, area, exact[0], 100 * da, perimeter, raw, exact[1], 100 * dp, flux, nodal);
    failures += std::abs(da) > area_tolerance || std::abs(dp) > perimeter_tolerance ||
                std::abs(flux - 1.0) > flux_tolerance;
    ++rows;
  }
  if (rows == 0) {
    std::fprintf(stderr, "%s: no planes by distance\n", argv[1]);
    return 2;
  }
  std::printf(failures ? "FAIL: %d plane(s) off\n" : "PASS: %d planes\n",
              failures ? failures : rows);
  return failures ? 1 : 0;
}
