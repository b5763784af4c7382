// The analyzed program as text: `sicm build --dump=analyzed` and `sicm
// emit-c --dump=analyzed` print each top-level form's Nodes (procedure.hpp)
// as an S-expression, local variables with their lexical addresses.
#pragma once

#include <string>

#include "eval/procedure.hpp"

namespace sicm {

// One Node tree, e.g. (define f (lambda f (1 0 #f 1) (call (global *) x@0.0 2))):
// a local is NAME@DEPTH.INDEX, a lambda shows (required optional rest?
// frame-size), a let its frame size.
std::string dump_node(const Node *n);

} // namespace sicm
