// Differential objects and their arithmetic: the chain rule, once per operation.
//
// Approach. Sums and products work on whole term lists (merge; pairwise
// products whose tag sets are disjoint). Every other operation f is applied
// by splitting its argument on its largest tag e, a = a0 + a1·e, and
// computing f(a) = f(a0) + f'(a0)·a1·e, where f(a0) and f'(a0) go back
// through generic arithmetic (a0 may still carry smaller tags, which is how
// higher derivatives arise). Splitting on the largest tag makes the result
// independent of the order in which nested derivatives introduced their tags.
#include "algebra/differential.hpp"

#include <algorithm>
#include <cstring>
#include <tuple>
#include <utility>
#include <vector>

#include "algebra/generic.hpp"
#include "algebra/structure.hpp"
#include "base/error.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

struct DTerm {
  const uint32_t *tags; // strictly increasing; GC atomic memory
  uint32_t ntags;
  Value coef;
};

struct Differential {
  DTerm *terms; // GC memory
  size_t n;
};

uint32_t g_next_tag = 1;

// The gradient groups (fresh_gradient_tags), as [first, last] tag ranges in
// increasing order (tags only grow). Kept for the life of the process: a
// differential can outlive the derivative that made it (inside a
// procedure's result), and a tag is never reused.
std::vector<std::pair<uint32_t, uint32_t>> g_groups;

// The index of the gradient group of a tag, or -1.
long group_of(uint32_t tag) {
  auto it = std::upper_bound(g_groups.begin(), g_groups.end(), std::make_pair(tag, UINT32_MAX));
  if (it == g_groups.begin()) return -1;
  --it;
  return tag <= it->second ? it - g_groups.begin() : -1;
}

void write_differential(std::string &out, const void *obj, bool display);
const OpaqueKind kDifferentialKind = {"differential", write_differential, nullptr};

Differential *as_diff(Value v) {
  return static_cast<Differential *>(v.as<Opaque>()->obj);
}

bool tags_less(const DTerm &a, const DTerm &b) {
  if (a.ntags != b.ntags) return a.ntags < b.ntags;
  return std::lexicographical_compare(a.tags, a.tags + a.ntags, b.tags, b.tags + b.ntags);
}

bool tags_equal(const DTerm &a, const DTerm &b) {
  return a.ntags == b.ntags && std::equal(a.tags, a.tags + a.ntags, b.tags);
}

bool has_tag(const DTerm &t, uint32_t tag) {
  return std::binary_search(t.tags, t.tags + t.ntags, tag);
}

const uint32_t *copy_tags(const uint32_t *tags, uint32_t n) {
  uint32_t *mem = static_cast<uint32_t *>(GC_MALLOC_ATOMIC(sizeof(uint32_t) * (n ? n : 1)));
  std::copy(tags, tags + n, mem);
  return mem;
}

// t with `tag` taken out of its tag set.
DTerm without_tag(const DTerm &t, uint32_t tag) {
  std::vector<uint32_t> tags;
  for (uint32_t k = 0; k < t.ntags; ++k)
    if (t.tags[k] != tag) tags.push_back(t.tags[k]);
  return DTerm{copy_tags(tags.data(), uint32_t(tags.size())), uint32_t(tags.size()), t.coef};
}

// The terms of any value: a differential's own, or one untagged term.
gcvec<DTerm> terms_of(Value v) {
  if (is_differential(v)) {
    Differential *d = as_diff(v);
    return gcvec<DTerm>(d->terms, d->terms + d->n);
  }
  return gcvec<DTerm>{DTerm{nullptr, 0, v}};
}

// Build a value from terms: sorts, merges equal tag sets, drops exact zeros,
// and collapses to a plain value when no infinitesimal is left.
Value from_terms(gcvec<DTerm> terms) {
  std::stable_sort(terms.begin(), terms.end(), tags_less);
  gcvec<DTerm> merged;
  for (const DTerm &t : terms) {
    if (!merged.empty() && tags_equal(merged.back(), t))
      merged.back().coef = g_add(merged.back().coef, t.coef);
    else
      merged.push_back(t);
  }
  gcvec<DTerm> kept;
  for (const DTerm &t : merged)
    if (!is_exact_zero(t.coef)) kept.push_back(t);
  if (kept.empty()) return Value::fixnum(0);
  if (kept.size() == 1 && kept[0].ntags == 0) return kept[0].coef;
  bool tagged = false;
  for (const DTerm &t : kept)
    tagged |= t.ntags > 0;
  if (!tagged) return kept[0].coef;
  Differential *d = gc_new<Differential>();
  d->n = kept.size();
  d->terms = static_cast<DTerm *>(GC_MALLOC(sizeof(DTerm) * d->n));
  std::copy(kept.begin(), kept.end(), d->terms);
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kDifferentialKind, d}));
}

