#pragma once
// Units shared by the stages: lengths in mm and in SI, and "MB" as the result files state it (the
// mebibyte, 2²⁰ bytes, everywhere).
#include <cstddef>

namespace naris {

// The mesh and the files are in millimetres, the solver and the particles in SI units.
inline constexpr double kMm = 1e-3;      // a millimetre in metres
inline constexpr double kMm2 = 1e-6;     // a square millimetre in m²
inline constexpr double kMlPerM3 = 1e6;  // millilitres in a cubic metre

inline double megabytes(std::size_t bytes) {
  return static_cast<double>(bytes) / 1048576.0;
}

}  // namespace naris
