// Repeated structure in a schedule found as loops (see loops.hpp).
//
// Approach, after heyoka's compact mode: the scheduler writes an N-body derivative as the
// same few steps once per pair (three differences and a distance; later the inverse cube
// and three force components) and each output as a sum of N - 1 of those components. A
// block is a run of `count` consecutive instances of a few Define steps whose term trees
// have one shape once their leaves are abstracted: a symbol or a temporary computed outside
// the instance becomes a slot (numbered by first appearance, so that which leaves coincide
// is part of the shape), a temporary computed inside it its position. A run that follows a
// block with as many instances, each reading only its own instance's values of the block,
// joins it as a second segment of the same loop body (the distances and the forces of a
// pair in one iteration). Each slot's indices over the instances are a column: affine in
// the instance number, a constant offset from an earlier column (y_i beside x_i, or the
// output of body i beside its input), or a static table; when the instances are the pairs
// i < j of n bodies in order and each table is affine in i or in j, the loop is two nested
// loops over i and j and needs no table. Values an instance computes that
// later steps read are kept in one array per block; the rest stay locals of the loop body.
// Outputs that are each a chain of + and - over one block's values, with every output's
// terms in the loop's order, are accumulated by the loop (LoopScatter), as a hand-written
// N-body loop does, and their values then need no array.
//
// Limits, named below: a block needs kMinLoopInstances instances and kMinLoopSteps steps, so
// that small kernels (a pendulum, up to 16 bodies) keep their straight-line C, which the C
// compiler schedules best. Measured with bench/scale against the hand-written pair loop,
// straight-line derivatives ran at 1.01x (10 bodies, 45 pairs) and 1.10x (16, 120) where
// loops ran at 1.06-1.17x; at 20 bodies (190 pairs) straight-line was 1.20x and the loop
// 1.02x, at 32 bodies 1.52x against 1.07x. Runs of up to kMaxPeriod steps per instance are
// tried. The values arrays live on the stack, kMaxValuesBytes in all (the N-body loop needs
// none); a run that would need more stays unrolled.
#include "codegen/loops.hpp"

#include <algorithm>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace sicm {

namespace {

constexpr size_t kMinLoopInstances = 128;
constexpr size_t kMinLoopSteps = 128;
constexpr size_t kMaxPeriod = 8;
constexpr size_t kMaxValuesBytes = size_t(1) << 20;

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

using Segments = std::vector<std::pair<size_t, size_t>>;

// Where a block computes a temporary: block, instance, position.
struct Origin {
  int block;
  size_t instance;
  uint32_t position;
};

class Planner {
public:
  Planner(const Schedule &s, const SymbolIndex &index_of, const std::vector<std::string> &targets)
      : s_(s), index_of_(index_of), targets_(targets), def_(s.ntemps, -1) {
    for (size_t i = 0; i < s.steps.size(); ++i) {
      const Step &step = s.steps[i];
      if (step.kind == StepKind::Define || step.kind == StepKind::SinCos ||
          step.kind == StepKind::Factor || step.kind == StepKind::Solve ||
          step.kind == StepKind::SolveInterpreted)
        def_[step.temp] = long(i);
      if (step.kind == StepKind::SinCos) def_[step.temp2] = long(i);
    }
  }

  // Blocks first; then the outputs they can accumulate; then the blocks again, now knowing
  // which values only those outputs read (they need no array).
  LoopPlan plan() {
    // A first plan finds the outputs the loops can accumulate (scatters). Its values arrays
    // are not bounded: it is not emitted, and the values the outputs read need no array
    // once they are accumulated (the force terms of 300 bodies, 1 MB of them, kept the
    // pair loop from being found at all when the first plan had to fit).
    find_uses({});
    values_limit_ = SIZE_MAX;
    find_blocks();
    if (plan_.blocks.empty()) return {};
    std::unordered_set<size_t> scattered = find_scatters();
    // The plan emitted: its values arrays within kMaxValuesBytes (the first one, when it
    // accumulates nothing and fits).
    if (scattered.empty() && values_bytes_ <= kMaxValuesBytes) return std::move(plan_);
    values_limit_ = kMaxValuesBytes;
    if (!scattered.empty()) {
      restart(scattered);
      if (find_scatters() == scattered) return std::move(plan_);
    }
    // Without accumulated outputs: every value they read is kept.
    restart({});
    find_scatters();
    return std::move(plan_);
  }