Value diff_add(Value a, Value b, bool subtract) {
  gcvec<DTerm> terms = terms_of(a);
  for (DTerm t : terms_of(b)) {
    if (subtract) t.coef = g_neg(t.coef);
    terms.push_back(t);
  }
  return from_terms(std::move(terms));
}

// Do two tag sets hold tags of one gradient group (whose product is 0)?
bool share_a_group(const DTerm &x, const DTerm &y) {
  if (g_groups.empty()) return false;
  for (uint32_t i = 0; i < x.ntags; ++i) {
    long g = group_of(x.tags[i]);
    if (g < 0) continue;
    for (uint32_t j = 0; j < y.ntags; ++j)
      if (group_of(y.tags[j]) == g) return true;
  }
  return false;
}

Value diff_mul(Value a, Value b) {
  gcvec<DTerm> out;
  for (const DTerm &x : terms_of(a)) {
    for (const DTerm &y : terms_of(b)) {
      // e_t² = 0: terms sharing a tag vanish, and so do products of two
      // tags of one gradient group.
      std::vector<uint32_t> tags;
      std::set_union(x.tags, x.tags + x.ntags, y.tags, y.tags + y.ntags, std::back_inserter(tags));
      if (tags.size() != x.ntags + y.ntags || share_a_group(x, y)) continue;
      out.push_back(DTerm{copy_tags(tags.data(), uint32_t(tags.size())), uint32_t(tags.size()),
                          g_mul(x.coef, y.coef)});
    }
  }
  return from_terms(std::move(out));
}

// f'(x) for the unary operations that are not linear.
Value unary_derivative(UnaryOp op, Value x) {
  Value one = Value::fixnum(1);
  switch (op) {
  case UnaryOp::Invert: return g_neg(g_unary(UnaryOp::Invert, g_square(x)));
  case UnaryOp::Sqrt:
    return g_unary(UnaryOp::Invert, g_mul(Value::fixnum(2), g_unary(UnaryOp::Sqrt, x)));
  case UnaryOp::Exp: return g_unary(UnaryOp::Exp, x);
  case UnaryOp::Log: return g_unary(UnaryOp::Invert, x);
  case UnaryOp::Sin: return g_unary(UnaryOp::Cos, x);
  case UnaryOp::Cos: return g_neg(g_unary(UnaryOp::Sin, x));
  case UnaryOp::Tan: return g_unary(UnaryOp::Invert, g_square(g_unary(UnaryOp::Cos, x)));
  case UnaryOp::Asin:
    return g_unary(UnaryOp::Invert, g_unary(UnaryOp::Sqrt, g_sub(one, g_square(x))));
  case UnaryOp::Acos:
    return g_neg(g_unary(UnaryOp::Invert, g_unary(UnaryOp::Sqrt, g_sub(one, g_square(x)))));
  case UnaryOp::Atan: return g_unary(UnaryOp::Invert, g_add(one, g_square(x)));
  case UnaryOp::Abs:
  case UnaryOp::Magnitude: return g_div(x, g_unary(UnaryOp::Abs, x));
  case UnaryOp::Square: return g_mul(Value::fixnum(2), x);
  case UnaryOp::Cube: return g_mul(Value::fixnum(3), g_square(x));
  case UnaryOp::Neg:
  case UnaryOp::ZeroP: break;
  }
  internal_failure(__FILE__, __LINE__, "no derivative rule for a linear operation");
}

