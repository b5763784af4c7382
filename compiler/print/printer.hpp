// Printing values the way MIT Scheme prints them: `write` form (strings
// quoted, characters as #\a) and `display` form.
#pragma once

#include <string>

#include "base/value.hpp"

namespace sicm {

void print_value(std::string &out, Value v, bool display);

// Later layers print their values by converting them to a datum first
// (an expression to its simplified prefix form, (up 1 2) for a structure).
using DatumConverter = Value (*)(Value v);
void set_datum_converter(Tag tag, DatumConverter convert);
std::string write_string(Value v);
std::string display_string(Value v);

// Print uninterned symbols -- the names the system makes for itself
// (compatible-shape's literals, kernel parameters) -- marked «so», for the
// test runner to find any that reaches a result. On when the environment
// has SICM_MARK_GENERATED_NAMES (tests/run sets it), else off.
void set_mark_generated_names(bool on);

} // namespace sicm
