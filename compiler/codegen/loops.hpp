// Repeated structure in a schedule found as loops: a run of steps that computes one shape
// over many index tuples (the pair terms of an N-body problem), and sums that gather them.
//
// Requires: an unchecked Schedule (codegen/schedule.hpp) and a way to name each symbol as an
// element of an array (in[i], p[j]). Produces: a plan the C emitter (emit_c.cpp) prints as
// loops over static tables of indices, or over the pairs i < j with none, so that N bodies
// cost O(1) code. Every instance of a loop performs the very operations its unrolled steps would,
// in the same order, and an output sum adds its terms in the order of the unrolled sum: the loops
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
// table[k]; in a block over the pairs i < j (LoopBlock::pairs), base + stride * i or
// base + stride * j.
struct LoopColumn {
  enum Kind : uint8_t { Affine, Offset, Table, PairFirst, PairSecond } kind = Affine;
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

// `count` instances of a body of Define steps: segment s contributes steps
// [first_s + m * period_s, first_s + (m + 1) * period_s) to instance m, the segments one after
// another in the schedule (a pair's distance, then its force), the body's positions numbered
// across them.
struct LoopBlock {
  std::vector<std::pair<size_t, size_t>> segments; // (first, period)
  size_t count = 0;
  std::vector<LoopSlot> slots;
  std::unordered_map<uint32_t, int> leaf_slot;  // instance 0's leaf terms -> slots
  std::unordered_map<uint32_t, uint32_t> local; // instance 0's temp terms -> position
  std::vector<int> escape;                      // position -> index in the values array, or -1
  size_t nescape = 0;                           // values per instance kept after the loop
  // When nonzero, instance k is the k-th pair (i, j), i < j < pairs, in the order
  // (0, 1), (0, 2), ..., (1, 2), ...: the loop is two nested loops and needs no tables.
  size_t pairs = 0;
  size_t positions() const {
    size_t n = 0;
    for (auto [first, period] : segments)
      n += period;
    return n;
  }
  size_t end() const { return segments.back().first + segments.back().second * count; }
};

// Output steps [first, first + count): array[index0 + o] = (-) the chain of + and - over the
// values of `block` that the unrolled output sums, accumulated as the loop makes them: each
// instance adds (or subtracts) its position `position`'s value to the output its column
// names. The outputs start as -0.0, which a first term replaces exactly, and each output's
// terms come in the loop's order (instance, then position), so the sums are the unrolled
// ones, bit for bit.
struct LoopScatter {
  size_t first = 0, count = 0;
  int block = -1;
  bool negate = false;
  std::string array;
  long index0 = 0;
  struct Term {
    uint32_t position = 0;
    bool minus = false;
    LoopColumn column; // o, per instance
  };
  std::vector<Term> terms;
};

struct LoopPlan {
  std::vector<LoopBlock> blocks;
  std::vector<LoopScatter> scatters;
  // Temporaries kept in a block's values array: temp -> (block, element).
  std::unordered_map<uint32_t, std::pair<int, long>> home;
  bool empty() const { return blocks.empty(); }
};

// How a symbol is an array element: its array's name and index; false if it is not one.
using SymbolIndex = std::function<bool(Symbol *, std::string *array, long *index)>;

// The loops of s's repeated runs of at least kMinLoopInstances instances (see loops.cpp),
// and the sums accumulated in them of outputs whose targets (targets[j], "NAME[index]")
// are consecutive.
LoopPlan plan_loops(const Schedule &s, const SymbolIndex &index_of,
                    const std::vector<std::string> &targets);

} // namespace sicm
