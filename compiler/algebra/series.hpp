// Power series as lazy sequences of terms, and the exponential of an
// operator, whose application to a function is its Taylor (or Lie) series.
#pragma once

#include "base/value.hpp"

namespace sicm {

bool is_series(Value v);
// Term k of series s (computed on demand and remembered).
Value series_term(Value s, size_t k);
// The series sum_k (1/k!) x^k f: (exp x) for an operator x, applied to f.
Value make_exp_series(Value op, Value f);
// Register the series arithmetic type and define series:for-each,
// series:print, series:ref, series:sum, series, series->list?...
void install_series_primitives();

} // namespace sicm
