// The C emitter for whole programs: a ResidualProgram (codegen/residual.hpp)
// as one C11 translation unit that includes "sicm/runtime.h" and defines
// main(). Compiles warning-free with -Wall -Wextra.
#pragma once

#include <string>
#include <string_view>

#include "codegen/residual.hpp"

namespace sicm {

// Throws a compile Error ("cannot compile: ...") when a run-time value
// escapes the procedure it was computed in, or a numerical result depends
// on a symbol or an unknown function.
std::string emit_residual_program(const ResidualProgram &program);

// Function `function` of the program (which calls no other and captures
// nothing) as a C11 unit for sicm run to load: it needs no runtime, and
// defines int ENTRY(const double *in, double *out, const volatile int
// *interrupt), which computes the function and returns 0, or returns 1 where
// one of the program's checked operations (a division by zero, a square
// root of a negative number) would fail or *interrupt becomes nonzero in a
// loop, leaving the value to the interpreter. See pe/for_run.cpp.
std::string emit_residual_function(const ResidualProgram &program, int function,
                                   const std::string &entry);

// s as a C string literal (with the quotes) in which every byte that is not
// printable ASCII, and " \ ?, is escaped.
std::string c_string_literal(std::string_view s);

} // namespace sicm