  // Blocks found again, the reads of steps `skip` not counted as uses.
  void restart(const std::unordered_set<size_t> &skip) {
    find_uses(skip);
    plan_ = {};
    origin_.clear();
    columns_.clear();
    values_bytes_ = 0;
    find_blocks();
  }

private:
  // last_use_[temp]: the last step, not one of `skip`, that reads temp.
  void find_uses(const std::unordered_set<size_t> &skip) {
    last_use_.assign(s_.ntemps, 0);
    for (size_t i = 0; i < s_.steps.size(); ++i) {
      if (skip.count(i)) continue;
      const Step &step = s_.steps[i];
      if (step.kind == StepKind::Define || step.kind == StepKind::SinCos ||
          step.kind == StepKind::Output)
        note_uses(step.term, i);
      for (uint32_t t : step.terms)
        note_uses(t, i);
      if (step.kind == StepKind::Solve) last_use_[step.temp2] = i;
      for (uint32_t f : step.flags)
        last_use_[f] = i;
    }
  }

  void note_uses(uint32_t t, size_t step) {
    const Term &term = s_.terms[t];
    if (term.kind == TermKind::Temp || term.kind == TermKind::Element)
      last_use_[term.temp] = std::max(last_use_[term.temp], step);
    for (uint32_t a : term.args)
      note_uses(a, step);
  }

  void find_blocks() {
    for (size_t i = 0; i < s_.steps.size();) {
      size_t end = try_block(i);
      i = end > i ? end : i + 1;
    }
  }

  // The position of the step computing temporary `def` in instance m of segs, or -1.
  static long position_of(long def, const Segments &segs, size_t m) {
    long base = 0;
    for (auto [first, period] : segs) {
      long lo = long(first + m * period);
      if (def >= lo && def < lo + long(period)) return base + def - lo;
      base += long(period);
    }
    return -1;
  }

  // The shape and leaves of instance m of segs, false if a step is not a Define or a term
  // cannot be in a loop. Records instance 0's leaf terms in `block` when given.
  bool instance(const Segments &segs, size_t m, Instance *out, LoopBlock *block) {
    std::unordered_map<Symbol *, int> symbols;
    std::unordered_map<uint32_t, int> temps;
    for (auto [first, period] : segs)
      for (size_t q = 0; q < period; ++q) {
        const Step &step = s_.steps[first + m * period + q];
        if (step.kind != StepKind::Define) return false;
        out->shape += "D";
        if (!walk(step.term, segs, m, symbols, temps, out, block)) return false;
        out->shape += ';';
      }
    return true;
  }

