// Effects a procedure must not make while it runs once to be traced into a
// kernel.
//
// sicm run traces a system derivative or compile-procedure's argument by
// running it once on symbols (codegen/trace.cpp); the kernel it becomes
// then runs at every call. An effect made during that one run would happen
// once instead of at each call: a counter bumped by set! would count 1, a
// debugging display would print once, a random number would be drawn once
// and frozen. While an EffectGuard lives, such effects raise instead (before
// they happen), the trace fails, and the procedure stays interpreted, where
// each call makes them. What the procedure makes for itself (its own
// variables, pairs and vectors) it may change.
//
// sicm build has its own rules for most of these effects (cells, run-time
// statements, "cannot compile": pe/specialized.cpp, pe/branches.cpp), so
// while the partial evaluator is on the tracer refuses only random numbers
// (Refused::Draws), which the build draws while compiling.
#pragma once

#include <cstdint>

#include "base/srcloc.hpp"
#include "base/value.hpp"

namespace sicm {

enum class Refused {
  All,   // sicm run: every effect below
  Draws, // sicm build: random numbers only
};

// Refuses effects while it lives (on this thread); nests.
class EffectGuard {
public:
  explicit EffectGuard(Refused refused);
  ~EffectGuard();
  EffectGuard(const EffectGuard &) = delete;
  EffectGuard &operator=(const EffectGuard &) = delete;

private:
  uint32_t outer_since_;
  int outer_depth_;
  int outer_draws_depth_;
};

// Raise if a guard is on: `what` is the effect ("output", "runtime").
void refuse_effect(const char *what); // at the current call
// Raise if any guard is on (Draws included): who draws a random number.
void refuse_draw(const char *who);
// Raise if a guard is on and v (a pair, vector or string that `who` would
// change) was made before the guard began. Strings keep no serial: any.
void refuse_change_of(Value v, const char *who);
// Raise if a guard is on and a set! would change a variable made before the
// guard began: a global, or a slot of a frame of that serial.
void refuse_set_global(Symbol *s, SrcLoc loc);
void refuse_set_local(uint32_t frame_serial, SrcLoc loc);

} // namespace sicm
