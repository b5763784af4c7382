// Every primitive declares when its work happens (Stage, base/primitive.hpp),
// and sicm build handles each that is not Pure: an Effect or RunTime work
// computed while compiling would happen once, in the compiler, instead of in
// the program. These tests hold the declarations against the build's tables
// (pe/specialized.cpp), so a new primitive cannot silently run at compile
// time; and each numerical primitive has its one argument signature
// (builtins/numeric_arguments.hpp), checked alike in both modes.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "base/primitive.hpp"
#include "builtins/numeric_arguments.hpp"
#include "pe/specialized.hpp"

using namespace sicm;

namespace {

std::set<std::string> names_of(const std::vector<const char *> &list) {
  return std::set<std::string>(list.begin(), list.end());
}

std::set<std::string> specialized() {
  std::set<std::string> names;
  for (const build::Specialization &s : build::specializations())
    names.insert(s.name);
  return names;
}

const Primitive *primitive_named(const std::string &name) {
  for (const Primitive *p : defined_primitives())
    if (name == p->name) return p;
  return nullptr;
}

TEST(PrimitiveStage, EveryEffectIsHandledByTheBuild) {
  std::set<std::string> handled = specialized();
  for (const std::string &n : names_of(build::effects_refused_for_run()))
    handled.insert(n);
  for (const std::string &n : names_of(build::effects_done_while_compiling()))
    handled.insert(n);
  for (const Primitive *p : defined_primitives()) {
    if (p->stage == Stage::Effect) {
      EXPECT_TRUE(handled.count(p->name))
          << p->name << " is an effect that sicm build neither specializes nor lists in "
          << "effects_refused_for_run or effects_done_while_compiling (pe/specialized.cpp)";
    }
  }
}

TEST(PrimitiveStage, EveryRunTimePrimitiveIsSpecialized) {
  std::set<std::string> handled = specialized();
  for (const Primitive *p : defined_primitives()) {
    if (p->stage == Stage::RunTime) {
      EXPECT_TRUE(handled.count(p->name))
          << p->name << " is run-time work that sicm build does not specialize";
    }
  }
}

TEST(PrimitiveStage, WhatTheBuildTreatsAsEffectsIsDeclaredOne) {
  std::set<std::string> effects = names_of(build::effects_refused_for_run());
  for (const std::string &n : names_of(build::effects_done_while_compiling()))
    effects.insert(n);
  for (const std::string &name : effects) {
    const Primitive *p = primitive_named(name);
    if (!p) continue; // a special form or a library procedure
    EXPECT_EQ(p->stage, Stage::Effect) << name << " is declared Pure or RunTime";
  }
}

TEST(PrimitiveStage, NumericalPrimitivesHaveOneSignature) {
  std::set<std::string> signed_;
  for (const NumericSignature &s : numeric_signatures())
    EXPECT_TRUE(signed_.insert(s.who).second) << s.who << " has two signatures";
  const std::set<std::string> not_numerical = {"parameter", "parallel-map", "parallel-for-each"};
  for (const Primitive *p : defined_primitives()) {
    if (p->stage == Stage::RunTime && !not_numerical.count(p->name)) {
      EXPECT_TRUE(signed_.count(p->name)) << p->name << " has no NumericSignature";
    }
  }
}

TEST(PrimitiveStage, ArithmeticIsPureAndOutputIsNot) {
  // Two known answers, so that the tests above cannot pass on empty tables.
  ASSERT_NE(primitive_named("+"), nullptr);
  EXPECT_EQ(primitive_named("+")->stage, Stage::Pure);
  ASSERT_NE(primitive_named("display"), nullptr);
  EXPECT_EQ(primitive_named("display")->stage, Stage::Effect);
  ASSERT_NE(primitive_named("evolve"), nullptr);
  EXPECT_EQ(primitive_named("evolve")->stage, Stage::RunTime);
}

} // namespace
