// The reader: source text -> data (Values), each with its source position.
//
// Lexical syntax is the book's (MIT Scheme's): integers, exact rationals
// (1/2, -5/128), decimals (.5, 1., 1e-13), strings with escapes, characters
// (#\a #\space #\newline #\x41), booleans (#t #f #true #false), symbols
// (->local, Lagrangian->state-derivative, :pi, p_x, v^0, 1+), quote ('),
// quasiquote (`), unquote (,) and unquote-splicing (,@), vectors #( ... ),
// #!optional #!rest #!default #!eof #!unspecific, dotted pairs, and comments:
// ; to end of line, #| nested block |#, and #; datum.
// Symbols are case-sensitive, as in MIT Scheme 9+.
//
// Positions: every pair records where its car starts (Pair::loc); the
// position of a whole top-level datum is returned beside it. So the position
// of any sub-form is known: the position of the pair holding it.
#pragma once

#include <string_view>
#include <vector>

#include "base/error.hpp"
#include "base/value.hpp"

namespace sicm {

struct ReadForm {
  Value datum;
  SrcLoc loc;
};

class Reader {
public:
  // Reads the registered source `file` (see register_source).
  explicit Reader(uint32_t file);
  // Read the next datum. Returns false at end of input. Throws a Syntax
  // Error (with the position of the problem) on malformed input.
  bool next(ReadForm &out);

private:
  Value read_datum(SrcLoc &loc);
  Value read_list(char close, SrcLoc open);
  Value read_hash(SrcLoc start);
  Value read_string(SrcLoc start);
  Value read_atom(SrcLoc start);
  void skip_atmosphere(); // white space and comments
  void skip_block_comment(SrcLoc start);
  int peek() const;
  int get();
  SrcLoc here() const;

  uint32_t file_;
  std::string_view text_;
  size_t pos_ = 0;
  uint32_t line_ = 1, col_ = 1;
  int depth_ = 0; // nesting, bounded to keep the reader's own stack safe
};

// Read every datum of a registered source. Throws on the first error.
gcvec<ReadForm> read_all(uint32_t file);

// Whether a symbol of this name must be written in bars (|a b|) to read back
// as itself: it is empty, holds a delimiter, a bar or a bracket, starts with
// #, or reads as a number or as the dot of a dotted list.
bool symbol_needs_bars(std::string_view name);

// Nesting deeper than this is a clear error rather than a stack overflow.
constexpr int kMaxReadDepth = 10000;

} // namespace sicm
