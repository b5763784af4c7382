// Declarations shared by the core primitives and the evaluator.
#pragma once

#include <string_view>

#include "base/value.hpp"

namespace sicm {


bool eqv(Value a, Value b);
bool equal(Value a, Value b);

// All program output goes through here (so with-output-to-string can capture it).
void output(std::string_view s);
// sicm build: every output not captured by with-output-to-string goes to
// the hook instead of stdout (null: stdout).
using OutputHook = void (*)(std::string_view s);
void set_output_hook(OutputHook hook);
// sicm build: called before output goes into with-output-to-string's string
// (null: nothing); may throw.
using CaptureHook = void (*)();
void set_capture_hook(CaptureHook hook);
// sicm build: run_source passes each top-level value it prints through this
// first (null: none), so run-time values can be named in the output.
using PrintPreparer = Value (*)(Value v);
void set_print_preparer(PrintPreparer prepare);
PrintPreparer print_preparer();
void flush_output();
int output_column();

// Escape-only continuations made by call/cc.
bool is_continuation(Value v);
[[noreturn]] void throw_to_continuation(Value k, Value *args, int nargs);

} // namespace sicm