  bool walk(uint32_t t, const Segments &segs, size_t m, std::unordered_map<Symbol *, int> &symbols,
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
      long q = position_of(def_[term.temp], segs, m);
      if (q >= 0) { // computed in this instance
        shape += "T" + std::to_string(q) + ",";
        if (block) block->local[t] = uint32_t(q);
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
        if (!walk(a, segs, m, symbols, temps, out, block)) return false;
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

  // Does instance b read its leaves where instance a does (the same array, values array or
  // scalar), every temporary it reads computed before the block starts at `start`?
  bool compatible(const Instance &a, const Instance &b, size_t start) const {
    for (size_t j = 0; j < a.leaves.size(); ++j) {
      const Leaf &x = a.leaves[j], &y = b.leaves[j];
      if (x.array != y.array) return false;
      if (!x.array.empty()) continue;
      if (def_[y.index] >= long(start)) return false;
      auto wx = where(x.index), wy = where(y.index);
      if (wx.first != wy.first || (wx.first < 0 && wx.second != wy.second)) return false;
    }
    return true;
  }

  // The instances of segs, as many as have instance 0's shape (at most `limit`).
  std::vector<Instance> run(const Segments &segs, size_t limit) {
    std::vector<Instance> insts;
    for (size_t m = 0; m < limit; ++m) {
      bool fits = true;
      for (auto [first, period] : segs)
        fits = fits && first + (m + 1) * period <= s_.steps.size();
      Instance inst;
      if (!fits || !instance(segs, m, &inst, nullptr)) break;
      if (m > 0 && inst.shape != insts[0].shape) break;
      if (!compatible(m ? insts[0] : inst, inst, segs[0].first)) break;
      insts.push_back(std::move(inst));
    }
    return insts;
  }

  // The longest block starting at step i, with the segments that follow it, entered in the
  // plan if it fits; the step after it, or i if there is none.
  size_t try_block(size_t i) {
    Segments best;
    std::vector<Instance> insts;
    for (size_t period = 1; period <= kMaxPeriod; ++period) {
      std::vector<Instance> r = run({{i, period}}, s_.steps.size());
      if (r.size() * period > insts.size() * (best.empty() ? 0 : best[0].second)) {
        best = {{i, period}};
        insts = std::move(r);
      }
    }
    size_t count = insts.size();
    if (best.empty() || count < kMinLoopInstances || count * best[0].second < kMinLoopSteps)
      return i;
    for (bool grew = true; grew;) {
      grew = false;
      size_t next = best.back().first + best.back().second * count;
      for (size_t period = 1; period <= kMaxPeriod && !grew; ++period) {
        Segments segs = best;
        segs.push_back({next, period});
        std::vector<Instance> r = run(segs, count);
        if (r.size() == count) {
          best = std::move(segs);
          insts = std::move(r);
          grew = true;
        }
      }
    }
    // A run refused stays unrolled as a whole: trying it again from each of its steps would
    // cost its length squared.
    enter_block(best, insts);
    return best.back().first + best.back().second * count;
  }

  // The column of v (an index per instance), as an offset from one of `cols` (the block's
  // slots' columns so far) when it is one.
  static LoopColumn column(const std::vector<long> &v, const std::vector<std::vector<long>> &cols,
                           const std::vector<LoopSlot> &slots) {
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
      LoopColumn::Kind kind = slots[j].column.kind;
      if (slots[j].scalar >= 0 || kind == LoopColumn::Affine || kind == LoopColumn::Offset)
        continue;
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

  // Enters the block of these instances in the plan, false if its values arrays would not
  // fit under kMaxValuesBytes.
  bool enter_block(const Segments &segs, const std::vector<Instance> &insts) {
    LoopBlock b;
    b.segments = segs;
    b.count = insts.size();
    Instance again;
    instance(segs, 0, &again, &b);
    // Which positions later steps read, after the block.
    size_t end = b.end(), npos = b.positions();
    b.escape.assign(npos, -1);
    for (size_t m = 0; m < b.count; ++m)
      for (size_t q = 0; q < npos; ++q)
        if (b.escape[q] < 0 && last_use_[s_.steps[step_of(segs, m, q)].temp] >= end)
          b.escape[q] = int(b.nescape++);
    if (b.nescape * b.count * sizeof(double) + values_bytes_ > values_limit_) return false;
    values_bytes_ += b.nescape * b.count * sizeof(double);
    std::vector<std::vector<long>> cols;
    for (size_t j = 0; j < insts[0].leaves.size(); ++j) {
      LoopSlot slot;
      std::vector<long> v;
      const Leaf &l0 = insts[0].leaves[j];
      slot.array = l0.array;
      if (l0.array.empty()) {
        auto w = where(l0.index);
        slot.block = w.first;
        if (w.first < 0) slot.scalar = w.second;
      }
      for (const Instance &inst : insts) {
        const Leaf &l = inst.leaves[j];
        v.push_back(l.array.empty() ? where(l.index).second : l.index);
      }
      if (slot.scalar < 0) slot.column = column(v, cols, b.slots);
      cols.push_back(std::move(v));
      b.slots.push_back(std::move(slot));
    }
    int id = int(plan_.blocks.size());
    for (size_t m = 0; m < b.count; ++m)
      for (size_t q = 0; q < npos; ++q) {
        uint32_t temp = s_.steps[step_of(segs, m, q)].temp;
        origin_[temp] = {id, m, uint32_t(q)};
        if (b.escape[q] >= 0) plan_.home[temp] = {id, long(m * b.nescape) + b.escape[q]};
      }
    pair_columns(&b, cols);
    columns_.push_back(std::move(cols));
    plan_.blocks.push_back(std::move(b));
    return true;
  }

  // When the block's instances are the pairs i < j of some n in order and every table
  // column is an affine function of i or of j (a pair's bodies), makes them so: the C is
  // then two nested loops, O(1) in n, where the tables were O(n^2).
  static void pair_columns(LoopBlock *b, const std::vector<std::vector<long>> &cols) {
    size_t n = 2;
    while (n * (n - 1) / 2 < b->count)
      ++n;
    if (n * (n - 1) / 2 != b->count) return;
    std::vector<long> first, second;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = i + 1; j < n; ++j) {
        first.push_back(long(i));
        second.push_back(long(j));
      }
    auto fits = [](const std::vector<long> &v, const std::vector<long> &index, long *base,
                   long *stride) {
      // v[k] = base + stride * index[k], index[0] = 0 and index running to at least 1.
      *base = v[0];
      size_t one = 0;
      while (one < index.size() && index[one] == 0)
        ++one;
      if (one == index.size()) return false;
      *stride = (v[one] - *base) / index[one];
      for (size_t k = 0; k < v.size(); ++k)
        if (v[k] != *base + *stride * index[k]) return false;
      return true;
    };
    std::vector<LoopColumn> made(cols.size());
    bool any = false;
    for (size_t j = 0; j < cols.size(); ++j) {
      if (b->slots[j].scalar >= 0 || b->slots[j].column.kind != LoopColumn::Table) continue;
      LoopColumn &c = made[j];
      // second[k] starts at 1: fit j - 1.
      std::vector<long> second0(second.size());
      for (size_t k = 0; k < second.size(); ++k)
        second0[k] = second[k] - 1;
      if (fits(cols[j], first, &c.base, &c.stride)) {
        c.kind = LoopColumn::PairFirst;
      } else if (fits(cols[j], second0, &c.base, &c.stride)) {
        c.kind = LoopColumn::PairSecond;
        c.base -= c.stride; // base + stride * j
      } else {
        return;
      }
      any = true;
    }
    if (!any) return;
    for (size_t j = 0; j < cols.size(); ++j)
      if (made[j].kind == LoopColumn::PairFirst || made[j].kind == LoopColumn::PairSecond)
        b->slots[j].column = made[j];
    b->pairs = n;
  }

  static size_t step_of(const Segments &segs, size_t m, size_t q) {
    for (auto [first, period] : segs) {
      if (q < period) return first + m * period + q;
      q -= period;
    }
    return 0;
  }

  // Output o's target as (array, index), false unless it reads NAME[digits].
  bool target(uint32_t o, std::string *array, long *index) const {
    const std::string &t = targets_[o];
    size_t open = t.find('[');
    if (open == std::string::npos || open == 0 || t.back() != ']' || open + 2 >= t.size())
      return false;
    for (size_t k = open + 1; k + 1 < t.size(); ++k)
      if (t[k] < '0' || t[k] > '9') return false;
    *array = t.substr(0, open);
    *index = std::stol(t.substr(open + 1));
    return true;
  }

  // A term of an output's chain: the block's value it adds or subtracts.
  struct Piece {
    Origin origin;
    bool minus;
  };

  // Output step `step` as a chain of + and - over the values of one block (sets *block
  // when it is -1), its terms in the loop's order; false if it is not one.
  bool chain(const Step &step, int *block, bool *negate, std::vector<Piece> *pieces) const {
    uint32_t t = step.term;
    *negate = s_.terms[t].kind == TermKind::Neg;
    if (*negate) t = s_.terms[t].args[0];
    std::vector<Piece> rev;
    auto piece = [&](uint32_t leaf, bool minus) {
      const Term &term = s_.terms[leaf];
      if (term.kind != TermKind::Temp) return false;
      auto it = origin_.find(term.temp);
      if (it == origin_.end() || (*block >= 0 && it->second.block != *block)) return false;
      *block = it->second.block;
      rev.push_back({it->second, minus});
      return true;
    };
    while (s_.terms[t].kind == TermKind::Add || s_.terms[t].kind == TermKind::Sub) {
      const Term &term = s_.terms[t];
      if (!piece(term.args[1], term.kind == TermKind::Sub)) return false;
      t = term.args[0];
    }
    bool neg = s_.terms[t].kind == TermKind::Neg;
    if (!piece(neg ? s_.terms[t].args[0] : t, neg)) return false;
    for (size_t k = rev.size(); k-- > 1;) {
      const Origin &a = rev[k].origin, &b = rev[k - 1].origin;
      if (a.instance > b.instance || (a.instance == b.instance && a.position >= b.position))
        return false;
    }
    pieces->insert(pieces->end(), rev.rbegin(), rev.rend());
    return true;
  }

  // The runs of consecutive outputs the blocks can accumulate, entered in the plan; their
  // steps.
  std::unordered_set<size_t> find_scatters() {
    std::unordered_set<size_t> steps;
    for (size_t i = 0; i < s_.steps.size();) {
      LoopScatter sc;
      sc.first = i;
      // per output, its pieces
      std::vector<std::vector<Piece>> outs;
      for (size_t j = i; j < s_.steps.size(); ++j) {
        const Step &step = s_.steps[j];
        if (step.kind != StepKind::Output) break;
        std::string array;
        long index;
        if (!target(step.output, &array, &index)) break;
        if (sc.count == 0) {
          sc.array = array;
          sc.index0 = index;
        } else if (array != sc.array || index != sc.index0 + long(sc.count)) {
          break;
        }
        int block = sc.block;
        bool negate;
        std::vector<Piece> pieces;
        if (!chain(step, &block, &negate, &pieces) || (sc.count && negate != sc.negate)) break;
        sc.block = block;
        sc.negate = negate;
        outs.push_back(std::move(pieces));
        ++sc.count;
      }
      if (sc.count >= 2 && uniform_terms(outs, &sc)) {
        for (size_t j = i; j < i + sc.count; ++j)
          steps.insert(j);
        i += sc.count;
        plan_.scatters.push_back(std::move(sc));
      } else {
        ++i;
      }
    }
    return steps;
  }

  // Do the pieces of outs come, instance after instance, in one pattern: for each position
  // the same number of outputs, with the same signs? Fills sc's terms if so.
  bool uniform_terms(const std::vector<std::vector<Piece>> &outs, LoopScatter *sc) {
    const LoopBlock &b = plan_.blocks[size_t(sc->block)];
    size_t npos = b.positions();
    // by instance and position: (output, minus), in output order
    std::vector<std::vector<std::vector<std::pair<long, bool>>>> by(
        b.count, std::vector<std::vector<std::pair<long, bool>>>(npos));
    size_t total = 0;
    for (size_t o = 0; o < outs.size(); ++o)
      for (const Piece &p : outs[o]) {
        by[p.origin.instance][p.origin.position].push_back({long(o), p.minus});
        ++total;
      }
    if (total < kMinLoopSteps) return false;
    for (size_t q = 0; q < npos; ++q) {
      const auto &pattern = by[0][q];
      for (size_t r = 0; r < pattern.size(); ++r) {
        LoopScatter::Term term;
        term.position = uint32_t(q);
        term.minus = pattern[r].second;
        std::vector<long> v;
        for (size_t m = 0; m < b.count; ++m) {
          const auto &here = by[m][q];
          if (here.size() != pattern.size() || here[r].second != term.minus) return false;
          v.push_back(here[r].first + sc->index0);
        }
        term.column = column(v, columns_[size_t(sc->block)], b.slots);
        if (term.column.kind == LoopColumn::Affine || term.column.kind == LoopColumn::Offset) {
          term.column.base -= sc->index0;
        } else {
          for (long &x : term.column.table)
            x -= sc->index0;
        }
        sc->terms.push_back(std::move(term));
      }
      for (size_t m = 1; m < b.count; ++m)
        if (by[m][q].size() != pattern.size()) return false;
    }
    return true;
  }

  const Schedule &s_;
  const SymbolIndex &index_of_;
  const std::vector<std::string> &targets_;
  std::vector<long> def_;        // temp -> the step that computes it
  std::vector<size_t> last_use_; // temp -> the last step that reads it
  std::unordered_map<uint32_t, Origin> origin_;
  std::vector<std::vector<std::vector<long>>> columns_; // per block, its slots' indices
  size_t values_bytes_ = 0;
  size_t values_limit_ = kMaxValuesBytes; // on values_bytes_ (see plan)
  LoopPlan plan_;
};

} // namespace

LoopPlan plan_loops(const Schedule &s, const SymbolIndex &index_of,
                    const std::vector<std::string> &targets) {
  return Planner(s, index_of, targets).plan();
}

} // namespace sicm
