// What a kernel divides by: the quantities whose zeros make a system's equations singular.
//
// An integration that fails at a collision (the distance between two bodies
// goes to 0) or at a singularity of the coordinates (Euler angles at
// theta = 0, where the mass matrix is singular) says no more, by itself,
// than "step size too small" or "singular matrix". A kernel knows better:
// what it divides by is in its outputs. singular_factors collects, from
// kernel outputs:
//   - the divisors: bases of negative powers and denominators of quotients,
//     arguments of logarithms;
//   - for each linear solve of at most kMaxProbedSolve unknowns, its matrix's
//     determinant, simplified (for the rigid body's Euler angles, a
//     constant times sin(theta)^2);
// split into their distinct factors that are not numbers (the factors of
// products and the bases of powers), at most kMaxSingularFactors of them,
// with each one's text in prefix form. The runtime evaluates them where an
// integration fails and names the one that has gone to zero
// (sicm_ode_set_singularity_probe, sicm/ode.h).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "cas/expr.hpp"

namespace sicm {

// A larger system's determinant is not worth its symbolic expansion here:
// its solve reports "singular matrix" by itself.
constexpr size_t kMaxProbedSolve = 3;

// Enough for every pair distance of a handful of bodies; an N-body kernel
// names the first pairs it divides by.
constexpr size_t kMaxSingularFactors = 32;

struct SingularFactors {
  std::vector<ExprId> values;     // over the kernel's inputs
  std::vector<std::string> texts; // values[k] in prefix form
};

// The factors of outputs' divisors. name_of(s) is the text an input symbol
// takes in the texts ("(ref state 1 0)"); the empty string keeps its name.
SingularFactors singular_factors(const std::vector<ExprId> &outputs,
                                 const std::function<std::string(Symbol *)> &name_of);

// The factors over other input symbols: each of `from` replaced by the
// symbol of `to` at the same place (for a residual function of its own).
std::vector<ExprId> with_inputs(const std::vector<ExprId> &factors,
                                const std::vector<Symbol *> &from, const std::vector<Symbol *> &to);

// The expressions with each node that is a key of `leaves` replaced by its
// value: a kernel's outputs with its parameters' values in place of them,
// so that what it divides by factors and reads as it did with the numbers
// folded in.
std::vector<ExprId> with_leaves(const std::vector<ExprId> &values,
                                const std::unordered_map<ExprId, ExprId> &leaves);

} // namespace sicm
