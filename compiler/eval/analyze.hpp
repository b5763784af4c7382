// Entry points of the analyzer (special forms -> Nodes); see analyze.cpp.
#pragma once

#include <vector>

#include "eval/procedure.hpp"

namespace sicm {

// Called for every reference to a global variable met during analysis (the
// whole-program check uses it to find unknown identifiers before running).
using GlobalRefHook = void (*)(Symbol *name, SrcLoc loc);

// Mark the special-form keywords. Call once at start-up.
void install_special_forms();
// Analyze a top-level form; `hook` may be null.
Node *analyze_form(Value datum, SrcLoc loc, GlobalRefHook hook);
// True if datum is a (define ...) form.
bool is_definition(Value datum);
// Append the global names a top-level form defines (looking inside begin).
void toplevel_defined_names(Value datum, std::vector<Symbol *> &out);

} // namespace sicm
