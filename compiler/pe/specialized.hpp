// The primitives sicm build's partial evaluator gives another meaning, and
// what each becomes. pe/specialized.cpp holds the one table of them; the
// functions are defined in the files named below, next to what they share.
#pragma once

#include <vector>

#include "base/primitive.hpp"

namespace sicm::build {

// One primitive rebound while a build lives (BuildSession).
struct Specialization {
  const char *name;
  int min_args, max_args;
  PrimFn fn;
  // The list primitives that refuse run-time lists are rebound only when
  // the name holds a primitive (the standard library may define some).
  bool only_over_a_primitive = false;
};

// Every primitive begin_build_mode rebinds, in the order it rebinds them.
const std::vector<Specialization> &specializations();

// The primitives refused, on top of the build's, while sicm run compiles
// bisect's function (pe/for_run.cpp): their effect would happen once, at
// compile time, instead of at each call.
const std::vector<const char *> &effects_refused_for_run();

// The effects sicm build performs while compiling, as sicm run would at
// that point of the program: text known at compile time printed into the
// program's output, errors raised (the compiler reports them), and
// mutations of data the compiler holds. Inside a procedure traced for run
// time they are refused (eval/effect_guard.hpp, effects_refused_for_run).
const std::vector<const char *> &effects_done_while_compiling();

// ---- pe/build_mode.cpp: printing, tests and rounding of run-time values -----------------
extern const PrimFn p_display, p_write, p_write_line, p_pp, p_print_expression, p_pe;
extern const PrimFn p_less, p_greater, p_less_eq, p_greater_eq, p_num_equal;
extern const PrimFn p_zero_p, p_positive_p, p_negative_p;
extern const PrimFn p_floor, p_round, p_truncate, p_max, p_min, p_abs, p_magnitude, p_not;
extern const PrimFn p_eq_p, p_eqv_p, p_equal_p;
extern const PrimFn p_random, p_real_time, p_parameter, p_runtime;
extern const PrimFn p_number_p, p_real_p, p_inexact_p, p_exact_p, p_integer_p, p_exact_integer_p,
    p_exact_nonnegative_integer_p, p_exact_rational_p;
extern const PrimFn p_exact_to_inexact, p_inexact;
extern const PrimFn p_divide, p_sqrt, p_log, p_asin, p_acos, p_expt;

// ---- pe/numerics.cpp: the numerical primitives record statements ------------------------
extern const PrimFn p_definite_integral, p_minimize, p_brent_min, p_multidimensional_minimize,
    p_find_root, p_nelder_mead, p_bisect, p_state_advancer, p_evolve, p_crossings;

// ---- pe/plots.cpp: plots record statements ----------------------------------------------
extern const PrimFn p_frame, p_plot_point, p_plot_line, p_plot_series, p_graphics_close,
    p_graphics_clear;

// ---- pe/lists.cpp: lists whose length is known only at run time -------------------------
extern const PrimFn p_car, p_cdr, p_null_p, p_pair_p, p_list_p, p_length, p_reverse, p_list_ref,
    p_list_tail, p_last, p_map, p_for_each;
extern const PrimFn p_caar, p_cadr, p_cdar, p_cddr, p_caddr, p_cdddr, p_cadddr, p_first, p_second,
    p_third, p_fourth, p_fifth;
extern const PrimFn p_append, p_list_copy, p_list_to_vector, p_sort, p_filter, p_reduce,
    p_fold_left, p_fold_right, p_list_head, p_sublist, p_last_pair, p_member, p_memv, p_assoc,
    p_append_map;

// ---- pe/parallel.cpp ----------------------------------------------------------------------
extern const PrimFn p_parallel_map, p_parallel_for_each;

// ---- pe/branches.cpp: mutations a traced procedure may not make ---------------------------
extern const PrimFn p_set_car, p_set_cdr, p_vector_set, p_vector_fill, p_vector_copy, p_string_set,
    p_append_bang, p_with_output_to_string;

} // namespace sicm::build
