// Crossing events: on-crossing and stop-on-crossing make them, evolve and
// state-advancer take them (see crossing_events.hpp).
#include "builtins/crossing_events.hpp"

#include <string>

#include "base/error.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "builtins/integration_errors.hpp"
#include "builtins/numeric_arguments.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"
#include "sicm/ode.h"

namespace sicm {

namespace {

// A procedure's name as the program wrote it, for the event's printed form.
std::string name_of(Value proc) {
  if (proc.is(Tag::Closure) && proc.as<Closure>()->lambda->name)
    return proc.as<Closure>()->lambda->name->name;
  if (proc.is(Tag::Primitive)) return proc.as<Primitive>()->name;
  return proc.is(Tag::Closure) ? "anonymous" : write_string(proc);
}

// #[on-crossing position up record] and #[stop-on-crossing position up]:
// the call that made it.
void write_event(std::string &out, const void *obj, bool) {
  const auto *e = static_cast<const CrossingEvent *>(obj);
  out += e->stops() ? "#[stop-on-crossing " : "#[on-crossing ";
  out += name_of(e->event) + " " + symbol_name(e->direction);
  if (!e->stops()) out += " " + name_of(e->action);
  out += "]";
}

const OpaqueKind kCrossingEventKind = {"crossing-event", write_event, nullptr};

// The event procedure and the action are called with the state: one that
// cannot take one argument is an error at its definition, now rather than
// at the first crossing.
Value make_event(const char *who, Value *a, int n, Value action) {
  check_numeric_arguments(who, a, n);
  SrcLoc loc = current_call_loc();
  check_monitor_arity(loc, who, a[0], "the event procedure");
  if (!action.is_false()) check_monitor_arity(loc, who, action, "the procedure");
  auto *e = gc_new<CrossingEvent>(CrossingEvent{a[0], a[1], action});
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kCrossingEventKind, e}));
}

// (on-crossing event direction procedure)
Value P_on_crossing(Value *a, int n) {
  return make_event("on-crossing", a, n, a[2]);
}

// (stop-on-crossing event direction)
Value P_stop_on_crossing(Value *a, int n) {
  return make_event("stop-on-crossing", a, n, Value::boolean(false));
}

} // namespace

const CrossingEvent *as_crossing_event(Value v) {
  if (!v.is(Tag::Opaque) || v.as<Opaque>()->kind != &kCrossingEventKind) return nullptr;
  return static_cast<const CrossingEvent *>(v.as<Opaque>()->obj);
}

int arguments_before_events(Value *a, int n, int required, const char *who) {
  int first = 0;
  while (first < n && !as_crossing_event(a[first]))
    ++first;
  if (first < n && first < required) wrong_type(a[first], first + 1, who);
  for (int i = first; i < n; ++i)
    if (!as_crossing_event(a[i])) wrong_type(a[i], i + 1, who);
  return first;
}

int crossing_direction(const CrossingEvent &e) {
  const std::string &name = symbol_name(e.direction);
  return name == "up"     ? SICM_ODE_EVENT_UP
         : name == "down" ? SICM_ODE_EVENT_DOWN
                          : SICM_ODE_EVENT_BOTH;
}

void install_crossing_event_primitives() {
  define_primitive("on-crossing", 3, 3, Stage::Pure, P_on_crossing);
  define_primitive("stop-on-crossing", 2, 2, Stage::Pure, P_stop_on_crossing);
}

} // namespace sicm
