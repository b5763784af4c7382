// Differential objects: forward-mode automatic differentiation with tagged
// infinitesimals, as in scmutils.
//
// A differential is a finite sum of terms c·e_{t1}·e_{t2}···, each an
// ordinary value c (number, expression, structure component) times a product
// of distinct infinitesimals e_t (with e_t² = 0), identified by integer tags.
// D makes a fresh tag for each derivative it takes, so derivatives nested
// inside derivatives never confuse their infinitesimals (the "perturbation
// confusion" of naive dual numbers): only terms carrying D's own tag are
// extracted.
//
// Invariants (checked by make_differential in debug builds):
//   - terms are sorted by tag set (shorter first, then lexicographically);
//   - tag sets are strictly increasing lists and no two terms share one;
//   - no coefficient is an exact zero;
//   - at least one term has a non-empty tag set (otherwise the value is just
//     the coefficient of the empty set, and no differential is made).
#pragma once

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "base/value.hpp"

namespace sicm {

bool is_differential(Value v);
// A fresh infinitesimal tag (never reused).
uint32_t fresh_differential_tag();
// n fresh tags first, first + 1, ..., first + n - 1 (returns first) that
// form one gradient: the product of any two of them is 0, not only of a tag
// with itself. Perturbing every component of a structure by a tag of one
// group gives all the partial derivatives in one evaluation, with no cross
// terms e_i e_j to carry; operations on a differential whose largest tag is
// in a group split off the whole group at once (one f and one f' for the
// gradient).
uint32_t fresh_gradient_tags(uint32_t n);
// x + e_tag.
Value add_infinitesimal(Value x, uint32_t tag);
// The coefficient of e_tag in v: terms of v carrying the tag, with the tag
// removed. Maps over structures and matrices, and over procedure results: a
// procedure-valued v gives a procedure that extracts the tag from v's
// results, with the tag private to each of its calls (an argument carrying
// e_tag from another calculation is not confused with v's own; see "hiding
// the tag" in differential.cpp). Values without the tag give 0.
Value extract_tangent(Value v, uint32_t tag);
// The largest tag in v (searching structures and matrices), or 0 if none.
uint32_t max_differential_tag(Value v);
// v with every term carrying `tag` dropped (the finite part in that tag),
// and the coefficient of the tag, so that v = finite + tangent·e_tag.
void split_differential(Value v, uint32_t tag, Value *finite, Value *tangent);
// tangent·e_tag (the tangent must not carry the tag).
Value times_infinitesimal(Value tangent, uint32_t tag);
// v = finite + sum of tangent_g e_g over the (tag, tangent) pairs appended
// to parts, for g = tag or, if tag is in a gradient group, every tag of that
// group that v carries (tangents are kept alive in keep). For rules that
// need a derivative as a whole (a linear solve: d(M^-1 b) = M^-1 (db - dM
// M^-1 b)) rather than through generic arithmetic.
void split_by_tag(Value v, uint32_t tag, Value *finite,
                  std::vector<std::pair<uint32_t, Value>> &parts, gcvec<Value> &keep);

// The part of v that carries no infinitesimal: the coefficient of the empty
// tag set of a differential (0 if it has none), v itself otherwise. What
// scmutils' comparisons of differentials compare (its finite-part, taken
// down to the last tag).
Value differential_finite_part(Value v);
// v with its finite part replaced by `finite` (v itself if v is not a
// differential).
Value with_finite_part(Value v, Value finite);
// The value whose coefficient of each tag set is f(a's coefficient, b's
// coefficient), with 0 for a tag set one of them lacks: a choice between two
// differentials term by term (sicm build's selection of a run-time test's
// alternatives). a and b are differentials or ordinary values.
Value combine_differential_terms(Value a, Value b, const std::function<Value(Value, Value)> &f);

// Register the differential arithmetic type with generic arithmetic.
void register_differential_arith();

} // namespace sicm