// v = finite + sum over the tags g of gradient group `group` of
// tangent_g e_g (no term of v carries two tags of one group).
void split_group(Value v, long group, Value *finite, std::vector<std::pair<uint32_t, Value>> &parts,
                 gcvec<Value> &keep) {
  // The tangent terms in one collected vector (a std::vector of gcvecs
  // would hide them from the collector), with the tag each belongs to.
  gcvec<DTerm> fin, tan;
  std::vector<uint32_t> tan_tag, order; // order: the tags, by first appearance
  for (const DTerm &t : terms_of(v)) {
    uint32_t tag = 0;
    for (uint32_t k = 0; k < t.ntags; ++k)
      if (group_of(t.tags[k]) == group) tag = t.tags[k];
    if (tag == 0) {
      fin.push_back(t);
      continue;
    }
    tan.push_back(without_tag(t, tag));
    tan_tag.push_back(tag);
    if (std::find(order.begin(), order.end(), tag) == order.end()) order.push_back(tag);
  }
  *finite = from_terms(std::move(fin));
  for (uint32_t tag : order) {
    gcvec<DTerm> terms;
    for (size_t i = 0; i < tan.size(); ++i)
      if (tan_tag[i] == tag) terms.push_back(tan[i]);
    keep.push_back(from_terms(std::move(terms)));
    parts.emplace_back(tag, keep.back());
  }
}

// f(x) for x whose largest tag is in a gradient group, from f(x0) and the
// slope f'(x0) (slope_of(x0)): f(x0) + sum_g f'(x0) x_g e_g. One evaluation
// of f and f' for the whole gradient, where splitting one tag at a time
// would evaluate them 2^k times for k tags.
template <typename F, typename Slope>
Value apply_on_group(Value x, long group, F f, Slope slope_of) {
  Value x0;
  std::vector<std::pair<uint32_t, Value>> parts;
  gcvec<Value> keep;
  split_group(x, group, &x0, parts, keep);
  Value fx0 = f(x0), slope = slope_of(x0);
  gcvec<DTerm> terms = terms_of(fx0);
  for (auto &[tag, xg] : parts)
    for (const DTerm &t : terms_of(times_infinitesimal(g_mul(slope, xg), tag)))
      terms.push_back(t);
  return from_terms(std::move(terms));
}

Value negate_terms(Value x) {
  gcvec<DTerm> terms = terms_of(x);
  for (DTerm &t : terms)
    t.coef = g_neg(t.coef);
  return from_terms(std::move(terms));
}

// scmutils' diff:abs: |x| is x or -x by the sign of x's finite part, and
// has no derivative where that part is 0. A finite part that is not a
// number (an expression, or a value sicm build knows only at run time) goes
// through the chain rule with the slope x/|x|, which is that sign wherever
// it is defined (scmutils refuses a literal number there).
bool abs_by_sign(Value x, Value *out) {
  Value f = differential_finite_part(x);
  if (!is_real(f)) return false;
  int sign = num_sign(f);
  if (sign == 0) runtime_error(current_call_loc(), "Derivative of abs undefined at zero");
  *out = sign < 0 ? negate_terms(x) : x;
  return true;
}

// scmutils' diff:zero?: every coefficient, the finite part's and the
// infinitesimals', is zero.
bool all_terms_zero(Value x) {
  for (const DTerm &t : terms_of(x))
    if (!g_zero_p(t.coef)) return false;
  return true;
}

Value diff_unary(UnaryOp op, Value x) {
  if (op == UnaryOp::Neg) return negate_terms(x);
  if (op == UnaryOp::ZeroP) return Value::boolean(all_terms_zero(x));
  if (Value by_sign; (op == UnaryOp::Abs || op == UnaryOp::Magnitude) && abs_by_sign(x, &by_sign))
    return by_sign;
  uint32_t e = max_differential_tag(x);
  if (long group = group_of(e); group >= 0)
    return apply_on_group(
        x, group, [&](Value x0) { return g_unary(op, x0); },
        [&](Value x0) { return unary_derivative(op, x0); });
  Value x0, x1;
  split_differential(x, e, &x0, &x1);
  Value fx0 = g_unary(op, x0);
  return g_add(fx0, times_infinitesimal(g_mul(unary_derivative(op, x0), x1), e));
}

