// Installers for the groups of primitives, called once at startup
// (driver/init.cpp), each defined in the file of its group.
#pragma once

namespace sicm {

void install_core_primitives();           // core.cpp: equivalence, predicates, control, output
void install_list_primitives();           // list.cpp: pairs, lists, streams
void install_number_primitives();         // number.cpp: Scheme's numeric primitives
void install_text_primitives();           // text.cpp: characters, strings, symbols
void install_vector_primitives();         // vector.cpp: vectors
void install_plot_primitives();           // plot.cpp: frame, plot-point, ...
void install_show_primitives();           // show.cpp: show-expression, ->infix, ->tex-string
void install_numerics_primitives();       // numerics.cpp: integrals, minimizers, roots, ODEs
void install_crossing_event_primitives(); // crossing_events.cpp: on-crossing, stop-on-crossing
void install_kernel_primitives();         // kernel.cpp: compile-procedure, kernel?
void install_parameter_primitives();      // parameter.cpp: (parameter 'name default)
void install_effect_primitives();         // effects_used.cpp: the library's effects used

} // namespace sicm
