// The library effects a program uses (stdlib/effects.sicm), for the
// "effects" list of `sicm build --report`.
#pragma once

#include <string>
#include <vector>

namespace sicm {

// The names recorded by (%use-effect 'name), each once, in the order first
// recorded.
const std::vector<std::string> &used_effects();

// (%use-effect name): called by each effect constructor of the library.
// Called by init_interpreter.

} // namespace sicm