Value diff_expt(Value base, Value exponent) {
  if (!is_differential(exponent)) {
    if (is_exact_zero(exponent)) return Value::fixnum(1);
    uint32_t e = max_differential_tag(base);
    if (long group = group_of(e); group >= 0)
      return apply_on_group(
          base, group, [&](Value b0) { return g_expt(b0, exponent); },
          [&](Value b0) { return g_mul(exponent, g_expt(b0, g_sub(exponent, Value::fixnum(1)))); });
    Value b0, b1;
    split_differential(base, e, &b0, &b1);
    Value n_minus_1 = g_sub(exponent, Value::fixnum(1));
    Value slope = g_mul(exponent, g_expt(b0, n_minus_1));
    return g_add(g_expt(b0, exponent), times_infinitesimal(g_mul(slope, b1), e));
  }
  // When the exponent varies: d(a^b) = a^b (db log a + b da / a), the value
  // kept as (expt a b), as scmutils keeps it (not exp(b log a)); a term
  // whose infinitesimal part is 0 is left out (log a of a negative base).
  uint32_t e = std::max(max_differential_tag(base), max_differential_tag(exponent));
  Value b0, b1, x0, x1;
  split_differential(base, e, &b0, &b1);
  split_differential(exponent, e, &x0, &x1);
  Value value = g_expt(b0, x0);
  Value rate = Value::fixnum(0);
  if (!is_exact_zero(x1)) rate = g_mul(x1, g_unary(UnaryOp::Log, b0));
  if (!is_exact_zero(b1)) rate = g_add(rate, g_div(g_mul(x0, b1), b0));
  return g_add(value, times_infinitesimal(g_mul(value, rate), e));
}

Value diff_atan2(Value y, Value x) {
  uint32_t e = std::max(max_differential_tag(y), max_differential_tag(x));
  if (long group = group_of(e); group >= 0) {
    // d atan2(y, x) = (x0 dy - y0 dx) / (x0^2 + y0^2), for every tag g.
    Value y0, x0;
    std::vector<std::pair<uint32_t, Value>> ys, xs;
    gcvec<Value> keep;
    split_group(y, group, &y0, ys, keep);
    split_group(x, group, &x0, xs, keep);
    Value r2 = g_add(g_square(x0), g_square(y0));
    gcvec<DTerm> terms = terms_of(g_binary(BinaryOp::Atan2, y0, x0));
    std::vector<uint32_t> tags;
    for (auto &p : ys)
      tags.push_back(p.first);
    for (auto &p : xs)
      if (std::find(tags.begin(), tags.end(), p.first) == tags.end()) tags.push_back(p.first);
    for (uint32_t g : tags) {
      Value dy = Value::fixnum(0), dx = Value::fixnum(0);
      for (auto &p : ys)
        if (p.first == g) dy = p.second;
      for (auto &p : xs)
        if (p.first == g) dx = p.second;
      Value slope = g_div(g_sub(g_mul(x0, dy), g_mul(y0, dx)), r2);
      for (const DTerm &t : terms_of(times_infinitesimal(slope, g)))
        terms.push_back(t);
    }
    return from_terms(std::move(terms));
  }
  Value y0, y1, x0, x1;
  split_differential(y, e, &y0, &y1);
  split_differential(x, e, &x0, &x1);
  Value slope = g_div(g_sub(g_mul(x0, y1), g_mul(y0, x1)), g_add(g_square(x0), g_square(y0)));
  return g_add(g_binary(BinaryOp::Atan2, y0, x0), times_infinitesimal(slope, e));
}

Value diff_binary(BinaryOp op, Value a, Value b) {
  if (!is_arithmetic(a)) arith_wrong_type(op, a, 1);
  if (!is_arithmetic(b)) arith_wrong_type(op, b, 2);
  switch (op) {
  case BinaryOp::Add: return diff_add(a, b, false);
  case BinaryOp::Sub: return diff_add(a, b, true);
  case BinaryOp::Mul: return diff_mul(a, b);
  case BinaryOp::Div: return diff_mul(a, g_unary(UnaryOp::Invert, b));
  case BinaryOp::Expt: return diff_expt(a, b);
  case BinaryOp::Atan2: return diff_atan2(a, b);
  case BinaryOp::Equal:
    // scmutils' diff:binary-comparator: = compares the finite parts.
    return Value::boolean(g_equal(differential_finite_part(a), differential_finite_part(b)));
  }
  internal_failure(__FILE__, __LINE__, "unknown binary operation");
}

