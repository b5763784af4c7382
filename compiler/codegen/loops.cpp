// Repeated structure in a schedule found as loops (see loops.hpp).
//
// Approach, after heyoka's compact mode: the scheduler writes an N-body derivative as the
// same few steps once per pair (three differences and a distance, then the inverse cube and
// three force components) and each output as a sum of N - 1 of those components. A block is
// a run of `count` consecutive instances of `period` Define steps whose term trees have one
// shape once their leaves are abstracted: a symbol or a temporary computed outside the
// instance becomes a slot (numbered by first appearance, so that which leaves coincide is
// part of the shape), a temporary computed inside it its position. Each slot's indices over
// the instances are a column: affine in the instance number, a constant offset from an
// earlier column (y_i beside x_i), or a static table. Values an instance computes that
// later steps read are kept in one array per block; the rest stay locals of the loop body.
// A gather is a run of outputs, each a left-folded chain of + and - over one block's
// values, written as a loop over a table of signed element indices.
//
// Limits, named below: a block needs kMinLoopInstances instances and kMinLoopSteps steps, so
// that small kernels (a pendulum, a handful of bodies) keep their straight-line C, which
// the C compiler schedules best; periods up to kMaxPeriod steps are tried; the values
// arrays live on the stack, kMaxValuesBytes in all. What does not fit stays unrolled.
#include "codegen/loops.hpp"

#include <string>
#include <unordered_map>

namespace sicm {

namespace {

constexpr size_t kMinLoopInstances = 32;
constexpr size_t kMinLoopSteps = 128;
constexpr size_t kMaxPeriod = 8;
constexpr size_t kMaxValuesBytes = size_t(4) << 20;

// One leaf of an instance: an array element, or a temporary computed before the instance.
struct Leaf {
  std::string array; // a symbol's array; empty for a temporary
  long index = 0;    // the symbol's index, or the temporary
};

// An instance's shape as text, and its leaves in slot order.
struct Instance {
  std::string shape;
  std::vector<Leaf> leaves;
};

class Planner {
public:
  Planner(const Schedule &s, const SymbolIndex &index_of, const std::vector<std::string> &targets)
      : s_(s), index_of_(index_of), targets_(targets), def_(s.ntemps, -1), last_use_(s.ntemps, 0) {
    for (size_t i = 0; i < s.steps.size(); ++i) {
      const Step &step = s.steps[i];
      if (step.kind == StepKind::Define || step.kind == StepKind::SinCos ||
          step.kind == StepKind::Factor || step.kind == StepKind::Solve ||
          step.kind == StepKind::SolveInterpreted)
        def_[step.temp] = long(i);
      if (step.kind == StepKind::SinCos) def_[step.temp2] = long(i);
      if (step.kind == StepKind::Define || step.kind == StepKind::SinCos ||
          step.kind == StepKind::Output)
        note_uses(step.term, i);
      for (uint32_t t : step.terms)
        note_uses(t, i);
      if (step.kind == StepKind::Solve) last_use_[step.temp2] = i;
    }
  }

  LoopPlan plan() {
    for (size_t i = 0; i < s_.steps.size();) {
      size_t n = try_block(i);
      i += n ? n : 1;
    }
    if (!plan_.blocks.empty()) find_gathers();
    return std::move(plan_);
  }

private:
  void note_uses(uint32_t t, size_t step) {
    const Term &term = s_.terms[t];
    if (term.kind == TermKind::Temp || term.kind == TermKind::Element)
      last_use_[term.temp] = std::max(last_use_[term.temp], step);
    for (uint32_t a : term.args)
      note_uses(a, step);
  }

  // The shape and leaves of steps [first, first + period), false if a step is not a Define
  // or a term cannot be in a loop. Records instance 0's leaf terms in `block` when given.
  bool instance(size_t first, size_t period, Instance *out, LoopBlock *block) {
    std::unordered_map<Symbol *, int> symbols;
    std::unordered_map<uint32_t, int> temps;
    for (size_t q = 0; q < period; ++q) {
      const Step &step = s_.steps[first + q];
      if (step.kind != StepKind::Define) return false;
      out->shape += "D";
      if (!walk(step.term, first, symbols, temps, out, block)) return false;
      out->shape += ';';
    }
    return true;
  }

