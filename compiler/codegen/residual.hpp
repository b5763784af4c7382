// The residual program: what `sicm build` leaves for run time.
//
// The build runs the program in the ordinary evaluator with one difference:
// numerical primitives do not run. Each leaves a statement here and returns
// run-time values (dynamic values) of the right shape: fresh uninterned
// symbols registered as residual variables. Generic arithmetic on them builds
// expressions, exactly as on the book's literal symbols, so everything the
// program computes from a dynamic value is an expression over residual
// variables. What needs a number (a comparison, floor, max, printing) becomes
// a statement too. Everything else (all symbolic work, all values that do not
// depend on a numerical result) is done at compile time and appears in the
// residual program only as the text it prints.
//
// The program is a tree of functions. `main` is the top level; a procedure
// handed to a numerical primitive (an integrand, a system derivative, a
// monitor) is traced into a function of its own: its arguments are fresh
// variables, the statements it causes are recorded in its body, its result
// leaves become its outputs. A function may use variables of the functions
// that enclose it (an integrand inside an objective uses the objective's
// argument): those are captured and passed in p[] (see sicm/program.h).
//
// Requires: the evaluator running with the hooks of pe/build_mode.cpp
// installed. Produces: a ResidualProgram that residual_emit.cpp writes as C.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "base/srcloc.hpp"
#include "base/value.hpp"
#include "cas/expr.hpp"

