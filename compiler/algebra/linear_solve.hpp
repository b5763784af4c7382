// Linear solves as expression nodes: how a kernel divides by a matrix of run-time values.
//
// Printing a symbolic result wants a matrix inverted symbolically: that is
// what the book shows. A kernel does not: the symbolic inverse of an n x n
// matrix of expressions grows with n! (a 4-link pendulum chain's inverse
// mass matrix had tens of millions of terms), and its expanded determinant
// cancels in floating point. So while a procedure is traced into a kernel
// (a KernelTracing object lives on this thread), dividing by a square
// structure (of any nesting, flattened by structure_linear_map.cpp) or
// matrix whose entries are run-time values -- the mass matrix
// of Lagrangian->state-derivative, the velocity solve of a Legendre
// transform, (/ b M) in user code -- makes one node per component of the
// solution:
//
//   (solve k M00 M01 ... M(n-1)(n-1) b0 ... b(n-1))
//
// a Call whose head is the uninterned symbol returned by solve_head(): the
// k-th component of x with M x = b, M's entries row-major. The C emitter
// factors each distinct M once (LDL^T when M is symmetric node for node, LU
// with partial pivoting otherwise) and solves once per distinct b. Nothing
// else rewrites these nodes: to the simplifier they are opaque functions of
// their arguments.
//
// Still inverted symbolically, as before: matrices of numbers, 1 x 1 and
// diagonal matrices, and those of at most kMaxSymbolicSolve rows, whose
// closed form costs less than a factorization and keeps the small systems
// of the book computing exactly what they computed -- unless such a matrix
// is singular whatever the inputs, which the factorization reports when
// the kernel runs, with the time and the state.
#pragma once

#include <cstddef>
#include <optional>

#include "base/value.hpp"
#include "cas/expr.hpp"

namespace sicm {

// Square matrices up to this size are inverted symbolically even in kernels.
constexpr size_t kMaxSymbolicSolve = 2;

// While one of these lives, divisions by matrices of run-time values make
// solve nodes (see above). Nests.
class KernelTracing {
public:
  KernelTracing();
  ~KernelTracing();
  KernelTracing(const KernelTracing &) = delete;
  KernelTracing &operator=(const KernelTracing &) = delete;
};

// The head of every solve node a kernel factors.
ExprId solve_head();

// sicm build, outside kernels: a division by a matrix with run-time entries
// in top-level code (a Hamiltonian made by Lagrangian->Hamiltonian,
// evaluated on a final state) must compute what `sicm run`'s interpreter
// computes, to the last bit. Its components are solve nodes with this head
// instead, which the C emitter writes as a call of
// sicm_linalg_solve_as_interpreted (sicm/linalg.h): Gauss-Jordan with the
// interpreter's pivoting and order of operations. Build mode says which
// values are run-time values (run_time_value_test, base/primitive.hpp);
// without it (sicm run) there are none.
ExprId interpreted_solve_head();

// Is id a solve node (of either head)? Its dimension n, component k, and
// entries.
bool is_solve_node(ExprId id);
bool is_interpreted_solve(ExprId id);
size_t solve_dimension(ExprId id);
size_t solve_component(ExprId id);
ExprId solve_matrix_entry(ExprId id, size_t i, size_t j);
ExprId solve_rhs_entry(ExprId id, size_t i);

// M x = b for the n x n matrix M (row-major: M(i, j) = m[i n + j]) and the
// n values b, as solve nodes, when kernels are being traced (or sicm build
// computes with run-time values) and M is a matrix the kernel should factor
// at run time; nullopt when the caller should invert M as usual. Structures
// of any nesting divide through this, flattened (structure_linear_map.cpp).
std::optional<gcvec<Value>> traced_solve(size_t n, const gcvec<Value> &m, const Value *b);

// The same for (/ a m) with m a square matrix and a an up of scalars.
std::optional<Value> traced_matrix_solve(Value a, Value m);

} // namespace sicm
