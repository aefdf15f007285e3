#pragma once
// Sizes as the result files state them: "MB" is the mebibyte, 2²⁰ bytes, everywhere.
#include <cstddef>

namespace naris {

inline double megabytes(std::size_t bytes) {
  return static_cast<double>(bytes) / 1048576.0;
}

}  // namespace naris
