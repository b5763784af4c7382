// The numerical primitives' signatures and their one checker (see
// numeric_arguments.hpp).
#include "builtins/numeric_arguments.hpp"

#include <cmath>
#include <string>

#include "algebra/generic.hpp"
#include "base/error.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/numerics_defaults.hpp"
#include "eval/procedure.hpp"

namespace sicm {

namespace {

using R = ArgRule;

bool is_missing(Value *a, int n, int i) {
  return i >= n || a[i].is(Tag::Default);
}

// A value sicm build knows only at run time.
bool known_at_run_time_only(Value v) {
  RunTimeValueTest test = run_time_value_test();
  return test && test(v);
}

// A real number, as every rule but Any, Procedure and Integrator wants;
// wrong_type otherwise.
double real_argument(Value *a, int i, const char *who) {
  if (!is_number(a[i]) || !is_real(a[i])) wrong_type(a[i], i + 1, who);
  return to_double(a[i]);
}

void check_point(Value *a, int i, const char *who) {
  gcvec<Value> items;
  if (a[i].is(Tag::Vector)) {
    Vector *v = a[i].vector();
    items.assign(v->items, v->items + v->len);
  } else if (list_length(a[i]) > 0) {
    items = list_to_vector(a[i]);
  }
  if (items.empty()) wrong_type(a[i], i + 1, who);
  for (Value x : items) {
    if (known_at_run_time_only(x)) continue;
    if (!is_number(x) || !is_real(x)) wrong_type(a[i], i + 1, who);
    if (!std::isfinite(to_double(x)))
      bad_range(a[i], i + 1, who, "a point's coordinates are finite");
  }
}

void check_integrator(Value *a, int i, const char *who) {
  if (is_symbol(a[i])) {
    const std::string &name = symbol_name(a[i]);
    if (integrator_c_name(name)) return;
    std::string why = integrator_not_provided(name);
    if (!why.empty()) runtime_error(current_call_loc(), std::string(who) + ": " + why);
  }
  bad_range(a[i], i + 1, who, std::string("the integrators are ") + integrator_list());
}

void check_argument(ArgRule rule, Value *a, int i, const char *who) {
  Value v = a[i];
  switch (rule) {
  case R::Any: return;
  case R::Procedure:
    if (!is_procedure(v) && !v.is(Tag::Structure)) wrong_type(v, i + 1, who);
    return;
  case R::Integrator: check_integrator(a, i, who); return;
  case R::Point: check_point(a, i, who); return;
  case R::Direction:
    if (!is_symbol(v) ||
        (symbol_name(v) != "up" && symbol_name(v) != "down" && symbol_name(v) != "both"))
      bad_range(v, i + 1, who, "a direction is 'up, 'down or 'both");
    return;
  default: break;
  }
  // A tolerance is compiled into the program; the other numbers the
  // runtime checks when it has them.
  if (known_at_run_time_only(v)) {
    if (rule == R::Tolerance) bad_range(v, i + 1, who); // "cannot compile: ..."
    return;
  }
  if (rule == R::Limit && is_symbol(v)) {
    const std::string &s = symbol_name(v);
    if (s == ":+infinity" || s == "+infinity" || s == ":-infinity" || s == "-infinity") return;
    wrong_type(v, i + 1, who);
  }
  if (rule == R::Index || rule == R::Count) {
    if (!v.is(Tag::Fixnum)) wrong_type(v, i + 1, who);
    if (v.i < (rule == R::Index ? 0 : 1) || (rule == R::Count && v.i > 100000000))
      bad_range(v, i + 1, who,
                rule == R::Index ? "a count of steps is an exact integer >= 0"
                                 : "a count is an exact integer from 1 to 100000000");
    return;
  }
  double x = real_argument(a, i, who);
  switch (rule) {
  case R::Finite:
    if (!std::isfinite(x)) bad_range(v, i + 1, who, "a finite real");
    return;
  case R::IntervalEnd:
    if (!std::isfinite(x)) bad_range(v, i + 1, who, "a finite real");
    if (!known_at_run_time_only(a[i - 1]) && is_number(a[i - 1]) && to_double(a[i - 1]) == x)
      bad_range(v, i + 1, who, "the ends of an interval differ");
    return;
  case R::Limit:
    if (std::isnan(x)) bad_range(v, i + 1, who, "a limit of integration is a real or :+infinity");
    return;
  case R::Tolerance:
    if (!(x > 0) || !std::isfinite(x)) bad_range(v, i + 1, who, "a tolerance is a positive real");
    return;
  case R::NonNegative:
    if (!(x >= 0) || !std::isfinite(x)) bad_range(v, i + 1, who, "a tolerance is a real >= 0");
    return;
  default: SICM_ASSERT(false);
  }
}

} // namespace

const std::vector<NumericSignature> &numeric_signatures() {
  static const std::vector<NumericSignature> table = {
      // (definite-integral f a b [tolerance [compile?]])
      {"definite-integral", 3, 5, {R::Procedure, R::Limit, R::Limit, R::Tolerance, R::Any}},
      // (minimize f a b [tolerance]), scmutils' brent-min the same
      {"minimize", 3, 4, {R::Procedure, R::Finite, R::IntervalEnd, R::Tolerance}},
      {"brent-min", 3, 4, {R::Procedure, R::Finite, R::IntervalEnd, R::Tolerance}},
      // (multidimensional-minimize f start [tolerance])
      {"multidimensional-minimize", 2, 3, {R::Procedure, R::Point, R::Tolerance}},
      // (nelder-mead f start [step [epsilon [max-iterations]]])
      {"nelder-mead", 2, 5, {R::Procedure, R::Point, R::Tolerance, R::Tolerance, R::Count}},
      // (find-root f a b [tolerance]): a tolerance of 0 is full precision
      {"find-root", 3, 4, {R::Procedure, R::Finite, R::IntervalEnd, R::NonNegative}},
      // (bisect f x0 x1 eps [n-break])
      {"bisect", 4, 5, {R::Procedure, R::Finite, R::Finite, R::NonNegative, R::Index}},
      // ((state-advancer sysder . params) state dt [tolerance [integrator [max-steps]]])
      {"state-advancer", 2, 5, {R::Any, R::Finite, R::Tolerance, R::Integrator, R::Count}},
      // ((evolve sysder . params) state monitor dt t-final [tolerance
      // [integrator [max-steps]]]); a step of 0 is the monitor schedule's to refuse
      // (sicm_monitor_schedule_start), after the first call of the monitor.
      {"evolve",
       4,
       7,
       {R::Any, R::Procedure, R::Finite, R::Finite, R::Tolerance, R::Integrator, R::Count}},
      // ((crossings sysder . params) state event direction t-final [tolerance [integrator
      // [count]]])
      {"crossings",
       4,
       7,
       {R::Any, R::Procedure, R::Direction, R::Finite, R::Tolerance, R::Integrator, R::Count}},
      // (on-crossing event direction procedure), (stop-on-crossing event direction):
      // the events evolve and state-advancer take after their other arguments
      {"on-crossing", 3, 3, {R::Procedure, R::Direction, R::Procedure}},
      {"stop-on-crossing", 2, 2, {R::Procedure, R::Direction}},
  };
  return table;
}

const NumericSignature &numeric_signature(std::string_view who) {
  for (const NumericSignature &s : numeric_signatures())
    if (who == s.who) return s;
  SICM_ASSERT(false); // every numerical primitive has a row above
  return numeric_signatures().front();
}

void check_numeric_arguments(const NumericSignature &sig, Value *a, int n, NativeProc *self) {
  if (self && (n < sig.min_args || n > sig.max_args))
    native_arity_error(self, n, sig.min_args, sig.max_args);
  for (int i = 0; i < n && i < static_cast<int>(sig.rules.size()); ++i)
    if (!is_missing(a, n, i)) check_argument(sig.rules[i], a, i, sig.who);
}

void check_numeric_arguments(const char *who, Value *a, int n, NativeProc *self) {
  check_numeric_arguments(numeric_signature(who), a, n, self);
}

} // namespace sicm
