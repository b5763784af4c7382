// The protocol of `sicm repl --kernel`: how a Jupyter kernel (jupyter/
// sicm_kernel.py) talks to one sicm session over its stdin and stdout.
//
// Requests, on stdin: a header line "VERB LENGTH [NAME]" and then exactly
// LENGTH bytes of UTF-8 text (no terminator needed):
//   execute N [NAME]  the text is a cell: every form is read, then evaluated
//                     in order; NAME (no spaces; default <cell-K>, the K-th
//                     cell) is how errors name the cell: In[3]:2:5
//   complete N        the text is the start of a name: the bound names it begins
//
// Replies, on stdout: one JSON object per line, each with a "type":
//   {"type":"ready"}                                    once, at start
//   {"type":"stream","name":"stdout","text":T}          display, write, newline
//   {"type":"result","last":B,"data":{MIME:TEXT,...}}   a top-level value
//   {"type":"display","data":{"image/svg+xml":SVG}}     a plot closed meanwhile
//   {"type":"error","ename":E,"evalue":M,"line":L,"col":C,"traceback":[LINES]}
//   {"type":"matches","matches":[NAMES]}                the reply to complete
//   {"type":"done"}                                     the request is answered
// "data" of a result always has "text/plain" (the value as `sicm run`
// writes it) and, for an expression, a structure or a matrix, "text/latex"
// ($$TeX$$ from ->tex-string, with the dot notation of print/infix.hpp).
// "last" is true for the value of a cell's last form, which the kernel
// shows as the cell's result (Out[n]); the others are shown as displays.
// An error's traceback is the compiler-style report: "cell:L:C: error: M",
// the source line and a caret; line and col are 1-based within the cell
// (0 when unknown). After an error the cell's later forms are not run.
// Nothing else is written to stdout: the session's fd 1 is moved to its
// stderr, so that stray writes cannot break the framing.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace sicm {

struct JupyterRequest {
  std::string verb; // "execute", "complete"; "" at end of input
  std::string text;
  std::string name; // "" when the header gives none
};

// The next request on `in`; verb "" at end of input or on a malformed header.
JupyterRequest read_jupyter_request(std::FILE *in);

// s as a JSON string literal, quotes included (invalid UTF-8 is passed
// through; Python's json reads it with errors="replace" on its side).
std::string json_string(std::string_view s);
// A JSON array of strings.
std::string json_strings(const std::vector<std::string> &items);
// A JSON object of string members, in order.
std::string json_object(const std::vector<std::pair<std::string, std::string>> &members);

// Writes one reply line (a JSON object given as text) to `out` and flushes.
void write_jupyter_message(std::FILE *out, const std::string &json);

} // namespace sicm
