// (%use-effect 'name): the effects library says which effects a program builds.
//
// Each constructor of stdlib/effects.sicm calls it when the program builds
// the effect (not when the effect's term is evaluated), so the list names
// what the scene is made of, whether or not a term folds away: a drive of
// amplitude 0 is listed, and costs nothing (the report's op counts show it).
#include "builtins/effects_used.hpp"
#include "builtins/builtins.hpp"

#include <algorithm>

#include "base/primitive.hpp"

namespace sicm {

namespace {

std::vector<std::string> g_used;

Value P_use_effect(Value *a, int) {
  if (!is_symbol(a[0])) wrong_type(a[0], 1, "%use-effect");
  std::string name = symbol_name(a[0]);
  if (std::find(g_used.begin(), g_used.end(), name) == g_used.end()) g_used.push_back(name);
  return Value::unspecified();
}

} // namespace

const std::vector<std::string> &used_effects() {
  return g_used;
}

void install_effect_primitives() {
  define_primitive("%use-effect", 1, 1, Stage::Effect, P_use_effect);
}

} // namespace sicm
