// Does a procedure assign a variable it does not own? parallel-map's rule:
// its members may run at the same time, so the procedure it is given must
// not set! (or fluid-let) a variable bound outside itself.
#pragma once

#include "base/srcloc.hpp"
#include "base/value.hpp"

namespace sicm {

struct CapturedAssignment {
  bool found = false;
  SrcLoc loc;       // the set! or fluid-let
  std::string name; // the variable, when the analyzer kept its name
};

// The first assignment, in the text of f (a closure), of a variable bound
// outside f: a global, or a local of an enclosing procedure. Procedures f
// calls are not looked into (their assignments of globals are found by `sicm
// build` when it compiles the members; see pe/parallel.cpp).
CapturedAssignment find_captured_assignment(Value f);

// Raise parallel-map's located run-time error if f assigns a variable it
// does not own; `who` is parallel-map or parallel-for-each.
void require_no_captured_assignment(Value f, const char *who);

} // namespace sicm
