// Parameters set from the command line: (parameter 'name default).
#pragma once

#include <string>

namespace sicm {

// Record `--param NAME=VALUE` (VALUE a real number in C syntax). False and
// a reason for anything else.
bool set_parameter_option(const std::string &assignment, std::string *why_not);

// (parameter name default). Called by init_interpreter.
void install_parameter_primitives();

} // namespace sicm
