// The analyzed program as text (see analyzed_dump.hpp).
#include "eval/analyzed_dump.hpp"


namespace sicm {

namespace {

std::string name_of(const Node *n) {
  return n->value.is(Tag::Symbol) ? n->value.symbol()->name : written(n->value);
}

std::string local(const Node *n) {
  return name_of(n) + "@" + std::to_string(n->depth) + "." + std::to_string(n->index);
}

void dump(const Node *n, std::string &out);

void kids(const Node *n, uint32_t from, uint32_t to, std::string &out) {
  for (uint32_t i = from; i < to && i < n->nkids; ++i) {
    out += ' ';
    dump(n->kids[i], out);
  }
}

// A Let's or Letrec's initial values, all kids but the body.
void inits(const Node *n, std::string &out) {
  std::string text;
  kids(n, 0, n->nkids - 1, text);
  out += text.empty() ? text : text.substr(1);
}

void form(const char *head, const Node *n, std::string &out) {
  out += '(';
  out += head;
  kids(n, 0, n->nkids, out);
  out += ')';
}

void dump(const Node *n, std::string &out) {
  if (!n) {
    out += "#<null>";
    return;
  }
  switch (n->kind) {
  case NodeKind::Const: {
    bool self = !n->value.is(Tag::Symbol) && !n->value.is(Tag::Pair) && !n->value.is(Tag::Nil);
    out += self ? written(n->value) : "(quote " + written(n->value) + ")";
    return;
  }
  case NodeKind::LocalRef: out += local(n); return;
  case NodeKind::GlobalRef: out += "(global " + name_of(n) + ")"; return;
  case NodeKind::SetLocal:
    out += "(set-local! " + local(n);
    kids(n, 0, 1, out);
    out += ')';
    return;
  case NodeKind::SetGlobal:
  case NodeKind::DefineGlobal:
    out += (n->kind == NodeKind::SetGlobal ? "(set-global! " : "(define ") + name_of(n);
    kids(n, 0, 1, out);
    out += ')';
    return;
  case NodeKind::If: form("if", n, out); return;
  case NodeKind::Lambda: {
    const Lambda *l = n->lambda;
    out += "(lambda " + (l->name ? l->name->name : std::string("anonymous")) + " (" +
           std::to_string(l->nrequired) + " " + std::to_string(l->noptional) + " " +
           (l->rest ? "#t" : "#f") + " " + std::to_string(l->frame_size) + ") ";
    dump(l->body, out);
    out += ')';
    return;
  }
  case NodeKind::Seq: form("begin", n, out); return;
  case NodeKind::Call: form("call", n, out); return;
  case NodeKind::And: form("and", n, out); return;
  case NodeKind::Or: form("or", n, out); return;
  case NodeKind::Let:
  case NodeKind::Letrec:
    out += (n->kind == NodeKind::Let ? "(let " : "(letrec ") + std::to_string(n->index) + " (";
    inits(n, out);
    out += ")";
    kids(n, n->nkids - 1, n->nkids, out);
    out += ')';
    return;
  case NodeKind::Delay: form("delay", n, out); return;
  case NodeKind::FluidLet: form("fluid-let", n, out); return;
  }
  out += "#<unknown node>";
}

} // namespace

std::string dump_node(const Node *n) {
  std::string out;
  dump(n, out);
  return out;
}

} // namespace sicm
