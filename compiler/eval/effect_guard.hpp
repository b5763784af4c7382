// Effects a procedure must not make while it runs once to be traced into a
// kernel.
//
// A system derivative in sicm run, or compile-procedure's argument in
// either mode, is traced by running it once on symbols
// (codegen/trace.cpp: trace_procedure); the kernel it becomes
// then runs at every call. An effect made during that one run would happen
// once instead of at each call: a counter bumped by set! would count 1, a
// debugging display would print once, a random number would be drawn once
// and frozen. While an EffectGuard lives, such effects raise instead (before
// they happen), the trace fails, and the procedure stays interpreted, where
// each call makes them. What the procedure makes for itself (its own
// variables, pairs and vectors) it may change.
//
// sicm build's own traces into residual functions have their own rules for
// the same effects (cells, run-time statements, "cannot compile":
// pe/specialized.cpp, pe/branches.cpp) and take no guard.
#pragma once

#include <cstdint>

#include "base/srcloc.hpp"
#include "base/value.hpp"

namespace sicm {

// Refuses effects while it lives (on this thread); nests.
class EffectGuard {
public:
  EffectGuard();
  ~EffectGuard();
  EffectGuard(const EffectGuard &) = delete;
  EffectGuard &operator=(const EffectGuard &) = delete;

private:
  uint32_t outer_since_;
  int outer_depth_;
};

// Raise, at the current call, if a guard is on: `what` is the effect
// ("output", "random", "runtime").
void refuse_effect(const char *what);
// Raise if a guard is on and v (a pair, vector or string that `who` would
// change) was made before the guard began. Strings keep no serial: any.
void refuse_change_of(Value v, const char *who);
// Raise if a guard is on and a set! would change a variable made before the
// guard began: a global, or a slot of a frame of that serial.
void refuse_set_global(Symbol *s, SrcLoc loc);
void refuse_set_local(uint32_t frame_serial, SrcLoc loc);

} // namespace sicm
