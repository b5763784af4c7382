// The Taylor emitter: a traced system derivative as a C function of the Taylor coefficients of
// its solution.
//
// Requires: a Trace (codegen/trace.hpp) of a system derivative, as many
// outputs as inputs, output f_i the derivative of input x_i (dx_i/dt = f_i,
// time being one of the inputs when the state has one). Produces: C text
// (with c_taylor_support() before it in the unit, after <math.h> with
// _GNU_SOURCE) that compiles warning-free with -std=c11 -Wall -Wextra:
//
//   void c_name(const double *in, int order, double *c, const double *p)
//
// fills c[k * n + i] with the k-th normalized Taylor coefficient
// x_i^(k)(t) / k! of the solution through the state in[0..n-1], for
// k = 0..order (order is clamped to 0..SICM_ODE_TAYLOR_MAX_ORDER). This is
// the coefficient function of sicm_ode_step_taylor (sicm/ode.h).
//
// Limits: operations with recurrences are + - * /, expt with a constant
// exponent (integer or real), sqrt, exp, log, sin and cos, sinh and cosh,
// atan (one and two arguments) and abs. tan, asin, acos, powers with a
// variable exponent and linear solves (algebra/linear_solve.hpp) have
// none here: the emitter then gives an empty string and says which.
#pragma once

#include <string>

#include "codegen/trace.hpp"

namespace sicm {

// The C function described above, or "" with a one-line reason in *why_not
// when an operation of the trace has no recurrence here.
std::string emit_taylor_function(const Trace &t, const std::string &c_name, std::string *why_not);

// The static inline helpers the Taylor functions call (the recurrences of
// the elementary functions), once per translation unit.
std::string c_taylor_support();

} // namespace sicm
