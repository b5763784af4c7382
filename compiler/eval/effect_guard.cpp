// Effects refused while a procedure is traced into a kernel (see
// effect_guard.hpp).
#include "eval/effect_guard.hpp"

#include <string>

#include "base/error.hpp"

namespace sicm {

namespace {

thread_local int g_depth = 0;      // guards alive on this thread
thread_local uint32_t g_since = 0; // g_frame_serial when the outermost began

[[noreturn]] void refuse(const std::string &what, SrcLoc loc) {
  runtime_error(loc, what + " in a procedure being compiled into a kernel: it would happen once, "
                            "while compiling, instead of at each call");
}

} // namespace

EffectGuard::EffectGuard() : outer_since_(g_since), outer_depth_(g_depth) {
  if (g_depth++ == 0) g_since = g_frame_serial;
}

EffectGuard::~EffectGuard() {
  g_depth = outer_depth_;
  g_since = outer_since_;
}

void refuse_effect(const char *what) {
  if (g_depth > 0) refuse(what, current_call_loc());
}

void refuse_change_of(Value v, const char *who) {
  if (g_depth == 0) return;
  if ((v.is(Tag::Vector) && !made_since(v.vector()->serial, g_since)) ||
      (v.is(Tag::Pair) && !made_since(v.pair()->serial, g_since)) || v.is(Tag::String))
    refuse(std::string(who) + " of an object made outside it", current_call_loc());
}

void refuse_set_global(Symbol *s, SrcLoc loc) {
  if (g_depth > 0) refuse("set! of the global variable " + s->name, loc);
}

void refuse_set_local(uint32_t frame_serial, SrcLoc loc) {
  if (g_depth > 0 && !made_since(frame_serial, g_since))
    refuse("set! of a variable made outside it", loc);
}

} // namespace sicm
