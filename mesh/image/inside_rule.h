#pragma once
// Which voxels are inside the object: those below a threshold (air in CT), above it, or equal to
// a label. One rule for segmentation, the mesher and the command line.
#include <string>

#include "core/error.h"

namespace naris {

enum class InsideRule { below, above, label };

inline const char* inside_rule_name(InsideRule rule) {
  constexpr const char* names[] = {"below", "above", "label"};
  return names[static_cast<int>(rule)];
}

// "below" or "above" (a threshold's side, as the command line and case files give it).
inline InsideRule parse_threshold_side(const std::string& side) {
  if (side == "below") return InsideRule::below;
  if (side == "above") return InsideRule::above;
  fail("inside '{}' is neither 'below' nor 'above'", side);
}

// Whether `value` is inside by `rule` at `level`.
inline bool is_inside(InsideRule rule, double value, double level) {
  return rule == InsideRule::label   ? value == level
         : rule == InsideRule::above ? value > level
                                     : value < level;
}

}  // namespace naris
