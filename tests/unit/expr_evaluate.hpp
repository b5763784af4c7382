// A numeric evaluator of expression DAGs for tests: the value of an expression at given values of
// its symbols.
#pragma once

#include <functional>
#include <string>

#include "cas/expr.hpp"

namespace sicm {

// The value of id with each symbol s replaced by value_of(s's name), in
// double arithmetic, operations as C's math library computes them; NaN for an
// unknown function (a Call) or an operator it does not know. When largest is
// given it grows to the largest magnitude of any subexpression met (large
// intermediates make values that differently arranged computations cannot
// reproduce).
double expr_evaluate(ExprId id, const std::function<double(const std::string &)> &value_of,
                     double *largest = nullptr);

} // namespace sicm
