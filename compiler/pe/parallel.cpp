// `sicm build`'s parallel-map and parallel-for-each: each member (the
// procedure applied to one element) becomes a function of the residual
// program, and one ParallelMap statement calls them all; the runtime runs
// them on threads and MPI ranks and emits what they print in list order
// (sicm_parallel_map in sicm/program.h). Part of build mode (the design is
// in pe/build_mode.cpp; the shared declarations in pe/state.hpp).
//
// Two ways to make the members' functions, tried in order:
//   one function for all  when the elements are inexact numbers or run-time
//                         values, or up/down structures of them, all of one
//                         shape: the procedure is traced once on run-time
//                         inputs, and each member calls it on its element
//                         (a sweep over 1000 initial conditions compiles one
//                         kernel, not 1000);
//   one function each     otherwise: the procedure is applied to each element
//                         at compile time, as map does, with what each call
//                         leaves for run time recorded in a function of its
//                         own.
// What a member returns is kept as it is, except its run-time numbers, which
// become the function's outputs. When neither way compiles, or the procedure
// does no run-time work, parallel-map is the build's map.
#include <string>

#include "base/number.hpp"
#include "codegen/state_shape.hpp"
#include "eval/captured_assignment.hpp"
#include "pe/specialized.hpp"
#include "pe/state.hpp"

namespace sicm::build {

namespace {

bool holds_rtlist(Value v) {
  if (as_rtlist(v)) return true;
  if (is_pair(v)) return holds_rtlist(car(v)) || holds_rtlist(cdr(v));
  size_t len = 0;
  Value *items = container_items(v, &len);
  for (size_t i = 0; items && i < len; ++i)
    if (holds_rtlist(items[i])) return true;
  return false;
}

// The run-time numbers of a member's result become the open function's
// outputs; their kinds are appended to `types`.
void add_outputs(Value result, const char *who, std::vector<RType> &types) {
  gcvec<Value> leaves;
  if (holds_rtlist(result) || !result_leaves(result, leaves))
    cannot_compile(here(), std::string("the procedure given to ") + who + " returns " +
                               describe(result) + ", which a member cannot return");
  for (Value leaf : leaves)
    if (is_dynamic_scalar(leaf)) {
      current().outputs.push_back(expr_of(leaf, who));
      types.push_back(scalar_type(leaf));
    }
}

// `shape` with its run-time numbers replaced by the next leaves.
Value with_leaves(Value shape, const Value *&leaves) {
  if (is_dynamic_scalar(shape)) return *leaves++;
  if (is_scalar(shape) || !contains_dynamic(shape)) return shape;
  if (is_pair(shape)) {
    Value a = with_leaves(car(shape), leaves);
    return cons(a, with_leaves(cdr(shape), leaves));
  }
  return state_like(shape, leaves, with_leaves);
}

// Can the members share one function: are the elements inexact numbers or
// run-time numbers (or up/down structures of them) all shaped as the first?
// Their leaves, element after element, go to `inputs`.
bool shared_inputs(const gcvec<Value> &elements, const char *who, std::vector<ExprId> &inputs) {
  for (Value e : elements) {
    if (!is_state_shape(e) || !same_shape(e, elements[0])) return false;
    gcvec<Value> leaves;
    state_leaves(e, leaves);
    for (Value leaf : leaves) {
      if (!leaf.is(Tag::Flonum) && !is_dynamic_scalar(leaf)) return false;
      inputs.push_back(expr_of(leaf, who));
    }
  }
  return true;
}

// The ParallelMap statement for the traced members and the members' values.
Value record(std::vector<int> members, size_t count, std::vector<ExprId> inputs,
             const gcvec<Value> &results, const std::vector<std::vector<RType>> &types,
             bool collect) {
  RStmt s{RKind::ParallelMap};
  s.members = std::move(members);
  s.count = static_cast<int>(count);
  s.args = std::move(inputs);
  gcvec<Value> values;
  for (size_t i = 0; i < count; ++i) {
    gcvec<Value> leaves;
    for (RType t : types[types.size() == 1 ? 0 : i]) {
      leaves.push_back(new_var(t));
      s.outs.push_back(var_of(leaves.back()));
    }
    const Value *next = leaves.data();
    values.push_back(with_leaves(results[results.size() == 1 ? 0 : i], next));
  }
  emit(std::move(s));
  read_cells(); // members may have assigned cells (they then run in order)
  return collect ? list_from(values.data(), values.size()) : Value::unspecified();
}

bool one_function_for_all(Value f, const gcvec<Value> &elements, bool collect, const char *who,
                          Value *out) {
  std::vector<ExprId> inputs;
  if (!shared_inputs(elements, who, inputs)) return false;
  gcvec<Value> result(1);
  std::vector<std::vector<RType>> types(1);
  int member = in_new_function("member of " + std::string(who) + ": " + procedure_name(f), [&] {
    Value x = input_like(elements[0]);
    result[0] = apply_procedure(f, &x, 1);
    add_outputs(result[0], who, types[0]);
  });
  *out = record({member}, elements.size(), std::move(inputs), result, types, collect);
  return true;
}

bool one_function_each(Value f, const gcvec<Value> &elements, bool collect, const char *who,
                       Value *out) {
  std::vector<int> members;
  gcvec<Value> results(elements.size());
  std::vector<std::vector<RType>> types(elements.size());
  for (size_t i = 0; i < elements.size(); ++i)
    members.push_back(in_new_function(
        "member " + std::to_string(i) + " of " + who + ": " + procedure_name(f), [&] {
          Value x = elements[i];
          results[i] = apply_procedure(f, &x, 1);
          add_outputs(results[i], who, types[i]);
        }));
  *out = record(std::move(members), elements.size(), {}, results, types, collect);
  return true;
}

template <bool Collect> Value P_parallel_map(Value *a, int n) {
  const char *who = Collect ? "parallel-map" : "parallel-for-each";
  if (!is_procedure(a[0])) wrong_type(a[0], 1, who);
  require_no_captured_assignment(a[0], who);
  if (n == 2 && list_length(a[1]) > 0 && !as_rtlist(a[1])) {
    gcvec<Value> elements;
    for (Value x = a[1]; is_pair(x); x = cdr(x))
      elements.push_back(car(x));
    if (does_run_time_work(a[0], {elements[0]})) {
      Value v;
      if (tentatively([&] { return one_function_for_all(a[0], elements, Collect, who, &v); }) ||
          tentatively([&] { return one_function_each(a[0], elements, Collect, who, &v); }))
        return v;
    }
  }
  // The build's own map or for-each: unrolled, or a C loop over a run-time list.
  Symbol *serial = intern(Collect ? "map" : "for-each").symbol();
  return apply_procedure(serial->global, a, n);
}

} // namespace

// What this file specializes (the table is pe/specialized.cpp).
const PrimFn p_parallel_map = P_parallel_map<true>, p_parallel_for_each = P_parallel_map<false>;

} // namespace sicm::build
