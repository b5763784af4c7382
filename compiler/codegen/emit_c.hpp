// The C emitter: a traced kernel as one C11 function with the kernel ABI.
//
// Requires: a Trace (codegen/trace.hpp): outputs over the inputs x_i with only
// numbers, input symbols and ops.def applications. Produces: C text that
// compiles warning-free with -std=c11 -Wall -Wextra, and contains no user
// text except names sanitized to [A-Za-z0-9_].
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "codegen/loops.hpp"
#include "codegen/trace.hpp"

namespace sicm {

// The function `c_name` (not static unless asked), without includes:
//   void c_name(const double *in, double *out, const double *p) { ... }
// in and out must not overlap. Needs <math.h> with _GNU_SOURCE (for sincos).
std::string emit_kernel_function(const Trace &t, const std::string &c_name, bool is_static);

// A whole translation unit for the C compiler: a comment naming the source
// procedure (sanitized), the feature macro and includes, a prototype and the
// function.
std::string emit_kernel_unit(const Trace &t, const std::string &c_name,
                             std::string_view source_name);

// C statements (each line starting with `indent`) that compute values[j]
// into the C lvalue targets[j], with CSE across all the values. A symbol is
// written as spell(symbol) (an atom: a name or an array element);
// temporaries are declared as temp_prefix followed by a number, so two
// calls with different prefixes can share a C block. With a checked_site
// (the C text of a const sicm_site *), division, sqrt, log, asin, acos and
// pow are the runtime's sicm_checked_ forms, which fail at that site where
// the interpreter raises an error or leaves the reals (the residual
// program's own arithmetic); kernels pass none. site_of, when given, names
// the site of a checked operation's node instead (the call that made it:
// the `/` of `(/ 1 x)`, as sicm run reports it), or "" for checked_site.
// With index_of (unchecked code only), runs of repeated steps become loops over tables
// (codegen/loops.hpp); the symbols in them are written as index_of names them.
std::string emit_c_assignments(const std::vector<ExprId> &values,
                               const std::vector<std::string> &targets,
                               const std::function<std::string(Symbol *)> &spell,
                               const std::string &temp_prefix, const std::string &indent,
                               const std::string &checked_site = "",
                               const std::function<std::string(ExprId)> &site_of = nullptr,
                               const SymbolIndex *index_of = nullptr);

// Does any output depend on a solve node (algebra/linear_solve.hpp)?
bool uses_linear_solve(const std::vector<ExprId> &outputs);

// The C functions that the code of solve nodes calls (static inline, so a
// unit that includes them and calls none compiles without warnings), for
// the top of a translation unit after <math.h>.
std::string c_linear_solve_support();

// s with every byte outside [A-Za-z0-9_] replaced by '_', cut to max_len
// bytes; "anonymous" if s is empty.
std::string c_sanitize(std::string_view s, size_t max_len = 48);

// The C name of the kernel for the procedure named `name`: "sicm_kernel_"
// and the name itself if it is at most 40 bytes of [A-Za-z0-9_] (and does not
// end like the other form), else the name sanitized and cut to 40 bytes, "_h"
// and 16 hex digits of its SHA-256. Distinct names give distinct C names (up
// to a 64-bit hash collision), never longer than 70 bytes.
std::string c_kernel_name(std::string_view name);

// A finite or infinite double as a C expression that denotes exactly it:
// "0.5", "1.0", "-2.5e-10", "INFINITY", "NAN".
std::string c_double_literal(double d);

} // namespace sicm
