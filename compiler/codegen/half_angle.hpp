// Kernels compute c - c cos x as 2c sin^2(x/2): the rewrite that keeps small angles accurate.
//
// c - c cos x loses all its digits as x goes to 0: at x = 1e-7, cos x rounds
// to 1 - 5e-15 within 1e-16, so the difference keeps one or two digits.
// Canonical forms make such differences out of stable procedures (the
// distance between two points of a circle, sqrt((l sin x)^2 + (l - l cos x)^2),
// becomes sqrt(2 l^2 - 2 l^2 cos x)), and users write them (the pendulum's
// potential energy m g l (1 - cos x)). The half-angle identity computes the
// same value to full relative accuracy at every x; likewise c + c cos x as
// 2c cos^2(x/2) near x = pi.
//
// Requires: kernel outputs (codegen/kernel_form.hpp), in any form. Produces:
// the same functions, in which every sum (or difference) holding a term
// c F and a term -c F cos x (F a product of factors, possibly none; c a
// number) holds instead the one term 2c F sin(x/2)^2, and one holding c F
// and c F cos x the term 2c F cos(x/2)^2. Nothing else changes.
#pragma once

#include <vector>

#include "cas/expr.hpp"

namespace sicm {

std::vector<ExprId> rewrite_half_angles(const std::vector<ExprId> &outputs);

} // namespace sicm
