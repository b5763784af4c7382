// The analyzed program: AST nodes with lexical addresses, lambdas, closures
// and environment frames.
//
// The analyzer (analyze.cpp) turns a datum into a tree of Nodes once; the
// evaluator (eval.cpp) walks Nodes. Local variables are addressed by
// (depth, index) into a chain of Frames; globals live in their Symbol.
#pragma once

#include "base/value.hpp"

namespace sicm {

enum class NodeKind : uint8_t {
  Const,        // a literal or quoted datum
  LocalRef,     // frame (depth, index)
  GlobalRef,    // symbol's global binding
  SetLocal,     // set! / internal define of a local
  SetGlobal,    // set! of a global (must be bound)
  DefineGlobal, // top-level define
  If,
  Lambda, // creates a closure
  Seq,    // begin / bodies
  Call,
  And,
  Or,
  Let,      // new frame; inits evaluated in the outer environment
  Letrec,   // new frame; inits evaluated inside it, in order
  Delay,    // make a promise of kids[0] (make_stream: cons-stream's tail)
  FluidLet, // temporarily set variables, evaluate body, restore
};

struct Lambda;

struct Node {
  NodeKind kind;
  uint16_t depth = 0; // LocalRef / SetLocal: frames to walk up
  uint32_t index = 0; // LocalRef / SetLocal: slot; Let/Letrec: frame size
  SrcLoc loc;
  Value value;           // Const: the datum; GlobalRef/SetGlobal/DefineGlobal: the symbol
  Node **kids = nullptr; // sub-nodes (meaning depends on kind)
  uint32_t nkids = 0;
  Lambda *lambda = nullptr; // Lambda nodes
};

struct Lambda {
  Symbol *name = nullptr; // for printing and error messages; null if anonymous
  uint32_t nrequired = 0;
  uint32_t noptional = 0;  // #!optional parameters, bound to #!default when missing
  bool rest = false;       // a rest parameter collects the remaining arguments
  uint32_t frame_size = 0; // parameters + internal definitions
  Node *body = nullptr;
  SrcLoc loc;
};

struct Frame {
  Frame *parent;
  uint32_t size;
  uint32_t serial; // order of creation (g_frame_serial when made; wraps, only compared in builds)
  Value slots[1];  // really `size` slots
};

struct Closure {
  Lambda *lambda;
  Frame *env;
};

Frame *make_frame(Frame *parent, uint32_t size);

// Apply any procedure to arguments (used by primitives such as map, apply, sort).
Value apply_procedure(Value proc, Value *args, int nargs);
// Sources registered from `file` on are the user's (the library's come
// first), so errors raised inside the library can say which of the user's
// forms was running.
void set_first_user_file(uint32_t file);
bool is_library_loc(SrcLoc loc);
// The user's line that is running: the current call when it is the user's,
// else the user's top-level form (a call inside the library).
SrcLoc user_call_loc();

// Tell the evaluator which primitive is `apply`, so calls to it are tail calls.
void register_apply_primitive(Value apply);

// Force a promise (other values are returned as they are).
Value force_promise(Value v);
inline bool is_applicable_opaque(Value v) {
  return v.is(Tag::Opaque) && v.as<Opaque>()->kind->apply != nullptr;
}
inline bool is_procedure(Value v) {
  return v.is(Tag::Closure) || v.is(Tag::Primitive) || is_applicable_opaque(v);
}

// Analyze a datum (with the position of the whole form) in the global scope.
Node *analyze_toplevel(Value datum, SrcLoc loc);
// Evaluate an analyzed node in an environment (null for top level).
Value eval(Node *node, Frame *env);

// Hooks for `sicm build` (pe/build_mode.cpp), null otherwise. When a
// test of if, and, or evaluates to a value that `dynamic_test` accepts (a
// truth value known only at run time), the evaluator does not choose a
// branch: `branch` gets the test and both alternatives (else_ may be null)
// and returns the value that selects between them at run time; `logic`
// does the same for the rest of an and/or from argument `from` on.
struct DynamicBranchHooks {
  bool (*dynamic_test)(Value test);
  Value (*branch)(Value test, Node *then, Node *else_, Frame *env);
  Value (*logic)(Value test, Node *n, uint32_t from, bool is_and, Frame *env);
  // set! of a global to v: returns the value to store.
  Value (*set_global)(Symbol *s, Value v, SrcLoc loc);
  // set! of a local variable (slot `index` of frame f) to v: the value to store.
  Value (*set_local)(Frame *f, uint32_t index, Value v, SrcLoc loc);
  // A call of closure f on evaluated arguments (a frame's slots, not to be
  // kept): true and the result in *out if the hook evaluated the call itself
  // (as a loop left for run time), false to let the evaluator go on.
  bool (*call_closure)(Value f, Value *args, long nargs, Value *out);
  // (apply f arg ... last) whose last argument is not a list known at compile
  // time (args: all of them): true and the result in *out if the hook
  // evaluated it, false for the usual error.
  bool (*apply_to_other)(Value f, Value *args, long nargs, Value *out);
  // Before a promise not yet forced is forced (null: nothing to do); may throw.
  void (*forcing)(Value promise) = nullptr;
};
extern const DynamicBranchHooks *g_dynamic_branch_hooks;

// The and/or node n evaluated from argument `from` on (not a tail call).
Value eval_logic_from(Node *n, uint32_t from, Frame *env);

// The stack guard: evaluation deeper than the limit raises MIT's
// "Aborting!: maximum recursion depth exceeded" instead of crashing.
void set_stack_limit(char *stack_base, size_t usable_bytes);
void check_stack(SrcLoc where = {});

} // namespace sicm
