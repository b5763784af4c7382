// Crossing events: the values (on-crossing event direction procedure) and
// (stop-on-crossing event direction) make, which the procedures evolve and
// state-advancer return take after their other arguments (docs/language.md
// says why they read so). sicm run's integrations (builtins/numerics.cpp)
// and sicm build's (pe/numerics.cpp) both read them here.
#pragma once

#include "base/value.hpp"

namespace sicm {

struct CrossingEvent {
  Value event;     // a real function of the state; a crossing is where it changes sign
  Value direction; // the symbol up, down or both
  Value action;    // the procedure called with the state at each crossing; #f: stop at the first
  bool stops() const { return action.is_false(); }
};

// v as a crossing event, or null when it is none.
const CrossingEvent *as_crossing_event(Value v);

// The number of arguments in a[0 .. n) before the first crossing event:
// those the primitive's signature checks. Every argument after it must be
// a crossing event too, and none may stand where one of the `required`
// arguments should (else the wrong-type error of `who`'s call names it: an
// event given in place of evolve's final time is the fourth argument of
// the wrong type, not a call with too few arguments).
int arguments_before_events(Value *a, int n, int required, const char *who);

// The runtime's direction of an event (SICM_ODE_EVENT_UP, _DOWN or _BOTH).
int crossing_direction(const CrossingEvent &e);

// on-crossing and stop-on-crossing.
void install_crossing_event_primitives();

} // namespace sicm
