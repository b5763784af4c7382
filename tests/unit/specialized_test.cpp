// Unit tests of the table of primitives sicm build specializes
// (pe/specialized.cpp): every row names a primitive the interpreter has,
// with its arity, once; a BuildSession rebinds exactly those and puts the
// originals back when it ends.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "base/primitive.hpp"
#include "eval/interp.hpp"
#include "pe/build.hpp"
#include "pe/specialized.hpp"

using namespace sicm;
using build::Specialization;
using build::specializations;

namespace {

const Primitive *primitive_named(const char *name) {
  Symbol *s = intern(name).symbol();
  if (!s->bound || !s->global.is(Tag::Primitive)) return nullptr;
  return s->global.as<Primitive>();
}

TEST(Specializations, EachNameOnce) {
  std::set<std::string> seen;
  for (const Specialization &p : specializations())
    EXPECT_TRUE(seen.insert(p.name).second) << p.name << " is listed twice";
}

TEST(Specializations, NameThePrimitivesWithTheirArities) {
  for (const Specialization &p : specializations()) {
    const Primitive *original = primitive_named(p.name);
    if (!original) {
      EXPECT_TRUE(p.only_over_a_primitive) << p.name << " is not a primitive of sicm run";
      continue;
    }
    EXPECT_EQ(p.min_args, original->min_args) << p.name;
    EXPECT_EQ(p.max_args, original->max_args) << p.name;
  }
}

TEST(Specializations, ABuildRebindsThemAndItsEndRestoresThem) {
  std::vector<const Primitive *> before;
  for (const Specialization &p : specializations())
    before.push_back(primitive_named(p.name));
  {
    BuildSession session;
    for (size_t i = 0; i < specializations().size(); ++i) {
      const Specialization &p = specializations()[i];
      const Primitive *now = primitive_named(p.name);
      if (!before[i]) {
        EXPECT_EQ(now, nullptr) << p.name << " is rebound, but it is not a primitive";
        continue;
      }
      ASSERT_NE(now, nullptr) << p.name;
      EXPECT_EQ(now->fn, p.fn) << p.name << " is not rebound";
    }
  }
  for (size_t i = 0; i < specializations().size(); ++i)
    EXPECT_EQ(primitive_named(specializations()[i].name), before[i])
        << specializations()[i].name << " is not restored";
}

TEST(Specializations, EffectsRefusedForRunArePrimitives) {
  for (const char *name : build::effects_refused_for_run())
    EXPECT_NE(primitive_named(name), nullptr) << name;
}

} // namespace
