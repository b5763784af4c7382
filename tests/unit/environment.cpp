// Start the collector and the interpreter once for every unit test.
#include <gtest/gtest.h>

#include "driver/init.hpp"
#include "eval/interp.hpp"

namespace {

class InterpreterEnvironment : public ::testing::Environment {
public:
  void SetUp() override {
    GC_INIT();
    sicm::init_interpreter();
  }
};

const auto *const kEnvironment = ::testing::AddGlobalTestEnvironment(new InterpreterEnvironment);

} // namespace
