#pragma once
// The grid lines of a volume along one axis, processed in parallel: the separable transforms
// (distances, Gaussian smoothing) work line by line, axis after axis.
#include <array>
#include <span>
#include <vector>

#include "core/parallel.h"
#include "mesh/image/volume.h"

namespace naris {

// For every line of the frame's grid along `axis`, copies the line of `values` out, calls the
// line function on the copy and writes it back. Each of `threads` threads (0: every core) calls
// make() once for its own line function, so scratch buffers live in it.
template <class MakeLineFunction>
void transform_lines(const ImageFrame& frame, std::vector<float>& values, int axis, int threads,
                     MakeLineFunction&& make) {
  const auto& n = frame.dims;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  const std::size_t stride = axis == 0   ? 1
                             : axis == 1 ? static_cast<std::size_t>(n[0])
                                         : static_cast<std::size_t>(n[0]) * n[1];
  const std::size_t lines = static_cast<std::size_t>(n[a1]) * static_cast<std::size_t>(n[a2]);
  run_threads(thread_count(threads), [&](unsigned t, unsigned count) {
    const auto [begin, end] = share(lines, t, count);
    auto line_function = make();
    std::vector<float> line(static_cast<std::size_t>(n[axis]));
    for (std::size_t l = begin; l < end; ++l) {
      std::array<int, 3> ijk{};
      ijk[a1] = static_cast<int>(l % static_cast<std::size_t>(n[a1]));
      ijk[a2] = static_cast<int>(l / static_cast<std::size_t>(n[a1]));
      const std::size_t first = frame.index(ijk[0], ijk[1], ijk[2]);
      for (std::size_t x = 0; x < line.size(); ++x) line[x] = values[first + stride * x];
      line_function(std::span<float>(line));
      for (std::size_t x = 0; x < line.size(); ++x) values[first + stride * x] = line[x];
    }
  });
}

}  // namespace naris
