#pragma once
// An inlet velocity profile typed by the user, e.g. "1 - (r/1.2)^2" or "exp(-r^2)": the speed
// along the inlet's inward normal as a function of the position x, y, z (mm, the mesh's frame)
// and r (mm, the distance from the inlet's area centroid). Parsed by muparser (operators
// + - * / ^, comparisons, `c ? a : b`, sqrt, exp, log, sin, cos, abs, min, max, …).
#include <Eigen/Core>
#include <memory>
#include <string>

namespace naris::ns {

class InletExpression {
 public:
  // Throws naris::Error naming the problem (syntax, an unknown variable) and its position.
  explicit InletExpression(const std::string& text);
  ~InletExpression();
  InletExpression(InletExpression&&) noexcept;
  InletExpression& operator=(InletExpression&&) noexcept;

  // The value at x (mm), r (mm); not thread-safe (the parser holds the variables).
  double operator()(const Eigen::Vector3d& x, double r) const;
  const std::string& text() const { return text_; }

 private:
  struct Parser;
  std::string text_;
  std::unique_ptr<Parser> parser_;
};

}  // namespace naris::ns