namespace sicm {

enum class RType : uint8_t { Real, Integer, Boolean };

struct RVar {
  Symbol *sym;
  RType type;
  int id;       // C name "rID"
  int function; // the function whose body defines it
};

// A computation that is not an expression of ops.def.
enum class RCompute : uint8_t {
  Expr,     // a[0]
  Less,     // a[0] < a[1]
  LessEq,   // a[0] <= a[1]
  Equal,    // a[0] == a[1]
  Select,   // a[0] != 0 ? a[1] : a[2]
  Not,      // a[0] == 0
  Floor,    // floor(a[0])
  Round,    // round half to even
  Truncate, // trunc(a[0])
  Max,      // fmax(a[0], a[1]) (NaN-propagating like MIT's max)
  Min,
  RealTime,   // milliseconds since the epoch, read when the statement runs
  RunTime,    // processor seconds, read when the statement runs
  Param,      // the program's --param `text`, or a[0]
  ReadCell,   // the current value of cell `cell`
  ListLength, // the number of elements of list `list`
  ListRef,  // leaf `leaf` of list `list`'s element at a[0], which must lie in [a[1], a[2]) (`text`
            // names the caller)
  ListFold, // min, max, + or * (`leaf`: sicm_list_fold_op) of list `list`'s numbers at [a[0],
            // a[1]); `backward`
};

enum class RKind : uint8_t {
  Text,        // print `text`
  Let,         // var = compute(args)
  Print,       // print var (by its type)
  Frame,       // plot `plot` = frame(args[0..3]) named `text`, titled `title`, axis_labels,
               // options `plot_options`
  PlotPoint,   // plot-point plot args[0] args[1] [series]
  PlotLine,    // plot-line plot args[0..3] [series]
  PlotStyle,   // plot-series plot series: its marker size and connect in `plot_options`
  Clear,       // graphics-clear plot
  Close,       // graphics-close plot
  SetCell,     // cell `cell` = args[0]
  If,          // if (args[0] != 0) then_body else else_body
  Loop,        // loop variables outs = args; repeat then_body (which ends in Break or Continue)
  Continue,    // next iteration with loop variables outs = args
  Break,       // leave the loop with results = args
  Integral,    // outs[0] = integral of callee over [args[0], args[1]], tolerance number
  Minimize,    // outs[0..2] = Brent on callee over [args[0], args[1]], tolerance number
  Multimin,    // outs = Nelder-Mead of callee from args, tolerance number
  FindRoot,    // outs[0] = root of callee in [args[0], args[1]], tolerance number
  Bisect,      // outs[0] = root of callee between args[0], args[1] to args[2]; number n-break
  Advance,     // outs = state args advanced by args.back() (dt); callee the derivative
  Evolve,      // outs = final state from args[0..dim) with monitor; dt t_final at the end
  Crossings,   // list `list` = the states from args[0..dim) to args.back() (t_final) where the
               // function `monitor` of the state crosses 0 in `direction`, at most `count`
  ListNew,     // list `list` = the empty list
  ListPush,    // add args (an element's leaves) to list `list`
  ListConst,   // list `list` = the elements of the constant table `leaf`
  ParallelMap, // parallel-map: member i is function members[i] (or members[0] for all) applied
               // to args[i*w .. i*w+w) (w = args / count); its outputs are the next ones of
               // outs, member by member (sicm_parallel_map runs them on threads and ranks)
  Fail,        // the program fails here: `text` is the whole message for stderr (an error
               // the build met at the program's top level, which sicm run raises there);
               // empty `text`: the message printed since FailCapture
  FailCapture, // what prints from here on is the message of the Fail that follows (it
               // holds numbers computed at run time)
};

// A frame's options and a series' style, as the runtime takes them
// (sicm_program_plot_options, sicm_program_plot_style).
struct RPlotOptions {
  bool equal_aspect = false; // Frame
  int legend = 0;            // Frame: a sicm_plot_legend
  double marker_size = -1;   // Frame, PlotStyle: negative for the default
  bool connect = false;      // PlotStyle
};

// An event of an Advance or Evolve (on-crossing, stop-on-crossing): where
// function `event` of the state crosses 0 in `direction`, function `action`
// is called with the state there, or, when it is -1, the integration stops.
struct REvent {
  int event = -1;
  int direction = 0; // SICM_ODE_EVENT_UP, _DOWN or _BOTH
  int action = -1;
};

struct RStmt {
  explicit RStmt(RKind k) : kind(k) {}
  RKind kind;
  RCompute compute = RCompute::Expr;
  std::vector<ExprId> args;
  std::vector<int> outs;      // variable ids defined by the statement
  std::vector<int> results;   // Loop, Break: the loop's result variables
  int var = -1;               // Let, Print
  int plot = -1;              // plot statements: the plot's number
  int callee = -1;            // the function a numerical statement calls
  int monitor = -1;           // Evolve: the monitor function, or -1; Crossings: the event
  int direction = 0;          // Crossings: SICM_ODE_EVENT_UP, _DOWN or _BOTH
  int first_monitor = -1;     // Evolve: the monitor for the initial state as written (exact
                              // numbers), or -1: monitor
  std::vector<int> members;   // ParallelMap: the members' functions (one for all, or one each)
  std::vector<REvent> events; // Advance, Evolve: their events, in the order written
  int count = 0;              // ParallelMap: the number of members; Crossings: the most, 0: all
  int jacobian = -1;          // Advance, Evolve: (D sysder) for implicit methods
  int probe = -1;             // Advance, Evolve: what sysder divides by, or -1
  int cell = -1;              // SetCell, Let of ReadCell
  int list = -1;              // ListNew, ListPush, Let of ListLength, ListRef, ListFold
  int leaf = 0;               // Let of ListRef, ListFold; ListConst: the table
  bool backward = false;      // Let of ListFold
  bool as_list = false;       // Multimin: the start point is a list (not a vector), for messages
  double number = 0;          // a tolerance
  long max_steps = 0;         // Advance, Evolve: steps per output time, 0 for the runtime's default
  bool time_first = false, rate_one = false; // Advance, Evolve
  std::string method;                        // Advance, Evolve: the runtime's step type variable
  std::string text, title;
  std::vector<std::string> probe_texts;    // Advance, Evolve: the probe's outputs as text
  std::vector<std::string> axis_labels;    // Frame: x, then y (none, one or both)
  std::optional<std::string> series;       // PlotPoint, PlotLine, PlotStyle: none: unnamed
  RPlotOptions plot_options;               // Frame, PlotStyle
  SrcLoc loc;                              // the call, for run-time errors
  std::vector<RStmt> then_body, else_body; // If
};

struct RFunction {
  int id;
  int parent;              // the enclosing function (-1 for main)
  std::string name;        // the procedure's name, for comments
  std::vector<int> inputs; // variables bound to in[0..]
  std::vector<ExprId> outputs;
  std::vector<RStmt> body;
  SrcLoc loc;
  // A kernel as sicm run compiles one (a system derivative, its Jacobian or
  // singular factors: one DAG, no statements): its outputs are plain C, as
  // in the JIT's kernels, and a division by zero is the integrator's
  // non-finite derivative, reported with the time and state, in both modes.
  bool kernel = false;
};

// A global variable that a procedure run at run time assigns with set!: a C
// global (cellN) that every function reads where the program reads it.
struct RCell {
  Value *place;     // the global's value or the frame slot (frames are kept alive by the builder)
  std::string name; // for messages
  RType type;
};

// A list built at run time whose elements all have one shape: a C global
// (listN, a sicm_list of `width` doubles per element; see sicm/program.h).
// A list value at compile time is a range of positions in it (see
// pe/build_mode.cpp).
struct RList {
  int width;
  std::string name; // for comments
};

// A list known at compile time that a loop left for run time walks (a
// for-each over 1000 initial points): a C array tableN of its elements'
// leaves, `width` doubles per element, copied into a list by ListConst.
struct RTable {
  int width;
  std::vector<double> data;
};

struct ResidualProgram {
  // The call that made each division, root, logarithm and power of run-time
  // values (pe/build_mode.cpp): where the executable reports it failing, as
  // sicm run does, rather than at the statement that computes it.
  std::unordered_map<ExprId, SrcLoc> op_sites;
  std::vector<RFunction> functions; // [0] is main
  std::vector<RVar> vars;
  std::vector<RCell> cells;
  std::vector<RList> lists;
  std::vector<RTable> tables;
  int plots = 0;
  std::string source_name;             // the program's file name, for the executable's --help
  std::vector<std::string> parameters; // names declared by (parameter 'name default)
};

} // namespace sicm
