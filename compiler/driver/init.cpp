// Starting the interpreter: the one place that knows every layer. It
// installs each layer's primitives and tells the lower layers what the
// higher ones provide (how values are written in messages), then loads the
// standard library from its embedded copy.
#include "driver/init.hpp"

#include <string>

#include "algebra/differential.hpp"
#include "algebra/generic.hpp"
#include "algebra/operator.hpp"
#include "algebra/series.hpp"
#include "algebra/symbolic.hpp"
#include "base/limits.hpp"
#include "base/value.hpp"
#include "builtins/builtins.hpp"
#include "builtins/numerics.hpp"
#include "cas/expr.hpp"
#include "eval/analyze.hpp"
#include "eval/interp.hpp"
#include "eval/procedure.hpp"
#include "eval/stdlib.hpp"
#include "pe/build.hpp"
#include "print/printer.hpp"
#include "syntax/reader.hpp"

namespace sicm {

namespace {

void load_embedded_stdlib() {
  for (const EmbeddedSource *s = embedded_stdlib(); s->name; ++s) {
    uint32_t file = register_source(std::string("<stdlib>/") + s->name, s->text);
    for (const ReadForm &f : read_all(file))
      eval_toplevel(f.datum, f.loc);
  }
}

} // namespace

void init_interpreter() {
  set_value_writer(write_string);
  set_expression_node_counter(expr_count);
  set_scalar_compiler(compile_for_run);
  set_system_compiler(compile_system_for_run);
  set_event_compiler(compile_event_for_run);
  install_special_forms();
  install_core_primitives();
  install_list_primitives();
  install_number_primitives();
  install_text_primitives();
  install_vector_primitives();
  install_plot_primitives();
  install_show_primitives();
  install_algebra_primitives();
  install_generic_primitives();
  register_differential_arith();
  install_operator_primitives();
  install_literal_function_primitives();
  install_series_primitives();
  install_numerics_primitives();
  install_crossing_event_primitives();
  install_kernel_primitives();
  install_parameter_primitives();
  install_effect_primitives();
  load_embedded_stdlib();
  set_first_user_file(register_source("<first user source>", "") + 1);
}

} // namespace sicm
