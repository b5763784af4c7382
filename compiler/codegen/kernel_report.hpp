// What each kernel of a built program computes: `sicm build --report` and `sicm report`.
//
// A kernel is a function of the emitted program (fN) that a numerical
// statement calls: the state derivative of an evolve or a state-advancer,
// its monitor, its Jacobian, an integrand, an objective. For each: where it
// is called (file:line:col), its role, its inputs and outputs, the
// parameters ((parameter 'name ...)) its values depend on, and the
// operations of its C as emitted, counted from the C text itself (after
// folding, CSE and every rewrite), so that what an effect costs can be read
// off and compared: a drive of amplitude 0 must leave the state derivative
// with exactly the counts of the scene written without it.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "codegen/residual.hpp"

namespace sicm {

// The operation classes counted, in the JSON's order. add counts additions,
// subtractions and negations; sincos counts as a sin and a cos; solve counts
// solves of a factored linear system (one per right-hand side); call counts
// every other function called (fabs, fmax, isnan, ...).
extern const char *const kReportedOps[12];

struct KernelReport {
  std::string site; // file:line:col of the statement that calls it
  std::string role; // state-derivative, monitor, map, objective, integrand, jacobian, other
  size_t inputs = 0, outputs = 0;
  std::vector<std::string> parameters;
  std::map<std::string, size_t> ops; // every class of kReportedOps
  size_t total = 0;
};

// The operations of a C function body (the text between its braces). The
// body of a loop the emitter writes over instances or pairs
// (codegen/loops.hpp: `for (int v = A; v < B; ++v)`, `v = w + 1` over the
// pairs) counts as many times as it runs; other loops once. Arithmetic
// inside an index is addressing, not counted.
std::map<std::string, size_t> count_c_ops(std::string_view body);

// The kernels of a residual program, with the C emitted for it.
std::vector<KernelReport> report_kernels(const ResidualProgram &program, const std::string &c_unit);

// {"kernels": [...], "effects": [...]}, exactly the shape documented in
// docs/compiling.md.
std::string report_json(const std::vector<KernelReport> &kernels,
                        const std::vector<std::string> &effects);

// A readable table of the same, the effects on a last line.
std::string report_table(const std::vector<KernelReport> &kernels,
                         const std::vector<std::string> &effects);

} // namespace sicm