void write_differential(std::string &out, const void *obj, bool display) {
  const Differential *d = static_cast<const Differential *>(obj);
  out += "[differential";
  for (size_t i = 0; i < d->n; ++i) {
    out += " (";
    for (uint32_t k = 0; k < d->terms[i].ntags; ++k) {
      if (k) out += ' ';
      out += std::to_string(d->terms[i].tags[k]);
    }
    out += ") ";
    print_value(out, d->terms[i].coef, display);
  }
  out += "]";
}

bool member(Value v) {
  return is_differential(v);
}

const ArithType kDifferentialArith = {"differential", 15, member, diff_unary, diff_binary};

// ---- tangents of procedures: hiding the tag ------------------------------------
//
// The tangent of a procedure-valued result P (D of a curried function) is a
// procedure T whose calls extract D's tag e from P's results. Calling T once
// more is one more derivative calculation, so e must be private to T: an
// argument may carry e from another calculation that reuses this T (f' in
// (f' (f' g)), the "amazing bug" of Manzyuk, Pearlmutter, Radul, Rush and
// Siskind, JFP 2019), and P, which closed over x + e, would confuse the two
// perturbations. So each call that could see e swaps it for a fresh tag e'
// in the arguments, extracts e from P's result and swaps back, e' becoming
// the caller's e again (as scmutils's hide-tag-in-procedure does). A tag of a
// gradient group is hidden with its whole group (a fresh group of the same
// size), since the group's tags multiply to 0 with each other only.
//
// A swap is applied to numbers and expressions (nothing to do), to
// differentials (tags renamed), to structures and matrices (by component),
// and to compound procedures, which may have closed over a perturbed value:
// they are wrapped so that their arguments and results are swapped too.
// Primitives, literal functions and the other applicable objects (operators,
// series, compiled kernels) close over no perturbation of a user's
// calculation and are left as they are; so are lists and vectors.

// The exchange of tags [a, a + n) with [b, b + n) (disjoint ranges).
struct TagSwap {
  uint32_t a, b, n;
};

uint32_t swap_tag(uint32_t t, TagSwap s) {
  if (t >= s.a && t - s.a < s.n) return t - s.a + s.b;
  if (t >= s.b && t - s.b < s.n) return t - s.b + s.a;
  return t;
}

// A closure or a procedure made in C++ (function_arith.cpp): what may close
// over a perturbed value.
bool is_compound_procedure(Value v) {
  if (v.is(Tag::Closure)) return true;
  return v.is(Tag::Opaque) && std::strcmp(v.as<Opaque>()->kind->name, "compound-procedure") == 0;
}

// Might a swap of tags [lo, hi] with fresh ones change v? (A compound
// procedure might: its closure cannot be searched.)
bool may_carry_tags(Value v, uint32_t lo, uint32_t hi) {
  if (is_differential(v)) {
    Differential *d = as_diff(v);
    for (size_t i = 0; i < d->n; ++i)
      for (uint32_t k = 0; k < d->terms[i].ntags; ++k)
        if (d->terms[i].tags[k] >= lo && d->terms[i].tags[k] <= hi) return true;
    return false;
  }
  if (is_structure(v)) {
    Structure *s = as_structure(v);
    for (size_t i = 0; i < s->len; ++i)
      if (may_carry_tags(s->items[i], lo, hi)) return true;
    return false;
  }
  if (is_matrix(v)) {
    Matrix *m = as_matrix(v);
    for (size_t i = 0; i < m->rows * m->cols; ++i)
      if (may_carry_tags(m->items[i], lo, hi)) return true;
    return false;
  }
  return is_compound_procedure(v);
}

Value swap_tags(Value v, TagSwap s);

// The procedure a = p under swap items = (a b n): arguments and result swapped.
Value call_swapped(NativeProc *self, Value *args, int nargs) {
  TagSwap s{static_cast<uint32_t>(self->items[0].i), static_cast<uint32_t>(self->items[1].i),
            static_cast<uint32_t>(self->items[2].i)};
  gcvec<Value> swapped(args, args + nargs);
  for (Value &x : swapped)
    x = swap_tags(x, s);
  return swap_tags(apply_procedure(self->a, swapped.data(), nargs), s);
}

