// States as kernels take and give them: numbers in nested up/down structures and vectors.
//
// The one walker of state shapes for `sicm run`'s kernels and `sicm build`'s
// residual program: a state's scalar leaves in order (depth first, left to
// right), the state rebuilt from leaves, and the leaves of a state's
// derivative, in which an exact 0 may stand for a zero of the shape it
// replaces (SICM's (up 1 0 0) for the derivative of (up t (up x y) (down
// px py))).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "base/value.hpp"

namespace sicm {

// The components of a container (structure or vector), or null.
Value *container_items(Value v, size_t *len);

// v's leaves (what is not a container), depth first.
void state_leaves(Value v, gcvec<Value> &out);
size_t state_dimension(Value v);

// How a program names each of v's leaves, in state_leaves' order: `root`
// for a leaf, else (ref root i j ...) (vectors too: ref reads them).
std::vector<std::string> state_leaf_paths(Value v, const std::string &root);

// A container shaped like `shape` (structures keep their orientation,
// vectors stay vectors) whose parts are part(item, leaves) of its items in
// order; a non-container takes the next leaf.
using PartFn = Value (*)(Value shape, const Value *&leaves);
Value state_like(Value shape, const Value *&leaves, PartFn part);

// `shape` with its leaves replaced by leaves[0 .. state_dimension(shape)).
Value state_from_leaves(Value shape, const gcvec<Value> &leaves);

// The leaves of d, a derivative of a state shaped like `shape`, where an
// exact 0 stands for a zero of the shape it replaces; each leaf must satisfy
// is_leaf. False when d is not so shaped.
bool derivative_leaves(Value d, Value shape, gcvec<Value> &out, bool (*is_leaf)(Value));

} // namespace sicm