  bool walk(uint32_t t, size_t first, std::unordered_map<Symbol *, int> &symbols,
            std::unordered_map<uint32_t, int> &temps, Instance *out, LoopBlock *block) {
    const Term &term = s_.terms[t];
    std::string &shape = out->shape;
    switch (term.kind) {
    case TermKind::Literal: shape += "L" + term.text + ","; return true;
    case TermKind::Symbol: {
      auto it = symbols.find(term.symbol);
      int slot;
      if (it != symbols.end()) {
        slot = it->second;
      } else {
        Leaf leaf;
        if (!index_of_(term.symbol, &leaf.array, &leaf.index) || leaf.array.empty()) return false;
        slot = int(out->leaves.size());
        out->leaves.push_back(leaf);
        symbols[term.symbol] = slot;
      }
      shape += "S" + std::to_string(slot) + ",";
      if (block) block->leaf_slot[t] = slot;
      return true;
    }
    case TermKind::Temp: {
      long def = def_[term.temp];
      if (def >= long(first)) { // computed in this instance, by the step at its position
        shape += "T" + std::to_string(def - long(first)) + ",";
        if (block) block->local[t] = uint32_t(def - long(first));
        return true;
      }
      auto it = temps.find(term.temp);
      int slot;
      if (it != temps.end()) {
        slot = it->second;
      } else {
        slot = int(out->leaves.size());
        out->leaves.push_back(Leaf{"", long(term.temp)});
        temps[term.temp] = slot;
      }
      shape += "S" + std::to_string(slot) + ",";
      if (block) block->leaf_slot[t] = slot;
      return true;
    }
    case TermKind::Element:
    case TermKind::CheckedCall:
    case TermKind::CheckedQuotient: return false;
    case TermKind::Paren:
    case TermKind::Neg:
    case TermKind::Add:
    case TermKind::Sub:
    case TermKind::Mul:
    case TermKind::Div:
    case TermKind::Call:
      shape += std::to_string(int(term.kind)) + term.text + "(";
      for (uint32_t a : term.args)
        if (!walk(a, first, symbols, temps, out, block)) return false;
      shape += ")";
      return true;
    }
    return false;
  }

  // Where a temporary computed before a block lives: (block, element), or (-1, temp).
  std::pair<int, long> where(long temp) const {
    auto it = plan_.home.find(uint32_t(temp));
    return it == plan_.home.end() ? std::pair<int, long>(-1, temp) : it->second;
  }

  // Do instance m's leaves sit where instance 0's do (the same array, block or scalar)?
  bool compatible(const Instance &a, const Instance &b) const {
    for (size_t j = 0; j < a.leaves.size(); ++j) {
      const Leaf &x = a.leaves[j], &y = b.leaves[j];
      if (x.array != y.array) return false;
      if (!x.array.empty()) continue;
      auto wx = where(x.index), wy = where(y.index);
      if (wx.first != wy.first || (wx.first < 0 && wx.second != wy.second)) return false;
    }
    return true;
  }

  // The longest block starting at step i, entered in the plan; its number of steps, or 0.
  size_t try_block(size_t i) {
    size_t best_period = 0, best_count = 0;
    std::vector<Instance> best;
    for (size_t period = 1; period <= kMaxPeriod; ++period) {
      std::vector<Instance> run;
      for (size_t m = 0; i + (m + 1) * period <= s_.steps.size(); ++m) {
        Instance inst;
        if (!instance(i + m * period, period, &inst, nullptr)) break;
        if (m > 0 && (inst.shape != run[0].shape || !compatible(run[0], inst))) break;
        if (m == 0 && !first_leaves_outside(inst, i)) break;
        run.push_back(std::move(inst));
      }
      if (run.size() * period > best_count * best_period) {
        best_period = period;
        best_count = run.size();
        best = std::move(run);
      }
    }
    if (best_count < kMinLoopInstances || best_count * best_period < kMinLoopSteps) return 0;
    return enter_block(i, best_period, best);
  }

  // Instance 0's outside temporaries are computed before the block (not by an instance of
  // it, which a loop could not read before writing).
  bool first_leaves_outside(const Instance &inst, size_t first) const {
    for (const Leaf &leaf : inst.leaves)
      if (leaf.array.empty() && def_[leaf.index] >= long(first)) return false;
    return true;
  }

  static LoopColumn column(const std::vector<long> &v, const std::vector<std::vector<long>> &cols,
                           const std::vector<LoopSlot> &slots, const LoopSlot &self) {
    LoopColumn c;
    long stride = v.size() > 1 ? v[1] - v[0] : 0;
    bool affine = true;
    for (size_t k = 0; k < v.size() && affine; ++k)
      affine = v[k] == v[0] + stride * long(k);
    if (affine) {
      c.base = v[0];
      c.stride = stride;
      return c;
    }
    for (size_t j = 0; j < cols.size(); ++j) {
      if (slots[j].array != self.array || slots[j].block != self.block || slots[j].scalar >= 0)
        continue;
      if (slots[j].column.kind == LoopColumn::Offset) continue;
      long d = v[0] - cols[j][0];
      bool same = true;
      for (size_t k = 0; k < v.size() && same; ++k)
        same = v[k] - cols[j][k] == d;
      if (same) {
        c.kind = LoopColumn::Offset;
        c.of = int(j);
        c.base = d;
        return c;
      }
    }
    c.kind = LoopColumn::Table;
    c.table = v;
    return c;
  }