// v with the tags of s exchanged.
Value swap_tags(Value v, TagSwap s) {
  if (is_differential(v)) {
    gcvec<DTerm> terms = terms_of(v);
    for (DTerm &t : terms) {
      std::vector<uint32_t> tags(t.tags, t.tags + t.ntags);
      for (uint32_t &tag : tags)
        tag = swap_tag(tag, s);
      std::sort(tags.begin(), tags.end());
      t.tags = copy_tags(tags.data(), t.ntags);
    }
    return from_terms(std::move(terms));
  }
  if (is_structure(v)) {
    Structure *st = as_structure(v);
    Value out = make_structure(st->up, st->len);
    for (size_t i = 0; i < st->len; ++i)
      as_structure(out)->items[i] = swap_tags(st->items[i], s);
    return out;
  }
  if (is_matrix(v)) {
    Matrix *m = as_matrix(v);
    Value out = make_matrix(m->rows, m->cols);
    for (size_t i = 0; i < m->rows * m->cols; ++i)
      as_matrix(out)->items[i] = swap_tags(m->items[i], s);
    return out;
  }
  if (is_compound_procedure(v)) {
    Value items[3] = {Value::fixnum(s.a), Value::fixnum(s.b), Value::fixnum(s.n)};
    return make_native_procedure(call_swapped, 0, v, Value::nil(), items, 3);
  }
  return v;
}

// The tangent procedure: a = P, op = D's tag e. See above.
Value call_tangent(NativeProc *self, Value *args, int nargs) {
  uint32_t e = static_cast<uint32_t>(self->op), lo = e, hi = e;
  if (long group = group_of(e); group >= 0) std::tie(lo, hi) = g_groups[group];
  bool hide = false;
  for (int i = 0; i < nargs && !hide; ++i)
    hide = may_carry_tags(args[i], lo, hi);
  if (!hide) return extract_tangent(apply_procedure(self->a, args, nargs), e);
  uint32_t n = hi - lo + 1;
  TagSwap s{lo, lo == hi ? fresh_differential_tag() : fresh_gradient_tags(n), n};
  gcvec<Value> swapped(args, args + nargs);
  for (Value &x : swapped)
    x = swap_tags(x, s);
  return swap_tags(extract_tangent(apply_procedure(self->a, swapped.data(), nargs), e), s);
}

} // namespace

bool is_differential(Value v) {
  return v.is(Tag::Opaque) && v.as<Opaque>()->kind == &kDifferentialKind;
}

uint32_t fresh_differential_tag() {
  return g_next_tag++;
}

uint32_t fresh_gradient_tags(uint32_t n) {
  SICM_ASSERT(n > 0);
  uint32_t first = g_next_tag;
  g_next_tag += n;
  g_groups.emplace_back(first, first + n - 1);
  return first;
}

Value times_infinitesimal(Value tangent, uint32_t tag) {
  gcvec<DTerm> terms = terms_of(tangent);
  // A term that carries a tag of tag's gradient group times e_tag is 0.
  long group = group_of(tag);
  if (group >= 0)
    terms.erase(std::remove_if(terms.begin(), terms.end(),
                               [&](const DTerm &t) {
                                 for (uint32_t k = 0; k < t.ntags; ++k)
                                   if (group_of(t.tags[k]) == group) return true;
                                 return false;
                               }),
                terms.end());
  for (DTerm &t : terms) {
    SICM_ASSERT(!has_tag(t, tag));
    std::vector<uint32_t> tags(t.tags, t.tags + t.ntags);
    tags.insert(std::upper_bound(tags.begin(), tags.end(), tag), tag);
    t.tags = copy_tags(tags.data(), uint32_t(tags.size()));
    t.ntags = uint32_t(tags.size());
  }
  return from_terms(std::move(terms));
}

Value add_infinitesimal(Value x, uint32_t tag) {
  return g_add(x, times_infinitesimal(Value::fixnum(1), tag));
}

uint32_t max_differential_tag(Value v) {
  if (is_differential(v)) {
    uint32_t m = 0;
    Differential *d = as_diff(v);
    for (size_t i = 0; i < d->n; ++i)
      if (d->terms[i].ntags) m = std::max(m, d->terms[i].tags[d->terms[i].ntags - 1]);
    return m;
  }
  if (is_structure(v)) {
    uint32_t m = 0;
    Structure *s = as_structure(v);
    for (size_t i = 0; i < s->len; ++i)
      m = std::max(m, max_differential_tag(s->items[i]));
    return m;
  }
  if (is_matrix(v)) {
    uint32_t m = 0;
    Matrix *mat = as_matrix(v);
    for (size_t i = 0; i < mat->rows * mat->cols; ++i)
      m = std::max(m, max_differential_tag(mat->items[i]));
    return m;
  }
  return 0;
}

