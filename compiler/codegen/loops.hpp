// Repeated structure in a schedule found as loops: a run of steps that computes one shape
// over many index tuples (the pair terms of an N-body problem), and sums that gather them.
//
// Requires: an unchecked Schedule (codegen/schedule.hpp) and a way to name each symbol as an
// element of an array (in[i], p[j]). Produces: a plan the C emitter (emit_c.cpp) prints as
// loops over static tables of indices, so that N bodies cost O(N^2) table entries but O(1)
// code. Every instance of a loop performs the very operations its unrolled steps would, in
// the same order, and a gather adds its terms in the order of the unrolled sum: the loops
// change the C's size, not one bit of what it computes, so the kernel interpreter
// (kernel_interpreter.cpp), which runs the unrolled schedule, agrees with them.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "codegen/schedule.hpp"

namespace sicm {

// Instance k's index of one leaf: base + stride * k, or column `of`'s index plus base, or
// table[k].
struct LoopColumn {
  enum Kind : uint8_t { Affine, Offset, Table } kind = Affine;
  long base = 0, stride = 0;
  int of = -1;
  std::vector<long> table;
};

// A leaf of the loop body that is not computed in the instance: an element of an array (a
// symbol's `array`, or an earlier block's values), or one scalar temporary for all instances.
struct LoopSlot {
  std::string array;   // "in", "p", ...; empty for a block's values or a scalar
  int block = -1;      // the block whose values array holds it
  int64_t scalar = -1; // the temporary every instance reads
  LoopColumn column;
};

// Steps [first, first + period * count): `count` instances of `period` Define steps.
struct LoopBlock {
  size_t first = 0, period = 0, count = 0;
  std::vector<LoopSlot> slots;
  std::unordered_map<uint32_t, int> leaf_slot;  // instance 0's leaf terms -> slots
  std::unordered_map<uint32_t, uint32_t> local; // instance 0's temp terms -> position
  std::vector<int> escape;                      // position -> index in the values array, or -1
  size_t nescape = 0;                           // values per instance kept after the loop
};

// Output steps [first, first + count): out_index + o = (sign) sum of values of `block`, the
// terms of output o being entries [start[o], start[o+1]) of `table` (e >= 0: + values[e];
// e < 0: - values[~e]; the first entry starts the sum).
struct LoopGather {
  size_t first = 0, count = 0;
  int block = -1;
  bool negate = false;
  std::vector<long> table, start;
};

struct LoopPlan {
  std::vector<LoopBlock> blocks;
  std::vector<LoopGather> gathers;
  // Temporaries kept in a block's values array: temp -> (block, element).
  std::unordered_map<uint32_t, std::pair<int, long>> home;
  bool empty() const { return blocks.empty(); }
};

// How a symbol is an array element: its array's name and index; false if it is not one.
using SymbolIndex = std::function<bool(Symbol *, std::string *array, long *index)>;

// The loops of s's repeated runs of at least kMinLoopInstances instances (see loops.cpp),
// and the gathers of outputs whose targets (targets[j], "NAME[index]") are consecutive.
LoopPlan plan_loops(const Schedule &s, const SymbolIndex &index_of,
                    const std::vector<std::string> &targets);

} // namespace sicm
