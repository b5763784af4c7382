// The one table of the primitives sicm build's partial evaluator specializes:
// while a build lives (BuildSession), each name below means the function
// beside it, which handles run-time values and otherwise calls the primitive
// it replaced (call_original). Everything not listed runs at compile time as
// it does in sicm run. To specialize another primitive, define its function
// next to its kind in pe/ and add a row here.
#include "pe/specialized.hpp"

#include "base/primitive.hpp"

namespace sicm::build {

const std::vector<Specialization> &specializations() {
  static const std::vector<Specialization> table = {
      // Printing names the run-time values it prints (pe/build_mode.cpp).
      {"display", 1, 2, p_display},
      {"write", 1, 2, p_write},
      {"write-line", 1, 2, p_write_line},
      {"pp", 1, 2, p_pp},
      {"print-expression", 1, 1, p_print_expression},
      {"pe", 1, 1, p_pe},
      // Tests, rounding and extrema of run-time values become statements.
      {"<", 1, kVariadic, p_less},
      {">", 1, kVariadic, p_greater},
      {"<=", 1, kVariadic, p_less_eq},
      {">=", 1, kVariadic, p_greater_eq},
      {"=", 1, kVariadic, p_num_equal},
      {"zero?", 1, 1, p_zero_p},
      {"positive?", 1, 1, p_positive_p},
      {"negative?", 1, 1, p_negative_p},
      {"floor", 1, 1, p_floor},
      {"round", 1, 1, p_round},
      {"truncate", 1, 1, p_truncate},
      {"max", 1, kVariadic, p_max},
      {"min", 1, kVariadic, p_min},
      {"abs", 1, 1, p_abs},
      {"magnitude", 1, 1, p_magnitude},
      {"not", 1, 1, p_not},
      {"eq?", 2, 2, p_eq_p},
      {"eqv?", 2, 2, p_eqv_p},
      {"equal?", 2, 2, p_equal_p},
      // Random numbers are drawn while compiling, where that draws what
      // sicm run draws; the clocks and parameters are read at run time.
      {"random", 1, 2, p_random},
      {"real-time", 0, 0, p_real_time},
      {"parameter", 2, 2, p_parameter},
      {"runtime", 0, 0, p_runtime},
      // A run-time value is a real number; its exactness is its type's.
      {"number?", 1, 1, p_number_p},
      {"real?", 1, 1, p_real_p},
      {"inexact?", 1, 1, p_inexact_p},
      {"exact?", 1, 1, p_exact_p},
      {"integer?", 1, 1, p_integer_p},
      {"exact-integer?", 1, 1, p_exact_integer_p},
      {"exact-nonnegative-integer?", 1, 1, p_exact_nonnegative_integer_p},
      {"exact-rational?", 1, 1, p_exact_rational_p},
      {"exact->inexact", 1, 1, p_exact_to_inexact},
      {"inexact", 1, 1, p_inexact},
      // Operations that can fail at run time remember where they were
      // called, for the executable's message.
      {"/", 1, kVariadic, p_divide},
      {"sqrt", 1, 1, p_sqrt},
      {"log", 1, 1, p_log},
      {"asin", 1, 1, p_asin},
      {"acos", 1, 1, p_acos},
      {"expt", 2, 2, p_expt},

      // The numerical primitives record a statement and return run-time
      // values; their procedures are traced into functions (pe/numerics.cpp).
      {"definite-integral", 3, 5, p_definite_integral},
      {"minimize", 3, 4, p_minimize},
      {"brent-min", 3, 4, p_brent_min},
      {"multidimensional-minimize", 2, 3, p_multidimensional_minimize},
      {"find-root", 3, 4, p_find_root},
      {"nelder-mead", 2, 5, p_nelder_mead},
      {"bisect", 4, 5, p_bisect},
      {"state-advancer", 1, kVariadic, p_state_advancer},
      {"evolve", 1, kVariadic, p_evolve},
      {"crossings", 1, kVariadic, p_crossings},

      // Plots record statements (pe/plots.cpp).
      {"frame", 4, kVariadic, p_frame},
      {"plot-point", 3, 4, p_plot_point},
      {"plot-line", 5, 6, p_plot_line},
      {"plot-series", 2, kVariadic, p_plot_series},
      {"graphics-close", 1, 1, p_graphics_close},
      {"graphics-clear", 1, 1, p_graphics_clear},

      // Lists whose length is known only at run time (pe/lists.cpp).
      {"car", 1, 1, p_car},
      {"cdr", 1, 1, p_cdr},
      {"null?", 1, 1, p_null_p},
      {"pair?", 1, 1, p_pair_p},
      {"list?", 1, 1, p_list_p},
      {"length", 1, 1, p_length},
      {"reverse", 1, 1, p_reverse},
      {"list-ref", 2, 2, p_list_ref},
      {"list-tail", 2, 2, p_list_tail},
      {"last", 1, 1, p_last},
      {"map", 2, kVariadic, p_map},
      {"for-each", 2, kVariadic, p_for_each},
      {"caar", 1, 1, p_caar},
      {"cadr", 1, 1, p_cadr},
      {"cdar", 1, 1, p_cdar},
      {"cddr", 1, 1, p_cddr},
      {"caddr", 1, 1, p_caddr},
      {"cdddr", 1, 1, p_cdddr},
      {"cadddr", 1, 1, p_cadddr},
      {"first", 1, 1, p_first},
      {"second", 1, 1, p_second},
      {"third", 1, 1, p_third},
      {"fourth", 1, 1, p_fourth},
      {"fifth", 1, 1, p_fifth},
      // ... and those that refuse them with a clear error.
      {"append", 0, kVariadic, p_append, true},
      {"list-copy", 1, 1, p_list_copy, true},
      {"list->vector", 1, 1, p_list_to_vector, true},
      {"sort", 2, 2, p_sort, true},
      {"filter", 2, 2, p_filter, true},
      {"reduce", 3, 3, p_reduce, true},
      {"fold-left", 3, kVariadic, p_fold_left, true},
      {"fold-right", 3, kVariadic, p_fold_right, true},
      {"list-head", 2, 2, p_list_head, true},
      {"sublist", 3, 3, p_sublist, true},
      {"last-pair", 1, 1, p_last_pair, true},
      {"member", 2, 3, p_member, true},
      {"memv", 2, 2, p_memv, true},
      {"assoc", 2, 3, p_assoc, true},
      {"append-map", 2, kVariadic, p_append_map, true}, // equal?: see p_equal_p

      // Parallel maps run their members' work at run time (pe/parallel.cpp).
      {"parallel-map", 2, kVariadic, p_parallel_map},
      {"parallel-for-each", 2, kVariadic, p_parallel_for_each},

      // Mutations and captured output that a procedure traced for run time
      // would make once, while compiling, are refused (pe/branches.cpp).
      {"set-car!", 2, 2, p_set_car},
      {"set-cdr!", 2, 2, p_set_cdr},
      {"vector-set!", 3, 3, p_vector_set},
      {"vector-fill!", 2, 4, p_vector_fill},
      {"vector-copy!", 3, 5, p_vector_copy},
      {"string-set!", 3, 3, p_string_set},
      {"append!", 0, kVariadic, p_append_bang},
      {"with-output-to-string", 0, 1, p_with_output_to_string},
  };
  return table;
}

const std::vector<const char *> &effects_refused_for_run() {
  // (Mutations of what the procedure did not make, and forcing promises it
  // did not make, the build refuses already: the last rows above.)
  static const std::vector<const char *> names = {
      "random",       "runtime",          "real-time",  "exit",
      "%exit",        "newline",          "fresh-line", "write-char",
      "write-string", "display",          "write",      "write-line",
      "pp",           "print-expression", "pe",         "with-output-to-string",
  };
  return names;
}

const std::vector<const char *> &effects_done_while_compiling() {
  static const std::vector<const char *> names = {
      // Text known while compiling is the program's output, in its place.
      "newline", "fresh-line", "write-char", "write-string", "flush-output", "series:print",
      "series:for-each", "show-expression",
      // An error raised while compiling is the compiler's to report, as
      // sicm run reports it (tests/run accepts the same exit status).
      "error", "warn",
      // Mutations of lists the compiler holds (run-time lists are refused
      // by pe/lists.cpp's rows above).
      "reverse!", "except-last-pair!", "delete!", "sort!",
      // Which effects a scene asks for: the compiler's own bookkeeping
      // (builtins/effects_used.cpp, --report).
      "%use-effect"};
  return names;
}

} // namespace sicm::build
