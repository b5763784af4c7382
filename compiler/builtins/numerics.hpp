// Numerical primitives of the interpreter: quadrature, minimization, root
// finding and ODE integration (definite-integral, minimize, nelder-mead,
// multidimensional-minimize, find-root, bisect, state-advancer, evolve), over
// the runtime's numerical modules (runtime/include/sicm/*.h).
#pragma once

namespace sicm {


} // namespace sicm
