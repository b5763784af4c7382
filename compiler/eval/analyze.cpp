// The analyzer: special forms to AST Nodes with lexical addresses.
//
// Approach. A form is analyzed once, before it runs. Core forms (quote, if,
// define, set!, lambda, begin, let, letrec, and, or, delay, fluid-let) map to
// their own Node kinds; derived forms (cond, case, do, when, unless, let*,
// named let, quasiquote, receive, ...) are rewritten into core forms at the
// datum level and analyzed again. Rewrites embed procedure objects (cons,
// memv, ...) directly in operator position, so user definitions that shadow
// those names cannot change what a derived form means.
//
// Scopes. A body (of a lambda or a let) gets one Frame holding its
// parameters and every name it defines internally (scanned before the body is
// analyzed, as MIT's scan-defines does), so each local has a fixed
// (depth, index) address. Anything not found in the scopes is global.
//
// Positions. A pair's `loc` is where its car was read; the position of a whole
// form is passed down beside it. Rewritten forms keep the positions of the
// user's sub-forms.
#include "eval/analyze.hpp"

#include <algorithm>
#include <vector>

#include "eval/procedure.hpp"

namespace sicm {

namespace {

struct Scope {
  std::vector<Symbol *> vars; // symbols are never collected
  Scope *parent;
  long index_of(Symbol *s) const {
    for (size_t i = vars.size(); i-- > 0;)
      if (vars[i] == s) return static_cast<long>(i);
    return -1;
  }
};

Value sym(const char *name) {
  return intern(name);
}

SrcLoc loc_of(Value pair, SrcLoc fallback) {
  if (is_pair(pair) && pair.pair()->loc.known()) return pair.pair()->loc;
  return fallback;
}

Node *new_node(NodeKind kind, SrcLoc loc, uint32_t nkids = 0) {
  Node *n = gc_new<Node>();
  n->kind = kind;
  n->loc = loc;
  n->nkids = nkids;
  if (nkids) {
    n->kids = static_cast<Node **>(GC_MALLOC(sizeof(Node *) * nkids));
    if (!n->kids) throw std::bad_alloc();
  }
  return n;
}

Node *const_node(Value v, SrcLoc loc) {
  Node *n = new_node(NodeKind::Const, loc);
  n->value = v;
  return n;
}

[[noreturn]] void ill_formed(Value form, SrcLoc loc) {
  syntax_error(loc, "Ill-formed special form: " + written(form));
}

// Procedures embedded by rewrites; looked up once after the primitives exist.
Value builtin(const char *name) {
  Symbol *s = intern(name).symbol();
  SICM_ASSERT(s->bound);
  return s->global;
}

class Analyzer {
public:
  explicit Analyzer(GlobalRefHook hook) : hook_(hook) {}
  Node *analyze(Value x, SrcLoc loc, Scope *sc);

private:
  Node *analyze_symbol(Value x, SrcLoc loc, Scope *sc);
  Node *analyze_pair(Value x, SrcLoc loc, Scope *sc);
  Node *analyze_special(int which, Value x, SrcLoc loc, Scope *sc);
  Node *analyze_call(Value x, SrcLoc loc, Scope *sc);
  Node *analyze_body(Value forms, SrcLoc loc, Scope *sc);
  Node *analyze_sequence(Value forms, SrcLoc loc, Scope *sc);
  Node *analyze_lambda(Value params, Value body, SrcLoc loc, Scope *sc, Symbol *name, Value form);
  Node *analyze_define(Value x, SrcLoc loc, Scope *sc);
  Node *analyze_set(Value x, SrcLoc loc, Scope *sc);
  Node *analyze_let(Value x, SrcLoc loc, Scope *sc);
  Node *analyze_letrec(Value x, SrcLoc loc, Scope *sc);
  Node *analyze_fluid_let(Value x, SrcLoc loc, Scope *sc);
  Node *variable_ref(Symbol *s, SrcLoc loc, Scope *sc);
  void scan_defines(Value forms, std::vector<Symbol *> &out);

