#include "solver/ns/inlet_expression.h"

#include <muParser.h>

#include "core/error.h"

namespace naris::ns {

struct InletExpression::Parser {
  mu::Parser parser;
  double x = 0.0, y = 0.0, z = 0.0, r = 0.0;
};

InletExpression::InletExpression(const std::string& text)
    : text_(text), parser_(std::make_unique<Parser>()) {
  if (text.find_first_not_of(" \t") == std::string::npos) fail("the inlet expression is empty");
  try {
    auto& p = parser_->parser;
    p.DefineVar("x", &parser_->x);
    p.DefineVar("y", &parser_->y);
    p.DefineVar("z", &parser_->z);
    p.DefineVar("r", &parser_->r);
    p.SetExpr(text);
    // muparser checks the syntax lazily: evaluate once so that every error shows here.
    p.Eval();
  } catch (const mu::Parser::exception_type& e) {
    fail("inlet expression '{}': {} (at character {}; variables are x, y, z, r in mm)", text,
         e.GetMsg(), e.GetPos() + 1);
  }
}

InletExpression::~InletExpression() = default;
InletExpression::InletExpression(InletExpression&&) noexcept = default;
InletExpression& InletExpression::operator=(InletExpression&&) noexcept = default;

double InletExpression::operator()(const Eigen::Vector3d& x, double r) const {
  parser_->x = x[0];
  parser_->y = x[1];
  parser_->z = x[2];
  parser_->r = r;
  try {
    return parser_->parser.Eval();
  } catch (const mu::Parser::exception_type& e) {
    fail("inlet expression '{}': {}", text_, e.GetMsg());
  }
}

}  // namespace naris::ns