  size_t enter_block(size_t first, size_t period, const std::vector<Instance> &run) {
    LoopBlock b;
    b.first = first;
    b.period = period;
    b.count = run.size();
    Instance again;
    instance(first, period, &again, &b);
    // Which positions are read after their instance.
    b.escape.assign(period, -1);
    for (size_t m = 0; m < b.count; ++m) {
      size_t end = first + (m + 1) * period;
      for (size_t q = 0; q < period; ++q)
        if (b.escape[q] < 0 && last_use_[s_.steps[first + m * period + q].temp] >= end)
          b.escape[q] = int(b.nescape++);
    }
    if (b.nescape * b.count * sizeof(double) + values_bytes_ > kMaxValuesBytes) return 0;
    values_bytes_ += b.nescape * b.count * sizeof(double);
    std::vector<std::vector<long>> cols;
    for (size_t j = 0; j < run[0].leaves.size(); ++j) {
      LoopSlot slot;
      std::vector<long> v;
      const Leaf &l0 = run[0].leaves[j];
      slot.array = l0.array;
      if (l0.array.empty()) {
        auto w = where(l0.index);
        slot.block = w.first;
        if (w.first < 0) slot.scalar = w.second;
      }
      for (const Instance &inst : run) {
        const Leaf &l = inst.leaves[j];
        v.push_back(l.array.empty() ? where(l.index).second : l.index);
      }
      if (slot.scalar < 0) slot.column = column(v, cols, b.slots, slot);
      cols.push_back(std::move(v));
      b.slots.push_back(std::move(slot));
    }
    int id = int(plan_.blocks.size());
    for (size_t m = 0; m < b.count; ++m)
      for (size_t q = 0; q < period; ++q)
        if (b.escape[q] >= 0)
          plan_.home[s_.steps[first + m * period + q].temp] = {id,
                                                               long(m * b.nescape) + b.escape[q]};
    plan_.blocks.push_back(std::move(b));
    return period * run.size();
  }

  // Output o's target as (array, index), false unless it reads NAME[digits].
  bool target(uint32_t o, std::string *array, long *index) const {
    const std::string &t = targets_[o];
    size_t open = t.find('[');
    if (open == std::string::npos || t.back() != ']' || open + 2 > t.size() - 1) return false;
    for (size_t k = open + 1; k + 1 < t.size(); ++k)
      if (t[k] < '0' || t[k] > '9') return false;
    *array = t.substr(0, open);
    *index = std::stol(t.substr(open + 1));
    return true;
  }

  // Output step i as a chain over one block's values: appends its entries, sets block and
  // negate; false if it is not one.
  bool chain(const Step &step, int *block, bool *negate, std::vector<long> *entries) const {
    uint32_t t = step.term;
    *negate = s_.terms[t].kind == TermKind::Neg;
    if (*negate) t = s_.terms[t].args[0];
    std::vector<long> rev;
    auto element = [&](uint32_t leaf, long *e) {
      const Term &term = s_.terms[leaf];
      if (term.kind != TermKind::Temp) return false;
      auto w = where(term.temp);
      if (w.first < 0 || (*block >= 0 && w.first != *block)) return false;
      *block = w.first;
      *e = w.second;
      return true;
    };
    while (s_.terms[t].kind == TermKind::Add || s_.terms[t].kind == TermKind::Sub) {
      const Term &term = s_.terms[t];
      long e;
      if (!element(term.args[1], &e)) return false;
      rev.push_back(term.kind == TermKind::Add ? e : ~e);
      t = term.args[0];
    }
    long e;
    bool neg = s_.terms[t].kind == TermKind::Neg;
    if (!element(neg ? s_.terms[t].args[0] : t, &e)) return false;
    rev.push_back(neg ? ~e : e);
    entries->insert(entries->end(), rev.rbegin(), rev.rend());
    return true;
  }

  void find_gathers() {
    for (size_t i = 0; i < s_.steps.size();) {
      LoopGather g;
      g.first = i;
      std::string array0;
      long index0 = 0;
      for (size_t j = i; j < s_.steps.size(); ++j) {
        const Step &step = s_.steps[j];
        if (step.kind != StepKind::Output) break;
        std::string array;
        long index;
        if (!target(step.output, &array, &index)) break;
        if (g.count == 0) {
          array0 = array;
          index0 = index;
        } else if (array != array0 || index != index0 + long(g.count)) {
          break;
        }
        int block = g.block;
        bool negate;
        size_t before = g.table.size();
        if (!chain(step, &block, &negate, &g.table) || (g.count && negate != g.negate)) {
          g.table.resize(before);
          break;
        }
        g.block = block;
        g.negate = negate;
        g.start.push_back(long(before));
        ++g.count;
      }
      if (g.count >= 2 && g.table.size() >= kMinLoopSteps) {
        g.start.push_back(long(g.table.size()));
        i += g.count;
        plan_.gathers.push_back(std::move(g));
      } else {
        ++i;
      }
    }
  }

  const Schedule &s_;
  const SymbolIndex &index_of_;
  const std::vector<std::string> &targets_;
  std::vector<long> def_;        // temp -> the step that computes it
  std::vector<size_t> last_use_; // temp -> the last step that reads it
  size_t values_bytes_ = 0;
  LoopPlan plan_;
};

} // namespace

LoopPlan plan_loops(const Schedule &s, const SymbolIndex &index_of,
                    const std::vector<std::string> &targets) {
  return Planner(s, index_of, targets).plan();
}

} // namespace sicm
