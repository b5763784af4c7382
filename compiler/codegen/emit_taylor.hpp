// The Taylor emitter: a traced system derivative as a C function of the Taylor coefficients of
// its solution.
//
// Requires: a Trace (codegen/trace.hpp) of a system derivative, as many
// outputs as inputs, output f_i the derivative of input x_i (dx_i/dt = f_i,
// time being one of the inputs when the state has one). Produces: C text
// (with c_taylor_support() before it in the unit, after <math.h> with
// _GNU_SOURCE; the text includes <stdlib.h> itself when it allocates)
// that compiles warning-free with -std=c11 -Wall -Wextra:
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
// atan (one and two arguments), abs and the linear solves of kernels
// (algebra/linear_solve.hpp). tan, asin, acos and powers with a variable
// exponent have none here: the emitter then gives an empty string and says
// which.
#pragma once

#include <functional>
#include <string>

#include "codegen/trace.hpp"

namespace sicm {

// Double for taylor; long double for taylor-extended, whose function is
//   void c_name(const long double *in, int order, long double *c, const double *p)
// with every operation, constant ones too, computed in long double.
enum class TaylorPrecision { Double, Extended };

// How a symbol of the trace that is not an input is written in C (a
// run-time parameter of a built program: "p[2]"), or "" if it cannot be.
using SymbolSpeller = std::function<std::string(Symbol *)>;

// The C function described above, or "" with a one-line reason in *why_not
// when an operation of the trace has no recurrence here or it holds a
// symbol that is not an input and that spell does not spell.
// known_order: the order the integration will ask for, when known (a
// built program's tolerance is), else 0; the function then also holds a
// faster path for that order (same operations, same results).
std::string emit_taylor_function(const Trace &t, const std::string &c_name, std::string *why_not,
                                 TaylorPrecision precision = TaylorPrecision::Double,
                                 const SymbolSpeller &spell = nullptr, int known_order = 0);

// The static inline helpers the Taylor functions of one precision call
// (the recurrences of the elementary functions), once per translation unit
// and precision.
std::string c_taylor_support(TaylorPrecision precision = TaylorPrecision::Double);

} // namespace sicm
