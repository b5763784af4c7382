// Does a procedure assign a variable it does not own (see
// captured_assignment.hpp)? A walk over the analyzed body that counts the
// frames opened inside the procedure: a local assignment that walks up past
// them reaches a frame of an enclosing procedure.
#include "eval/captured_assignment.hpp"

#include "base/error.hpp"
#include "eval/procedure.hpp"

namespace sicm {

namespace {

std::string name_of(const Node *n) {
  return n->value.is(Tag::Symbol) ? n->value.symbol()->name : std::string();
}

// `level`: frames opened between the procedure's own frame and n (0 in its
// body). A local reference of depth d names a frame of the procedure itself
// when d <= level.
bool find(const Node *n, uint32_t level, CapturedAssignment *out) {
  if (!n) return false;
  auto outside = [&](const Node *target) {
    return target->kind == NodeKind::GlobalRef || target->kind == NodeKind::SetGlobal ||
           target->depth > level;
  };
  switch (n->kind) {
  case NodeKind::SetLocal:
  case NodeKind::SetGlobal:
    if (outside(n)) {
      *out = {true, n->loc, name_of(n)};
      return true;
    }
    return find(n->kids[0], level, out);
  case NodeKind::FluidLet: {
    uint32_t count = (n->nkids - 1) / 2;
    for (uint32_t i = 0; i < count; ++i)
      if (outside(n->kids[i])) {
        *out = {true, n->loc, name_of(n->kids[i])};
        return true;
      }
    for (uint32_t i = count; i < n->nkids; ++i)
      if (find(n->kids[i], level, out)) return true;
    return false;
  }
  case NodeKind::Lambda: return find(n->lambda->body, level + 1, out);
  case NodeKind::Let: // the inits outside the new frame, the body inside it
    for (uint32_t i = 0; i + 1 < n->nkids; ++i)
      if (find(n->kids[i], level, out)) return true;
    return n->nkids > 0 && find(n->kids[n->nkids - 1], level + 1, out);
  case NodeKind::Letrec:
    for (uint32_t i = 0; i < n->nkids; ++i)
      if (find(n->kids[i], level + 1, out)) return true;
    return false;
  default:
    for (uint32_t i = 0; i < n->nkids; ++i)
      if (find(n->kids[i], level, out)) return true;
    return false;
  }
}

} // namespace

CapturedAssignment find_captured_assignment(Value f) {
  CapturedAssignment found;
  if (f.is(Tag::Closure)) find(f.as<Closure>()->lambda->body, 0, &found);
  return found;
}

void require_no_captured_assignment(Value f, const char *who) {
  CapturedAssignment a = find_captured_assignment(f);
  if (!a.found) return;
  std::string what = a.name.empty() ? "a variable" : a.name;
  throw Error(ErrorKind::Runtime, a.loc,
              std::string("The procedure passed to ") + who + " assigns " + what +
                  ", which it does not own; members of " + who + " may run at the same time",
              "compute the value and return it, or keep the variable local to the procedure");
}

} // namespace sicm
