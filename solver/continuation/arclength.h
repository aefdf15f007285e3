#pragma once
// The geometry of following a branch of steady solutions: secant, predictor and chord
// (the constraint itself: nonlinear/options.h, ArclengthConstraint).
#include <functional>

#include "solver/nonlinear/options.h"

namespace naris::continuation {

// ⟨a, b⟩ of the arclength constraint over the whole mesh (collective where the mesh is shared).
using InnerProduct = std::function<double(const ns::FlowField&, const ns::FlowField&)>;

// Points the constraint's tangent along the secant from (from, Re₀) to (to, Re₁): (to − from,
// Re₁ − Re₀) divided by its length in the constraint's metric, √(⟨δu, δu⟩ + (δRe/Re₁)²), which
// it returns (the step that would reach `to` again from `from`).
double aim_along_secant(nonlinear::ArclengthConstraint& c, const ns::FlowField& from,
                        double re_from, const ns::FlowField& to, double re_to,
                        const InnerProduct& inner);

// The predictor of a step: origin + step · tangent (its Re: origin_reynolds + step · t_Re).
ns::FlowField arclength_predictor(const nonlinear::ArclengthConstraint& c);

// a + t (b − a), node by node: the secant predictor (t beyond 1) and the chord (t in [0, 1]).
ns::FlowField blend(const ns::FlowField& a, const ns::FlowField& b, double t);

}  // namespace naris::continuation
