// Repeated recurrences of a Taylor function found as loops: the statements of one order that
// apply one recurrence to many coefficient arrays (the pair terms of an N-body problem), written
// as a loop over index tables instead of once per array.
//
// Requires: the statements of order k of a Taylor function (codegen/emit_taylor.cpp), one C
// statement each, in the order the emitter wrote them, and the names of its coefficient arrays.
// Every array but those filled before the k loop is written by the first statement that names
// it, and read only by later ones. Produces: a plan that keeps every array as a row of one
// pool, REAL pool[rows][K], and writes order k's statements as loops over groups of statements
// that differ only in their rows. Each statement still computes what it did, from the same
// coefficients, with the same operations in the same order, so the coefficients are the
// unrolled ones, bit for bit; only the order in which independent statements run changes.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

namespace sicm {

struct TaylorLoops {
  size_t rows = 0;    // the pool's rows, one per array; 0: no loops, the straight-line C
  std::string body;   // order k's statements, indented for the k loop
  std::string tables; // the static index tables the loops read, as declarations
  std::unordered_map<std::string, size_t> row_of; // array -> its row
  std::string pool;                               // the pool's C name
  bool scalar_array = false; // whether the body reads scalars as elements of an array of them

  bool empty() const { return rows == 0; }
  // text with each array name written as its pool row ("pool[12]").
  std::string in_pool(const std::string &text) const;
};

// The loops of statements when one recurrence repeats at least kMinLoopInstances times at one
// depth (see taylor_loops.cpp); else an empty plan. before_loop: the arrays that are filled
// before the k loop (constants spread into arrays), which no statement writes. scalars: the
// names of the constants the statements read; a loop whose members read different ones reads
// them from scalar_array, {scalars[0], scalars[1], ...}, which the caller declares when the
// plan says so.
TaylorLoops plan_taylor_loops(const std::vector<std::string> &statements,
                              const std::vector<std::string> &arrays,
                              const std::vector<std::string> &before_loop,
                              const std::vector<std::string> &scalars, const std::string &pool,
                              const std::string &scalar_array);

} // namespace sicm
