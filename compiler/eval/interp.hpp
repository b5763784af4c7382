// The interpreter's public face: what `sicm run`, the REPL and the tests use.
#pragma once

#include <string>
#include <vector>

#include "base/error.hpp"
#include "base/value.hpp"

namespace sicm {

// Analyze and evaluate one top-level form read from a source. Throws Error.
Value eval_toplevel(Value datum, SrcLoc loc);

// True if a top-level form's value should be printed: the form is not a
// definition and the value is not unspecified.
bool is_printable_toplevel(Value datum, Value result);

// Evaluate every form of a registered source in order, printing the
// printable values (as `sicm run` does) to stdout. Throws Error.
void run_source(uint32_t file);

// Analyze a whole program before running it, and check that every free
// identifier is defined by the program or by the global environment. Throws
// a Syntax Error naming the first unknown name (with a "did you mean" note).
// Returns the analyzed forms, in order, ready to evaluate.
gcvec<struct Node *> check_program(const gcvec<struct ReadForm> &forms);

// The names bound in the global environment (for REPL completion).
std::vector<std::string> global_names();

// e as the user should see it: an error raised inside the library is
// located at the user's form that led there (current_toplevel_loc: a line
// of the program, or the REPL's entry), the library's place in a note.
Error as_users_error(const Error &e);

} // namespace sicm
