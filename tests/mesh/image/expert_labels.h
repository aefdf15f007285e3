#pragma once
// A segmentation scored against expert labels on the same grid (the NasalSeg test and the
// anatomy benchmark).
#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "mesh/image/volume.h"

namespace naris::testing {

// The voxels that carry any of the `wanted` labels, as a 0/1 mask.
inline std::vector<std::uint8_t> label_mask(const Volume<float>& labels,
                                            std::initializer_list<int> wanted) {
  std::vector<std::uint8_t> m(labels.values.size(), 0);
  for (std::size_t q = 0; q < m.size(); ++q)
    for (int l : wanted) m[q] |= labels.values[q] == static_cast<float>(l);
  return m;
}

struct Overlap {
  double dice = 0.0, volume_ratio = 0.0;  // 2|A∩B|/(|A|+|B|), |A|/|B|
};
inline Overlap overlap(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  std::size_t na = 0, nb = 0, both = 0;
  for (std::size_t q = 0; q < a.size(); ++q) na += a[q], nb += b[q], both += a[q] && b[q];
  return {2.0 * static_cast<double>(both) / static_cast<double>(na + nb),
          static_cast<double>(na) / static_cast<double>(nb)};
}

// The last slice along j that holds `label` (for the right cavity: the expert's choana).
inline int last_slice_j(const Volume<float>& labels, float label) {
  int last = -1;
  for (int k = 0; k < labels.frame.dims[2]; ++k)
    for (int j = 0; j < labels.frame.dims[1]; ++j)
      for (int i = 0; i < labels.frame.dims[0]; ++i)
        if (labels.at(i, j, k) == label) last = std::max(last, j);
  return last;
}

}  // namespace naris::testing