  GlobalRefHook hook_;
};

bool is_special(Value head, Scope *sc, int &which) {
  if (!is_symbol(head)) return false;
  Symbol *s = head.symbol();
  if (s->special_form < 0) return false;
  for (Scope *p = sc; p; p = p->parent)
    if (p->index_of(s) >= 0) return false; // shadowed by a local
  which = s->special_form;
  return true;
}

// ---- the special-form table ----------------------------------------------

enum Special {
  SF_QUOTE,
  SF_QUASIQUOTE,
  SF_IF,
  SF_DEFINE,
  SF_SET,
  SF_LAMBDA,
  SF_NAMED_LAMBDA,
  SF_BEGIN,
  SF_LET,
  SF_LET_STAR,
  SF_LETREC,
  SF_LETREC_STAR,
  SF_COND,
  SF_CASE,
  SF_AND,
  SF_OR,
  SF_WHEN,
  SF_UNLESS,
  SF_DO,
  SF_DELAY,
  SF_MAKE_STREAM, // cons-stream
  SF_FLUID_LET,
  SF_RECEIVE,
  SF_LET_VALUES,
  SF_DEFINE_INTEGRABLE,
  SF_DECLARE,
  SF_LET_STAR_VALUES,
  SF_ASSERT_SYNTAX_UNUSED,
  SF_COUNT
};

const char *const kSpecialNames[] = {
    "quote",       "quasiquote",   "if",      "define",     "set!",
    "lambda",      "named-lambda", "begin",   "let",        "let*",
    "letrec",      "letrec*",      "cond",    "case",       "and",
    "or",          "when",         "unless",  "do",         "delay",
    "cons-stream", "fluid-let",    "receive", "let-values", "define-integrable",
    "declare",     "let*-values",  nullptr,
};

// ---- rewrites of derived forms --------------------------------------------

Value qq_expand(Value x, int depth, SrcLoc loc);

bool tagged(Value x, const char *tag) {
  return is_pair(x) && is_symbol(car(x)) && symbol_name(car(x)) == tag && is_pair(cdr(x)) &&
         is_null(cdr(cdr(x)));
}

bool has_unquote(Value x, int depth) {
  if (is_pair(x)) {
    if (tagged(x, "unquote") || tagged(x, "unquote-splicing"))
      return depth == 1 || has_unquote(car(cdr(x)), depth - 1);
    if (tagged(x, "quasiquote")) return has_unquote(car(cdr(x)), depth + 1);
    return has_unquote(car(x), depth) || has_unquote(cdr(x), depth);
  }
  if (x.is(Tag::Vector)) {
    Vector *v = x.vector();
    for (size_t i = 0; i < v->len; ++i)
      if (has_unquote(v->items[i], depth)) return true;
  }
  return false;
}

Value quoted(Value x) {
  return list({sym("quote"), x});
}

// Quasiquote at nesting depth `depth` (1 = innermost active level).
Value qq_expand(Value x, int depth, SrcLoc loc) {
  if (!has_unquote(x, depth)) return quoted(x);
  if (x.is(Tag::Vector)) {
    Vector *v = x.vector();
    Value l = list_from(v->items, v->len);
    return list({builtin("list->vector"), qq_expand(l, depth, loc)});
  }
  if (tagged(x, "unquote")) {
    if (depth == 1) return car(cdr(x));
    return list({builtin("list"), quoted(sym("unquote")), qq_expand(car(cdr(x)), depth - 1, loc)});
  }
  if (tagged(x, "quasiquote"))
    return list(
        {builtin("list"), quoted(sym("quasiquote")), qq_expand(car(cdr(x)), depth + 1, loc)});
  if (tagged(x, "unquote-splicing")) {
    if (depth == 1) syntax_error(loc, "unquote-splicing (,@) is not inside a list");
    return list(
        {builtin("list"), quoted(sym("unquote-splicing")), qq_expand(car(cdr(x)), depth - 1, loc)});
  }
  Value head = car(x);
  if (depth == 1 && tagged(head, "unquote-splicing"))
    return list({builtin("append"), car(cdr(head)), qq_expand(cdr(x), depth, loc)});
  return list({builtin("cons"), qq_expand(head, depth, loc), qq_expand(cdr(x), depth, loc)});
}

// (cond clause...) -> nested ifs.
Value cond_expand(Value clauses, Value form, SrcLoc loc) {
  if (is_null(clauses)) return Value::unspecified();
  if (!is_pair(clauses) || !is_pair(car(clauses))) ill_formed(form, loc);
  Value clause = car(clauses);
  Value test = car(clause);
  Value body = cdr(clause);
  Value rest = cdr(clauses);
  if (is_symbol(test) && symbol_name(test) == "else") {
    if (!is_null(rest))
      syntax_error(loc,
                   "Ill-formed special form: else clause must be last in " + written(form));
    if (is_null(body)) ill_formed(form, loc);
    return cons(sym("begin"), body);
  }
  if (is_null(body)) {
    // (test): the value of test when true
    return list({sym("or"), test, cond_expand(rest, form, loc)});
  }
  if (is_pair(body) && is_symbol(car(body)) && symbol_name(car(body)) == "=>") {
    if (!is_pair(cdr(body)) || !is_null(cdr(cdr(body)))) ill_formed(form, loc);
    Value tmp = make_uninterned_symbol("cond-value");
    Value receiver = car(cdr(body));
    return list({sym("let"), list({list({tmp, test})}),
                 list({sym("if"), tmp, list({receiver, tmp}), cond_expand(rest, form, loc)})});
  }
  Value then = cons(sym("begin"), body, loc_of(body, loc));
  if (is_null(rest)) return list({sym("if"), test, then});
  return list({sym("if"), test, then, cond_expand(rest, form, loc)});
}

// (case key clause...) -> a let binding the key and a cond over memv.
Value case_expand(Value x, SrcLoc loc) {
  if (list_length(x) < 2) ill_formed(x, loc);
  Value key = car(cdr(x));
  Value tmp = make_uninterned_symbol("case-key");
  gcvec<Value> conds;
  for (Value c = cdr(cdr(x)); !is_null(c); c = cdr(c)) {
    if (!is_pair(c) || !is_pair(car(c)) || list_length(car(c)) < 2) ill_formed(x, loc);
    Value data = car(car(c));
    Value body = cdr(car(c));
    if (is_symbol(data) && symbol_name(data) == "else") {
      conds.push_back(cons(sym("else"), body));
    } else {
      if (list_length(data) < 0) ill_formed(x, loc);
      conds.push_back(cons(list({builtin("memv"), tmp, quoted(data)}), body));
    }
  }
  Value cond = cons(sym("cond"), list_from(conds.data(), conds.size()));
  return list({sym("let"), list({list({tmp, key})}), cond});
}

// The forms of `forms` followed by `last`, in new pairs that keep the source
// places of the old ones: an error in one of the user's forms then points at
// that form, not at the whole rewritten construct.
Value append_keeping_places(Value forms, Value last) {
  if (!is_pair(forms)) return list({last});
  return cons(car(forms), append_keeping_places(cdr(forms), last), forms.pair()->loc);
}

// (do ((var init step)...) (test res...) command...) -> a named let loop.
Value do_expand(Value x, SrcLoc loc) {
  if (list_length(x) < 3) ill_formed(x, loc);
  Value specs = car(cdr(x));
  Value exit = car(cdr(cdr(x)));
  Value commands = cdr(cdr(cdr(x)));
  if (list_length(specs) < 0 || list_length(exit) < 1) ill_formed(x, loc);
  Value loop = make_uninterned_symbol("do-loop");
  gcvec<Value> bindings, steps;
  std::vector<SrcLoc> step_places;
  for (Value s = specs; !is_null(s); s = cdr(s)) {
    Value spec = car(s);
    long n = list_length(spec);
    if (n < 2 || n > 3 || !is_symbol(car(spec))) ill_formed(x, loc);
    bindings.push_back(cons(car(spec), cons(car(cdr(spec)), Value::nil(), cdr(spec).pair()->loc)));
    steps.push_back(n == 3 ? car(cdr(cdr(spec))) : car(spec));
    step_places.push_back(n == 3 ? cdr(cdr(spec)).pair()->loc : spec.pair()->loc);
  }
  Value result = is_null(cdr(exit)) ? Value::unspecified() : cons(sym("begin"), cdr(exit));
  Value step_list = Value::nil();
  for (size_t i = steps.size(); i-- > 0;)
    step_list = cons(steps[i], step_list, step_places[i]);
  Value again = cons(loop, step_list);
  Value body = cons(sym("begin"), append_keeping_places(commands, again));
  return list({sym("let"), loop, list_from(bindings.data(), bindings.size()),
               cons(sym("if"), cons(car(exit), list({result, body}), exit.pair()->loc))});
}

// (let* ((a 1) (b a)) body) -> nested lets.
Value let_star_expand(Value x, SrcLoc loc) {
  if (list_length(x) < 3) ill_formed(x, loc);
  Value bindings = car(cdr(x));
  Value body = cdr(cdr(x));
  if (list_length(bindings) < 0) ill_formed(x, loc);
  if (is_null(bindings) || is_null(cdr(bindings))) return cons(sym("let"), cons(bindings, body));
  gcvec<Value> bs = list_to_vector(bindings);
  Value inner = cons(sym("let"), cons(list({bs.back()}), body));
  for (size_t i = bs.size() - 1; i-- > 0;)
    inner = list({sym("let"), list({bs[i]}), inner});
  return inner;
}

// (receive formals expr body...) -> (call-with-values (lambda () expr) (lambda formals body...))
Value receive_expand(Value x, SrcLoc loc) {
  if (list_length(x) < 4) ill_formed(x, loc);
  Value formals = car(cdr(x));
  Value expr = car(cdr(cdr(x)));
  Value body = cdr(cdr(cdr(x)));
  return list({builtin("call-with-values"), list({sym("lambda"), Value::nil(), expr}),
               cons(sym("lambda"), cons(formals, body))});
}

// (let-values (((a b) expr) ...) body...) -> nested receives.
Value let_values_expand(Value x, SrcLoc loc) {
  if (list_length(x) < 3 || list_length(car(cdr(x))) < 0) ill_formed(x, loc);
  gcvec<Value> bs = list_to_vector(car(cdr(x)));
  Value body = cons(sym("let"), cons(Value::nil(), cdr(cdr(x))));
  for (size_t i = bs.size(); i-- > 0;) {
    if (list_length(bs[i]) != 2) ill_formed(x, loc);
    body = list({sym("receive"), car(bs[i]), car(cdr(bs[i])), body});
  }
  return body;
}

// ---- the analyzer proper ---------------------------------------------------

Node *Analyzer::analyze(Value x, SrcLoc loc, Scope *sc) {
  switch (x.tag) {
  case Tag::Symbol: return analyze_symbol(x, loc, sc);
  case Tag::Pair: return analyze_pair(x, loc, sc);
  case Tag::Nil: syntax_error(loc, "Combination must be a proper list: ()");
  default: return const_node(x, loc); // self-evaluating, including embedded procedures
  }
}

Node *Analyzer::variable_ref(Symbol *s, SrcLoc loc, Scope *sc) {
  uint16_t depth = 0;
  for (Scope *p = sc; p; p = p->parent, ++depth) {
    long i = p->index_of(s);
    if (i >= 0) {
      Node *n = new_node(NodeKind::LocalRef, loc);
      n->depth = depth;
      n->index = static_cast<uint32_t>(i);
      n->value = Value::object(Tag::Symbol, s);
      return n;
    }
  }
  Node *n = new_node(NodeKind::GlobalRef, loc);
  n->value = Value::object(Tag::Symbol, s);
  if (hook_) hook_(s, loc);
  return n;
}

Node *Analyzer::analyze_symbol(Value x, SrcLoc loc, Scope *sc) {
  int which;
  if (is_special(x, sc, which))
    syntax_error(loc, "Syntactic keyword may not be used as an expression: " + symbol_name(x));
  return variable_ref(x.symbol(), loc, sc);
}

Node *Analyzer::analyze_pair(Value x, SrcLoc loc, Scope *sc) {
  if (list_length(x) < 0)
    syntax_error(loc, "Combination must be a proper list: " + written(x));
  int which;
  if (is_special(car(x), sc, which)) return analyze_special(which, x, loc, sc);
  return analyze_call(x, loc, sc);
}

Node *Analyzer::analyze_call(Value x, SrcLoc loc, Scope *sc) {
  long n = list_length(x);
  Node *call = new_node(NodeKind::Call, loc, static_cast<uint32_t>(n));
  uint32_t i = 0;
  for (Value p = x; is_pair(p); p = cdr(p), ++i)
    call->kids[i] = analyze(car(p), loc_of(p, loc), sc);
  return call;
}

Node *Analyzer::analyze_sequence(Value forms, SrcLoc loc, Scope *sc) {
  long n = list_length(forms);
  if (n == 0) return const_node(Value::unspecified(), loc);
  if (n == 1) return analyze(car(forms), loc_of(forms, loc), sc);
  Node *seq = new_node(NodeKind::Seq, loc, static_cast<uint32_t>(n));
  uint32_t i = 0;
  for (Value p = forms; is_pair(p); p = cdr(p), ++i)
    seq->kids[i] = analyze(car(p), loc_of(p, loc), sc);
  return seq;
}

// Names defined by (define ...) forms of a body, including inside (begin ...).
void Analyzer::scan_defines(Value forms, std::vector<Symbol *> &out) {
  for (Value p = forms; is_pair(p); p = cdr(p)) {
    Value f = car(p);
    int which;
    if (!is_pair(f) || !is_special(car(f), nullptr, which)) continue;
    if (which == SF_BEGIN) {
      scan_defines(cdr(f), out);
    } else if ((which == SF_DEFINE || which == SF_DEFINE_INTEGRABLE) && is_pair(cdr(f))) {
      Value target = car(cdr(f));
      while (is_pair(target))
        target = car(target); // (define ((f a) b) ...)
      if (is_symbol(target) && std::find(out.begin(), out.end(), target.symbol()) == out.end())
        out.push_back(target.symbol());
    }
  }
}

// A body whose scope `sc` is fresh: its internal defines join sc's frame.
Node *Analyzer::analyze_body(Value forms, SrcLoc loc, Scope *sc) {
  if (is_null(forms)) syntax_error(loc, "Ill-formed special form: a body must not be empty");
  scan_defines(forms, sc->vars);
  return analyze_sequence(forms, loc, sc);
}

Node *Analyzer::analyze_lambda(Value params, Value body, SrcLoc loc, Scope *sc, Symbol *name,
                               Value form) {
  Lambda *lam = gc_new<Lambda>();
  lam->name = name;
  lam->loc = loc;
  Scope inner{{}, sc};
  enum { Required, Optional, Rest } mode = Required;
  Value p = params;
  for (; is_pair(p); p = cdr(p)) {
    Value v = car(p);
    if (is_symbol(v) && symbol_name(v) == "#!optional") {
      if (mode != Required) ill_formed(form, loc);
      mode = Optional;
      continue;
    }
    if (is_symbol(v) && symbol_name(v) == "#!rest") {
      if (mode == Rest || !is_pair(cdr(p)) || !is_null(cdr(cdr(p)))) ill_formed(form, loc);
      mode = Rest;
      continue;
    }
    if (!is_symbol(v)) ill_formed(form, loc);
    if (inner.index_of(v.symbol()) >= 0)
      syntax_error(loc_of(p, loc), "Ill-formed special form: parameter " + symbol_name(v) +
                                       " appears twice in " + written(form));
    inner.vars.push_back(v.symbol());
    if (mode == Required)
      ++lam->nrequired;
    else if (mode == Optional)
      ++lam->noptional;
    else
      lam->rest = true;
  }
  if (!is_null(p)) {
    if (!is_symbol(p) || mode == Rest) ill_formed(form, loc);
    if (inner.index_of(p.symbol()) >= 0) ill_formed(form, loc);
    inner.vars.push_back(p.symbol());
    lam->rest = true;
  }
  lam->body = analyze_body(body, loc, &inner);
  lam->frame_size = static_cast<uint32_t>(inner.vars.size());
  Node *n = new_node(NodeKind::Lambda, loc);
  n->lambda = lam;
  return n;
}

Node *Analyzer::analyze_define(Value x, SrcLoc loc, Scope *sc) {
  long n = list_length(x);
  if (n < 2) ill_formed(x, loc);
  Value target = car(cdr(x));
  Node *value;
  Symbol *name;
  if (is_pair(target)) {
    // (define (name . params) body...), curried when name is itself a list.
    Value head = car(target);
    Value params = cdr(target);
    Value body = cdr(cdr(x));
    if (is_null(body)) ill_formed(x, loc);
    while (is_pair(head)) {
      body = list({cons(sym("lambda"), cons(params, body))});
      params = cdr(head);
      head = car(head);
    }
    if (!is_symbol(head)) ill_formed(x, loc);
    name = head.symbol();
    value = analyze_lambda(params, body, loc, sc, name, x);
  } else {
    if (!is_symbol(target) || n > 3) ill_formed(x, loc);
    name = target.symbol();
    if (n == 2) {
      value = const_node(Value(), loc);
      value->value.tag = Tag::Unassigned;
    } else {
      Value expr = car(cdr(cdr(x)));
      SrcLoc eloc = loc_of(cdr(cdr(x)), loc);
      // (define f (lambda ...)) names the procedure f, as MIT does.
      int which;
      if (is_pair(expr) && is_special(car(expr), sc, which) && which == SF_LAMBDA &&
          list_length(expr) >= 3)
        value = analyze_lambda(car(cdr(expr)), cdr(cdr(expr)), eloc, sc, name, expr);
      else
        value = analyze(expr, eloc, sc);
    }
  }
  if (sc) {
    long i = sc->index_of(name);
    if (i < 0)
      syntax_error(loc, "Ill-formed special form: definition of " + name->name +
                            " is not at the start of a body");
    Node *set = new_node(NodeKind::SetLocal, loc, 1);
    set->index = static_cast<uint32_t>(i);
    set->kids[0] = value;
    set->value = Value::object(Tag::Symbol, name);
    return set;
  }
  Node *def = new_node(NodeKind::DefineGlobal, loc, 1);
  def->value = Value::object(Tag::Symbol, name);
  def->kids[0] = value;
  return def;
}

Node *Analyzer::analyze_set(Value x, SrcLoc loc, Scope *sc) {
  long n = list_length(x);
  if (n != 3 && n != 2) ill_formed(x, loc);
  Value target = car(cdr(x));
  if (!is_symbol(target)) ill_formed(x, loc);
  Node *ref = variable_ref(target.symbol(), loc_of(cdr(x), loc), sc);
  Node *value = n == 3 ? analyze(car(cdr(cdr(x))), loc_of(cdr(cdr(x)), loc), sc)
                       : const_node(Value::unspecified(), loc);
  Node *set =
      new_node(ref->kind == NodeKind::LocalRef ? NodeKind::SetLocal : NodeKind::SetGlobal, loc, 1);
  set->depth = ref->depth;
  set->index = ref->index;
  set->value = ref->value;
  set->kids[0] = value;
  return set;
}

Node *Analyzer::analyze_let(Value x, SrcLoc loc, Scope *sc) {
  if (list_length(x) < 3) ill_formed(x, loc);
  Value second = car(cdr(x));
  if (is_symbol(second)) {
    // Named let: ((letrec ((name (lambda (vars...) body...))) name) inits...)
    Value bindings = car(cdr(cdr(x)));
    Value body = cdr(cdr(cdr(x)));
    if (list_length(bindings) < 0 || is_null(body)) ill_formed(x, loc);
    gcvec<Value> vars, inits;
    for (Value b = bindings; is_pair(b); b = cdr(b)) {
      Value bind = car(b);
      if (is_symbol(bind)) {
        vars.push_back(bind);
        inits.push_back(Value::unspecified());
        continue;
      }
      if (!is_pair(bind) || !is_symbol(car(bind)) || list_length(bind) > 2) ill_formed(x, loc);
      vars.push_back(car(bind));
      inits.push_back(is_null(cdr(bind)) ? Value::unspecified() : car(cdr(bind)));
    }
    Scope loop_scope{{second.symbol()}, sc};
    Node *lambda = analyze_lambda(list_from(vars.data(), vars.size()), body, loc, &loop_scope,
                                  second.symbol(), x);
    Node *letrec = new_node(NodeKind::Letrec, loc, 2);
    letrec->index = 1;
    letrec->kids[0] = lambda;
    Node *ref = new_node(NodeKind::LocalRef, loc);
    ref->value = second;
    letrec->kids[1] = ref;
    Node *call = new_node(NodeKind::Call, loc, static_cast<uint32_t>(inits.size() + 1));
    call->kids[0] = letrec;
    uint32_t i = 1;
    for (Value b = bindings; is_pair(b); b = cdr(b), ++i)
      call->kids[i] = analyze(inits[i - 1], loc_of(is_pair(car(b)) ? cdr(car(b)) : b, loc), sc);
    return call;
  }
  if (list_length(second) < 0) ill_formed(x, loc);
  Scope inner{{}, sc};
  gcvec<Node *> inits;
  for (Value b = second; is_pair(b); b = cdr(b)) {
    Value bind = car(b);
    Value var, init = Value::unspecified();
    SrcLoc iloc = loc_of(b, loc);
    if (is_symbol(bind)) {
      var = bind; // MIT: (let (x) ...) binds x unassigned
      init.tag = Tag::Unassigned;
    } else {
      long bn = list_length(bind);
      if (bn != 2 || !is_symbol(car(bind))) ill_formed(x, loc);
      var = car(bind);
      init = car(cdr(bind));
      iloc = loc_of(cdr(bind), iloc);
    }
    if (inner.index_of(var.symbol()) >= 0)
      syntax_error(iloc, "Ill-formed special form: " + symbol_name(var) + " is bound twice in " +
                             written(x));
    inner.vars.push_back(var.symbol());
    inits.push_back(init.is(Tag::Unassigned) ? const_node(init, iloc) : analyze(init, iloc, sc));
  }
  Node *body = analyze_body(cdr(cdr(x)), loc, &inner);
  Node *let = new_node(NodeKind::Let, loc, static_cast<uint32_t>(inits.size() + 1));
  for (size_t i = 0; i < inits.size(); ++i)
    let->kids[i] = inits[i];
  let->kids[inits.size()] = body;
  let->index = static_cast<uint32_t>(inner.vars.size());
  return let;
}

Node *Analyzer::analyze_letrec(Value x, SrcLoc loc, Scope *sc) {
  if (list_length(x) < 3 || list_length(car(cdr(x))) < 0) ill_formed(x, loc);
  Scope inner{{}, sc};
  Value bindings = car(cdr(x));
  for (Value b = bindings; is_pair(b); b = cdr(b)) {
    Value bind = car(b);
    if (list_length(bind) != 2 || !is_symbol(car(bind))) ill_formed(x, loc);
    inner.vars.push_back(car(bind).symbol());
  }
  size_t nb = inner.vars.size();
  gcvec<Node *> inits;
  for (Value b = bindings; is_pair(b); b = cdr(b)) {
    Value bind = car(b);
    Value init = car(cdr(bind));
    SrcLoc iloc = loc_of(cdr(bind), loc);
    int which;
    if (is_pair(init) && is_special(car(init), &inner, which) && which == SF_LAMBDA &&
        list_length(init) >= 3)
      inits.push_back(
          analyze_lambda(car(cdr(init)), cdr(cdr(init)), iloc, &inner, car(bind).symbol(), init));
    else
      inits.push_back(analyze(init, iloc, &inner));
  }
  Node *body = analyze_body(cdr(cdr(x)), loc, &inner);
  Node *letrec = new_node(NodeKind::Letrec, loc, static_cast<uint32_t>(nb + 1));
  for (size_t i = 0; i < nb; ++i)
    letrec->kids[i] = inits[i];
  letrec->kids[nb] = body;
  letrec->index = static_cast<uint32_t>(inner.vars.size());
  return letrec;
}

Node *Analyzer::analyze_fluid_let(Value x, SrcLoc loc, Scope *sc) {
  if (list_length(x) < 3 || list_length(car(cdr(x))) < 0) ill_formed(x, loc);
  gcvec<Value> bs = list_to_vector(car(cdr(x)));
  uint32_t n = static_cast<uint32_t>(bs.size());
  Node *fl = new_node(NodeKind::FluidLet, loc, 2 * n + 1);
  for (uint32_t i = 0; i < n; ++i) {
    if (list_length(bs[i]) != 2 || !is_symbol(car(bs[i]))) ill_formed(x, loc);
    fl->kids[i] = variable_ref(car(bs[i]).symbol(), loc, sc);
    fl->kids[n + i] = analyze(car(cdr(bs[i])), loc, sc);
  }
  fl->kids[2 * n] = analyze_sequence(cdr(cdr(x)), loc, sc);
  return fl;
}

Node *Analyzer::analyze_special(int which, Value x, SrcLoc loc, Scope *sc) {
  long n = list_length(x);
  Value args = cdr(x);
  switch (static_cast<Special>(which)) {
  case SF_QUOTE:
    if (n != 2) ill_formed(x, loc);
    return const_node(car(args), loc);
  case SF_QUASIQUOTE:
    if (n != 2) ill_formed(x, loc);
    return analyze(qq_expand(car(args), 1, loc), loc, sc);
  case SF_IF: {
    if (n < 3 || n > 4) ill_formed(x, loc);
    Node *node = new_node(NodeKind::If, loc, static_cast<uint32_t>(n - 1));
    uint32_t i = 0;
    for (Value p = args; is_pair(p); p = cdr(p), ++i)
      node->kids[i] = analyze(car(p), loc_of(p, loc), sc);
    return node;
  }
  case SF_DEFINE:
  case SF_DEFINE_INTEGRABLE: return analyze_define(x, loc, sc);
  case SF_SET: return analyze_set(x, loc, sc);
  case SF_LAMBDA:
    if (n < 3) ill_formed(x, loc);
    return analyze_lambda(car(args), cdr(args), loc, sc, nullptr, x);
  case SF_NAMED_LAMBDA:
    if (n < 3 || !is_pair(car(args)) || !is_symbol(car(car(args)))) ill_formed(x, loc);
    return analyze_lambda(cdr(car(args)), cdr(args), loc, sc, car(car(args)).symbol(), x);
  case SF_BEGIN:
    if (n == 1 && sc) return const_node(Value::unspecified(), loc);
    return analyze_sequence(args, loc, sc);
  case SF_LET: return analyze_let(x, loc, sc);
  case SF_LET_STAR: return analyze(let_star_expand(x, loc), loc, sc);
  case SF_LETREC:
  case SF_LETREC_STAR: return analyze_letrec(x, loc, sc);
  case SF_COND: return analyze(cond_expand(args, x, loc), loc, sc);
  case SF_CASE: return analyze(case_expand(x, loc), loc, sc);
  case SF_AND:
  case SF_OR: {
    if (n == 1) return const_node(Value::boolean(which == SF_AND), loc);
    if (n == 2) return analyze(car(args), loc_of(args, loc), sc);
    Node *node =
        new_node(which == SF_AND ? NodeKind::And : NodeKind::Or, loc, static_cast<uint32_t>(n - 1));
    uint32_t i = 0;
    for (Value p = args; is_pair(p); p = cdr(p), ++i)
      node->kids[i] = analyze(car(p), loc_of(p, loc), sc);
    return node;
  }
  case SF_WHEN:
  case SF_UNLESS: {
    if (n < 3) ill_formed(x, loc);
    Value body = cons(sym("begin"), cdr(args), loc_of(cdr(args), loc));
    Value test = car(args);
    Value form = which == SF_WHEN ? list({sym("if"), test, body})
                                  : list({sym("if"), test, Value::unspecified(), body});
    return analyze(form, loc, sc);
  }
  case SF_DO: return analyze(do_expand(x, loc), loc, sc);
  case SF_DELAY: {
    if (n != 2) ill_formed(x, loc);
    Node *d = new_node(NodeKind::Delay, loc, 1);
    d->kids[0] = analyze(car(args), loc_of(args, loc), sc);
    return d;
  }
  case SF_MAKE_STREAM: {
    if (n != 3) ill_formed(x, loc);
    Node *call = new_node(NodeKind::Call, loc, 3);
    call->kids[0] = const_node(builtin("cons"), loc);
    call->kids[1] = analyze(car(args), loc_of(args, loc), sc);
    Node *d = new_node(NodeKind::Delay, loc, 1);
    d->kids[0] = analyze(car(cdr(args)), loc_of(cdr(args), loc), sc);
    call->kids[2] = d;
    return call;
  }
  case SF_FLUID_LET: return analyze_fluid_let(x, loc, sc);
  case SF_RECEIVE: return analyze(receive_expand(x, loc), loc, sc);
  case SF_LET_VALUES:
  case SF_LET_STAR_VALUES: return analyze(let_values_expand(x, loc), loc, sc);
  case SF_DECLARE: return const_node(Value::unspecified(), loc);
  case SF_ASSERT_SYNTAX_UNUSED:
  case SF_COUNT: break;
  }
  internal_failure(__FILE__, __LINE__, "unknown special form");
}

} // namespace

void install_special_forms() {
  for (int i = 0; kSpecialNames[i]; ++i)
    intern(kSpecialNames[i]).symbol()->special_form = i;
}

bool is_definition(Value datum) {
  int which;
  return is_pair(datum) && is_special(car(datum), nullptr, which) &&
         (which == SF_DEFINE || which == SF_DEFINE_INTEGRABLE);
}

void toplevel_defined_names(Value datum, std::vector<Symbol *> &out) {
  int which;
  if (!is_pair(datum) || !is_special(car(datum), nullptr, which)) return;
  if (which == SF_BEGIN) {
    for (Value p = cdr(datum); is_pair(p); p = cdr(p))
      toplevel_defined_names(car(p), out);
  } else if ((which == SF_DEFINE || which == SF_DEFINE_INTEGRABLE) && is_pair(cdr(datum))) {
    Value target = car(cdr(datum));
    while (is_pair(target))
      target = car(target);
    if (is_symbol(target)) out.push_back(target.symbol());
  }
}

Node *analyze_form(Value datum, SrcLoc loc, GlobalRefHook hook) {
  Analyzer a(hook);
  return a.analyze(datum, loc, nullptr);
}

Node *analyze_toplevel(Value datum, SrcLoc loc) {
  return analyze_form(datum, loc, nullptr);
}

} // namespace sicm
