#pragma once
// A surface given as the level zero of a function, positive inside: the wall that node
// relocation (relocate.h) slides boundary nodes on.
#include <Eigen/Dense>

namespace naris {

class LevelSet {
 public:
  virtual ~LevelSet() = default;
  // The function's value at x (mm) and its gradient (per mm); false where it is not defined.
  virtual bool evaluate(const Eigen::Vector3d& x, double& value,
                        Eigen::Vector3d& gradient) const = 0;
};

}  // namespace naris