void split_differential(Value v, uint32_t tag, Value *finite, Value *tangent) {
  if (is_structure(v)) {
    Structure *s = as_structure(v);
    Value f = make_structure(s->up, s->len), t = make_structure(s->up, s->len);
    for (size_t i = 0; i < s->len; ++i)
      split_differential(s->items[i], tag, &as_structure(f)->items[i], &as_structure(t)->items[i]);
    *finite = f;
    *tangent = t;
    return;
  }
  if (!is_differential(v)) {
    *finite = v;
    *tangent = Value::fixnum(0);
    return;
  }
  gcvec<DTerm> fin, tan;
  for (const DTerm &t : terms_of(v)) {
    if (!has_tag(t, tag)) {
      fin.push_back(t);
      continue;
    }
    tan.push_back(without_tag(t, tag));
  }
  *finite = from_terms(std::move(fin));
  *tangent = from_terms(std::move(tan));
}

Value extract_tangent(Value v, uint32_t tag) {
  if (is_structure(v)) {
    Structure *s = as_structure(v);
    Value out = make_structure(s->up, s->len);
    for (size_t i = 0; i < s->len; ++i)
      as_structure(out)->items[i] = extract_tangent(s->items[i], tag);
    return out;
  }
  if (is_matrix(v)) {
    Matrix *m = as_matrix(v);
    Value out = make_matrix(m->rows, m->cols);
    for (size_t i = 0; i < m->rows * m->cols; ++i)
      as_matrix(out)->items[i] = extract_tangent(m->items[i], tag);
    return out;
  }
  if (is_procedure(v))
    return make_native_procedure(call_tangent, static_cast<int>(tag), v, Value::unspecified());
  Value finite, tangent;
  split_differential(v, tag, &finite, &tangent);
  return tangent;
}

void split_by_tag(Value v, uint32_t tag, Value *finite,
                  std::vector<std::pair<uint32_t, Value>> &parts, gcvec<Value> &keep) {
  if (long group = group_of(tag); group >= 0) {
    split_group(v, group, finite, parts, keep);
    return;
  }
  Value tangent;
  split_differential(v, tag, finite, &tangent);
  keep.push_back(tangent);
  if (!is_exact_zero(tangent)) parts.emplace_back(tag, tangent);
}

Value differential_finite_part(Value v) {
  if (!is_differential(v)) return v;
  Differential *d = as_diff(v);
  return d->n > 0 && d->terms[0].ntags == 0 ? d->terms[0].coef : Value::fixnum(0);
}

Value with_finite_part(Value v, Value finite) {
  if (!is_differential(v)) return v;
  gcvec<DTerm> terms;
  terms.push_back(DTerm{nullptr, 0, finite});
  for (const DTerm &t : terms_of(v))
    if (t.ntags > 0) terms.push_back(t);
  return from_terms(std::move(terms));
}

Value combine_differential_terms(Value a, Value b, const std::function<Value(Value, Value)> &f) {
  gcvec<DTerm> ta = terms_of(a), tb = terms_of(b), out;
  Value zero = Value::fixnum(0);
  size_t i = 0, j = 0;
  // Both lists are sorted by tag set (from_terms): walk them as a merge.
  while (i < ta.size() || j < tb.size()) {
    if (j == tb.size() || (i < ta.size() && tags_less(ta[i], tb[j]))) {
      out.push_back(DTerm{ta[i].tags, ta[i].ntags, f(ta[i].coef, zero)});
      ++i;
    } else if (i == ta.size() || tags_less(tb[j], ta[i])) {
      out.push_back(DTerm{tb[j].tags, tb[j].ntags, f(zero, tb[j].coef)});
      ++j;
    } else {
      out.push_back(DTerm{ta[i].tags, ta[i].ntags, f(ta[i].coef, tb[j].coef)});
      ++i, ++j;
    }
  }
  return from_terms(std::move(out));
}

void register_differential_arith() {
  register_arith_type(&kDifferentialArith);
}

} // namespace sicm
