// "Did you mean ...?" suggests a slip of the fingers, never a stranger.
#include <gtest/gtest.h>

#include "eval/name_suggestion.hpp"

using sicm::suggested_name;

namespace {
const std::vector<std::string> kKnown = {"*",  "+",  "x",      "square",         "cube",
                                         "<=", "->", "evolve", "state-advancer", "L-pendulum"};
}

TEST(NameSuggestion, AMisspeltWordGetsTheWord) {
  EXPECT_EQ(suggested_name("sqaure", kKnown), "square");
  EXPECT_EQ(suggested_name("evovle", kKnown), "evolve");
  EXPECT_EQ(suggested_name("state-advancr", kKnown), "state-advancer");
}

TEST(NameSuggestion, AShortNameGetsNone) {
  // One edit from * and from x, and meant as neither.
  EXPECT_EQ(suggested_name("y", kKnown), "");
  EXPECT_EQ(suggested_name("q1", kKnown), "");
}

TEST(NameSuggestion, AWordIsNeverSuggestedAnOperator) {
  const std::vector<std::string> operators = {"*", "+", "<=", "->", "-->"};
  EXPECT_EQ(suggested_name("abc", operators), "");
  EXPECT_EQ(suggested_name("<==", {"square", "<="}), "<=");
  EXPECT_EQ(suggested_name("<==", {"a<="}), "");
}

TEST(NameSuggestion, AFarNameGetsNone) {
  EXPECT_EQ(suggested_name("velocity", kKnown), "");
  EXPECT_EQ(suggested_name("cubes", kKnown), "cube");
}
