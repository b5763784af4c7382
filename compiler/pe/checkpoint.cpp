// The one checkpoint of sicm build's partial evaluator: how far the build had
// got when an attempt at residual code began, and going back there when the
// attempt fails.
//
// The partial evaluator often tries something and takes it back: a numerical
// primitive traced again once its procedures turned a global into a cell
// (with_retrace), a bisect or a Jacobian that cannot be traced
// (pe/numerics.cpp), a call tried as a C loop or evaluated tentatively
// (pe/loops.cpp), a kernel trace left by an exception. Each takes a
// Checkpoint where the attempt begins and calls restore() when it fails, so
// that every attempt forgets the same things:
//   - functions and variables made since (the program is append-only, so a
//     size is a mark), with their symbols' entries in var_ids and
//     parameter_values;
//   - lists and tables made since, unless a list cell now holds one of the
//     lists (a cell made meanwhile keeps its list: see below);
//   - statements added to the current function's body and to the current
//     block (an alternative's or a loop's, where kernel parameters are
//     defined);
//   - the list cells' variables, as they were.
// What it leaves alone, on purpose:
//   - cells, list cells and cell_initialized: a global that became a cell
//     stays one for the rest of the build (with_retrace traces again so that
//     it is read as one);
//   - the evaluator's variables: the scopes that evaluate an alternative or
//     a trial (pe/branches.cpp, pe/loops.cpp) log the assignments and undo
//     their own log, since the log belongs to their scope;
//   - the stacks of the build (open functions, blocks, loops, logs), which
//     the scopes that push them pop;
//   - effort counters (work, branch_evaluations): effort spent on a failed
//     attempt is spent, as the limits count it;
//   - dynamic_memo: it answers for expressions, and the symbols of forgotten
//     variables are uninterned, so no new expression meets them.
#include "pe/state.hpp"

namespace sicm::build {

Checkpoint::Checkpoint()
    : nfunctions_(g_build->program.functions.size()), nvars_(g_build->program.vars.size()),
      nlists_(g_build->program.lists.size()), ntables_(g_build->program.tables.size()),
      function_(g_build->open.empty() ? -1 : g_build->open.back()),
      nbody_(function_ < 0 ? 0 : current().body.size()),
      block_(g_build->blocks.empty() ? nullptr : g_build->blocks.back()),
      nblock_(block_ ? block_->size() : 0) {
  for (Value *place : list_cell_places())
    list_places_.push_back(*place);
}

namespace {

void truncate(std::vector<RStmt> &block, size_t n) {
  if (block.size() > n) block.erase(block.begin() + static_cast<long>(n), block.end());
}

} // namespace

void Checkpoint::restore() const {
  ResidualProgram &p = g_build->program;
  if (p.vars.size() > nvars_) {
    for (size_t v = nvars_; v < p.vars.size(); ++v)
      g_build->var_ids.erase(p.vars[v].sym);
    // Keyed by the parameters' symbols, each a variable's.
    std::unordered_map<ExprId, ExprId> &values = g_build->parameter_values;
    for (auto it = values.begin(); it != values.end();)
      it = g_build->var_ids.count(expr_node(it->first).sym) ? std::next(it) : values.erase(it);
  }
  p.functions.resize(nfunctions_);
  p.vars.resize(nvars_);
  p.tables.resize(ntables_);
  bool lists_in_use = false; // by a list cell started meanwhile
  for (const ListCell &c : g_build->list_cells)
    lists_in_use = lists_in_use || c.list >= static_cast<int>(nlists_);
  if (!lists_in_use) {
    p.lists.resize(nlists_);
    g_build->list_shapes.resize(nlists_);
    g_build->list_types.resize(nlists_);
  }
  if (function_ >= 0) truncate(p.functions[static_cast<size_t>(function_)].body, nbody_);
  if (block_) truncate(*block_, nblock_);
  std::vector<Value *> places = list_cell_places();
  for (size_t i = 0; i < list_places_.size() && i < places.size(); ++i)
    *places[i] = list_places_[i];
}

} // namespace sicm::build
