"""grammar: random small mechanics programs for the differential fuzz target.

A program is a mechanical system (a Lagrangian turned into a state derivative
by Lagrangian->state-derivative, or a hand-written state derivative) with
captured numbers, exact and inexact, and (parameter 'name value) values,
followed by a few actions on it: evolve with a monitor, state-advancer, the
minimizers, quadrature, root finders and plots, and arithmetic on their
results. Some programs end with a deliberately bad form, so that the two
modes' error messages and exit statuses are compared too.

Every choice is drawn from one random.Random, seeded by the caller, so the
same seed gives the same program. Each choice that selects a feature of the
language records the feature's name in Program.features; a run can exclude
features by name (the smoke test excludes those where the modes are known to
differ), and a finding names the features its program used.
"""

from __future__ import annotations

import dataclasses
import random


@dataclasses.dataclass
class Program:
    text: str
    features: set[str]


class Excluded(Exception):
    """A choice drew a feature the caller excluded; the caller draws again."""


# Numbers as a program writes them: MIT Scheme's flonum spellings, exact
# integers and rationals. The modes must read, capture and print them alike.
INEXACT_NUMBERS = [".37", "1.5", "2.", "-.25", ".1", "1e-1", "0.5", "3.", ".8", "1.25", "-1.5"]
EXACT_NUMBERS = ["2", "1/3", "3/2", "1", "-1/2", "5/4"]
POSITIVE_NUMBERS = [".37", "1.5", "2.", ".5", "1.", "2", "3/2", "1/3", "5/4", ".8"]

# Integrators of evolve and state-advancer (stdlib/doc/core.txt), with the
# tolerance each is given; the symplectic ones take a step size there and
# need a separable system.
INTEGRATORS = ["bulirsch-stoer", "qcrk4", "qcctrap2", "rk8pd", "rkf45", "rkck",
               "gear", "msbdf", "cvode-adams", "cvode-bdf", "taylor"]
SYMPLECTIC_INTEGRATORS = ["verlet", "yoshida4"]


@dataclasses.dataclass
class System:
    """A state derivative: how to name it in (evolve NAME ARGS ...), its
    initial state, and what is known of it."""
    definition: str          # the define forms
    sysder: str              # "Lagrangian->state-derivative (L 1. .37)" or "sysder .5 2"
    initial: str             # "(up 0. 1. 0.)"
    dimensions: int          # degrees of freedom: 1 or 2
    separable: bool          # T(v) + V(t, q): the symplectic integrators apply
    # sysder with its last captured number replaced by "{c}": the form a
    # parameter sweep advances for several values of c
    sweep_template: str = ""


class Generator:
    def __init__(self, rng: random.Random, excluded: set[str]):
        self.rng = rng
        self.excluded = excluded
        self.features: set[str] = set()
        self.globals_used = 0   # counter for unique global names
        self.frames = 0         # counter for unique plot names

    # --- features and choices ---------------------------------------------

    def feature(self, name: str) -> None:
        """Record that the program uses feature `name` (or refuse it)."""
        if name in self.excluded:
            raise Excluded(name)
        self.features.add(name)

    def allowed(self, name: str) -> bool:
        return name not in self.excluded

    def chance(self, p: float) -> bool:
        return self.rng.random() < p

    def pick(self, options):
        return self.rng.choice(options)

    def fresh(self, stem: str) -> str:
        self.globals_used += 1
        return f"{stem}{self.globals_used}"

    # --- numbers and expressions ------------------------------------------

    def number(self, positive: bool = False) -> str:
        if positive:
            n = self.pick(POSITIVE_NUMBERS)
        elif self.allowed("exact-number") and self.chance(0.3):
            n = self.pick(EXACT_NUMBERS)
        else:
            n = self.pick(INEXACT_NUMBERS)
        if "/" in n or "." not in n and "e" not in n:
            self.feature("exact-number")
        return n

    def state_number(self) -> str:
        """A component of an initial state: exact ones are a feature of
        their own, since a monitor sees the initial state as given."""
        if self.allowed("exact-initial-state") and self.chance(0.25):
            self.feature("exact-initial-state")
            return self.pick(EXACT_NUMBERS)
        return self.pick(INEXACT_NUMBERS)

    def expression(self, variables: list[str], depth: int, bounded: bool = False) -> str:
        """An expression in the variables. bounded: every value it takes stays
        within a fixed range whatever the variables (sin and cos at the top,
        denominators kept away from zero), so a force built on it cannot blow
        the motion up in the short times the programs integrate over."""
        if bounded:
            inner = self.expression(variables, depth - 1)
            f = self.pick(["sin", "cos"])
            return f"({f} {inner})" if not self.chance(0.3) else \
                f"(/ {inner} (+ 1 (square {inner})))"
        if depth <= 0 or self.chance(0.25):
            return self.pick(variables) if self.chance(0.7) else self.number()
        a = self.expression(variables, depth - 1)
        b = self.expression(variables, depth - 1)
        form = self.pick(["+", "-", "*", "/", "sin", "cos", "square", "expt", "neg"])
        if form in ("+", "-", "*"):
            return f"({form} {a} {b})"
        if form == "/":
            # Away from zero: 1 + b^2 >= 1.
            return f"(/ {a} (+ 1 (square {b})))"
        if form == "expt":
            self.feature("expt")
            return f"(expt {a} {self.pick(['2', '3'])})"
        if form == "neg":
            return f"(- {a})"
        return f"({form} {a})"

    # --- parameters ---------------------------------------------------------

    def parameters(self) -> tuple[str, list[str]]:
        """Zero to two (define NAME (parameter 'NAME default)) forms, and the
        names, which later choices may use where a number goes."""
        if not self.allowed("parameter") or not self.chance(0.5):
            return "", []
        self.feature("parameter")
        names = ["amp", "gain"][: self.pick([1, 2])]
        text = "".join(f"(define {n} (parameter '{n} {self.number(positive=True)}))\n"
                       for n in names)
        return text, names

    def coefficient(self, params: list[str], positive: bool = False) -> str:
        if params and self.chance(0.3):
            return self.pick(params)
        return self.number(positive)

    # --- systems --------------------------------------------------------------

    def system(self, params: list[str]) -> System:
        kind = self.pick(["lagrangian-1d", "lagrangian-1d", "lagrangian-2d", "sysder"])
        self.feature(kind)
        if kind == "lagrangian-1d":
            return self.lagrangian_1d(params)
        if kind == "lagrangian-2d":
            return self.lagrangian_2d(params)
        return self.hand_sysder(params)

    def lagrangian_1d(self, params: list[str]) -> System:
        # T = m v^2 / 2 (times 1 + c cos q when the mass depends on q, which
        # keeps it positive for |c| < 1); V = k q^2 / 2 plus c times a
        # bounded function of q (and of t: a driven system).
        driven = self.chance(0.3)
        variables = ["q", "t"] if driven else ["q"]
        if driven:
            self.feature("driven")
        coupling = self.expression(variables, 2, bounded=True)
        kinetic = "(* 1/2 m (square v))"
        separable = not driven
        if self.chance(0.25):
            self.feature("position-dependent-mass")
            kinetic = "(* 1/2 m (+ 1 (* .5 (cos q))) (square v))"
            separable = False
        if self.chance(0.15):
            # A term linear in v: a gauge term, which changes nothing physical
            # but goes through the Lagrange equations' derivatives.
            self.feature("velocity-term")
            kinetic = f"(+ {kinetic} (* c q v))"
            separable = False
        definition = (
            "(define ((L m k c) local)\n"
            "  (let ((t (time local)) (q (coordinate local)) (v (velocity local)))\n"
            f"    (- {kinetic}\n"
            f"       (+ (* 1/2 k (square q)) (* c {coupling})))))\n")
        m = self.coefficient(params, positive=True)
        k = self.coefficient(params, positive=True)
        c = self.coefficient(params)
        init = f"(up 0. {self.state_number()} {self.state_number()})"
        return System(definition, f"Lagrangian->state-derivative (L {m} {k} {c})", init, 1,
                      separable, f"Lagrangian->state-derivative (L {m} {k} {{c}})")

    def lagrangian_2d(self, params: list[str]) -> System:
        coupling = self.expression(["x", "y"], 2, bounded=True)
        definition = (
            "(define ((L2 m k c) local)\n"
            "  (let* ((q (coordinate local)) (x (ref q 0)) (y (ref q 1))\n"
            "         (v (velocity local)))\n"
            "    (- (* 1/2 m (dot-product v v))\n"
            f"       (+ (* 1/2 k (+ (square x) (square y))) (* c {coupling})))))\n")
        m = self.coefficient(params, positive=True)
        k = self.coefficient(params, positive=True)
        c = self.coefficient(params)
        init = f"(up 0. (up {self.state_number()} {self.state_number()}) (up {self.state_number()} 0.))"
        return System(definition, f"Lagrangian->state-derivative (L2 {m} {k} {c})", init, 2,
                      True, f"Lagrangian->state-derivative (L2 {m} {k} {{c}})")

    def hand_sysder(self, params: list[str]) -> System:
        # x'' = -a x + b f(t, x, v), f bounded, and a damping term sometimes.
        force = self.expression(["x", "v", "t"], 2, bounded=True)
        damping = ""
        if self.chance(0.3):
            damping = f" (* {self.number(positive=True)} v)"
        definition = (
            "(define ((sysder a b) state)\n"
            "  (let ((t (ref state 0)) (x (ref state 1)) (v (ref state 2)))\n"
            f"    (up 1 v (- (* b {force}) (* a x){damping}))))\n")
        a = self.coefficient(params, positive=True)
        b = self.coefficient(params)
        init = f"(up 0. {self.state_number()} {self.state_number()})"
        return System(definition, f"sysder {a} {b}", init, 1, False, f"sysder {a} {{c}}")

    # --- monitors ---------------------------------------------------------------

    def monitor(self, system: System) -> tuple[str, str, str]:
        """(definitions before the evolve, the monitor expression, forms after
        it that print what the monitor gathered)."""
        kind = self.pick(["print", "write-state", "count", "maximum", "conditional",
                          "plot", "collect", "silent"])
        self.feature("monitor-" + kind)
        coord = "(ref s 1)" if system.dimensions == 1 else "(ref s 1 0)"
        if kind == "print":
            return "", f"(lambda (s) (display {coord}) (newline))", ""
        if kind == "write-state":
            return "", "(lambda (s) (write s) (newline))", ""
        if kind == "count":
            n = self.fresh("count")
            return (f"(define {n} 0)\n", f"(lambda (s) (set! {n} (+ {n} 1)))", f"{n}\n")
        if kind == "maximum":
            m = self.fresh("largest")
            return (f"(define {m} 0.)\n",
                    f"(lambda (s) (set! {m} (max {m} (abs {coord}))))", f"{m}\n")
        if kind == "conditional":
            n = self.fresh("above")
            return (f"(define {n} 0)\n",
                    f"(lambda (s) (if (> {coord} 0) (set! {n} (+ {n} 1))))", f"{n}\n")
        if kind == "plot":
            w = self.fresh("win")
            name = self.plot_name()
            return (f"(define {w} (frame 0. 5. -3. 3. \"{name}\"))\n",
                    f"(lambda (s) (plot-point {w} (ref s 0) {coord}))",
                    f"(graphics-close {w})\n")
        if kind == "collect":
            states = self.fresh("states")
            after = f"(length {states})\n"
            if self.chance(0.5):
                after += f"(apply max (map (lambda (s) {coord}) {states}))\n"
            return (f"(define {states} '())\n",
                    f"(lambda (s) (set! {states} (cons s {states})))", after)
        return "", "(lambda (s) s)", ""

    def plot_name(self) -> str:
        self.frames += 1
        return f"plot{self.frames}"

    # --- actions ------------------------------------------------------------------

    def integrator_arguments(self, system: System) -> str:
        """' TOL' or ' TOL 'INTEGRATOR' or '' (the defaults)."""
        r = self.rng.random()
        if r < 0.3:
            return ""
        tol = self.pick(["1e-10", "1e-12", "1e-8", ".00001"])
        if r < 0.6:
            self.feature("tolerance")
            return f" {tol}"
        if system.separable and self.chance(0.2):
            name = self.pick(SYMPLECTIC_INTEGRATORS)
            self.feature("integrator-" + name)
            return f" .01 '{name}"
        name = self.pick(INTEGRATORS)
        self.feature("integrator-" + name)
        return f" {tol} '{name}"

    def use_of_state(self, name: str, system: System) -> str:
        """A form that prints something of the final state `name`."""
        coord = f"(ref {name} 1)" if system.dimensions == 1 else f"(ref {name} 1 1)"
        choice = self.pick(["write", "coordinate", "arith", "test", "display"])
        self.feature("result-" + choice)
        if choice == "write":
            return f"{name}\n"
        if choice == "coordinate":
            return f"{coord}\n"
        if choice == "arith":
            return f"(+ (* 2 {coord}) (square (ref {name} 2{'' if system.dimensions == 1 else ' 0'})))\n"
        if choice == "test":
            # Numbers in both arms: a run-time choice between two symbols
            # is a documented "cannot compile" (docs/compiling.md).
            return f"(if (> {coord} 0) 1 -1)\n"
        return f"(display (list 'final {coord})) (newline)\n"

    def evolve(self, system: System) -> str:
        self.feature("evolve")
        before, monitor, after = self.monitor(system)
        dt = self.pick([".1", ".25", ".5", "1/4", "1."])
        if "/" in dt:
            self.feature("exact-step")
        t_end = self.pick(["1.", "2.", "2.5", "3."])
        final = self.fresh("final")
        return (before +
                f"(define {final}\n  ((evolve {system.sysder}) {system.initial}\n"
                f"   {monitor}\n   {dt} {t_end}{self.integrator_arguments(system)}))\n" +
                after + self.use_of_state(final, system))

    def state_advancer(self, system: System) -> str:
        self.feature("state-advancer")
        dt = self.pick(["1.", ".5", "2.", "3/2"])
        return (f"((state-advancer {system.sysder}) {system.initial} {dt}"
                f"{self.integrator_arguments(system)})\n")

    def sweep(self, system: System) -> str:
        # One procedure, several parameter values: each value a kernel
        # parameter (sicm run) or a run-time number (the executable).
        self.feature("sweep")
        values = " ".join(self.number() for _ in range(self.pick([2, 3])))
        sysder = system.sweep_template.format(c="c")
        advance = f"((state-advancer {sysder}) {system.initial} 1.)"
        return (f"(for-each (lambda (c) (write {advance}) (newline))\n"
                f"          '({values}))\n")

    def minimize(self, params: list[str]) -> str:
        self.feature("minimize")
        # A parabola plus a small bounded term: one minimum inside [-2, 2].
        bump = self.expression(["x"], 2, bounded=True)
        c = self.coefficient(params)
        f = f"(lambda (x) (+ (square (- x {c})) (* .1 {bump})))"
        tol = " 1e-8" if self.chance(0.3) else ""
        if tol:
            self.feature("minimize-tolerance")
        call = f"(minimize {f} -2. 2.{tol})"
        if self.chance(0.4):
            self.feature("result-car")
            return f"(car {call})\n"
        return call + "\n"

    def multidimensional_minimize(self, params: list[str]) -> str:
        self.feature("multidimensional-minimize")
        bump = self.expression(["x", "y"], 2, bounded=True)
        c1, c2 = self.coefficient(params), self.number()
        start = self.pick(["'(0. 0.)", "'(1. -1.)", "(list .5 .5)"])
        return (f"(multidimensional-minimize\n"
                f" (lambda (l) (let ((x (car l)) (y (cadr l)))\n"
                f"   (+ (square (- x {c1})) (square (- y {c2})) (* .1 {bump}))))\n"
                f" {start})\n")

    def definite_integral(self, params: list[str]) -> str:
        self.feature("definite-integral")
        f = self.expression(["x"], 3)
        c = self.coefficient(params)
        a, b = self.pick([("0.", "1."), ("-1.", "2."), ("0", ":pi"), ("1/2", "3/2")])
        if a in ("0", "1/2"):
            self.feature("exact-bounds")
        tol = " 1e-8" if self.chance(0.3) else ""
        return f"(definite-integral (lambda (x) (* {c} {f})) {a} {b}{tol})\n"

    def find_root(self, params: list[str]) -> str:
        self.feature("find-root")
        return f"(find-root {self.root_function()} -2. 2.)\n"

    def bisect(self, params: list[str]) -> str:
        self.feature("bisect")
        eps = self.pick(["1e-10", "1e-6", ".001"])
        return f"(bisect {self.root_function()} -2. 2. {eps})\n"

    def root_function(self) -> str:
        """x - d - c g(x) with |c g| < 1 and |d| < 1: a sign change on [-2, 2].
        Without d the root is often exactly 0, which find-root misses in
        both modes ("no convergence"): a feature of its own."""
        g = self.expression(["x"], 2, bounded=True)
        c = self.pick([".5", ".3", "-.7", "1/2"])
        if self.allowed("root-at-zero") and self.chance(0.1):
            self.feature("root-at-zero")
            return f"(lambda (x) (- x (* {c} (sin x))))"
        d = self.pick([".1", "-.25", ".37", "1/3"])
        return f"(lambda (x) (- x {d} (* {c} {g})))"

    def orbit_plot(self, params: list[str]) -> str:
        self.feature("plot-orbit")
        w = self.fresh("win")
        k = self.pick([".9", "1.2", ".3"])
        n = self.pick(["20", "50", "100"])
        return (f"(define {w} (frame 0. :2pi 0. :2pi \"{self.plot_name()}\"))\n"
                f"(plot-orbit {w} (standard-map {k}) {self.number()} {self.number()} {n})\n"
                f"(graphics-close {w})\n")

    def derived(self, params: list[str]) -> str:
        # Arithmetic and tests on numerical results: C in the executable.
        self.feature("derived")
        r = self.fresh("r")
        return (f"(define {r} (minimize (lambda (x) (square (- x {self.coefficient(params)}))) -3. 3.))\n"
                f"(if (< (cadr {r}) 1e-6) (* 10 (car {r})) (- (cadr {r})))\n")

    def action(self, system: System, params: list[str]) -> str:
        actions = [self.evolve, self.evolve, self.state_advancer, self.sweep,
                   lambda s: self.minimize(params),
                   lambda s: self.multidimensional_minimize(params),
                   lambda s: self.definite_integral(params),
                   lambda s: self.find_root(params),
                   lambda s: self.bisect(params),
                   lambda s: self.orbit_plot(params),
                   lambda s: self.derived(params)]
        return self.pick(actions)(system)

    # --- bad inputs -----------------------------------------------------------------

    def bad_form(self, system: System) -> str:
        """A form that must fail: both modes must say the same, at the same
        place, and exit alike. The program ends there."""
        bad = self.pick(["evolve-arity", "negative-tolerance", "division-at-t0",
                         "monitor-step-0", "minimize-division", "integral-divergent",
                         "no-bracket", "monitor-error", "sysder-arity", "state-shape",
                         "integrator-name", "objective-not-number",
                         "advancer-negative-tolerance", "car-of-result"])
        self.feature("bad-" + bad)
        quiet = "(lambda (s) s)"
        if bad == "evolve-arity":
            return f"((evolve {system.sysder}) {system.initial} {quiet} .5)\n"
        if bad == "negative-tolerance":
            return f"((evolve {system.sysder}) {system.initial} {quiet} .5 2. -1)\n"
        if bad == "division-at-t0":
            return ("((evolve (lambda () (lambda (s) (up 1 (ref s 2) (/ 1 (ref s 0))))))\n"
                    f" (up 0. 1. 0.) {quiet} .5 2.)\n")
        if bad == "monitor-step-0":
            return f"((evolve {system.sysder}) {system.initial} {quiet} 0. 2.)\n"
        if bad == "minimize-division":
            return "(minimize (lambda (x) (/ 1 x)) 0. 1.)\n"
        if bad == "integral-divergent":
            return "(definite-integral (lambda (x) (/ 1. x)) 0. 1.)\n"
        if bad == "no-bracket":
            return "(find-root (lambda (x) (+ 1 (square x))) 0. 1.)\n"
        if bad == "monitor-error":
            return f"((evolve {system.sysder}) {system.initial} (lambda (s) (car s)) .5 2.)\n"
        if bad == "sysder-arity":
            name = system.sysder.split(" ")[0]
            if name.startswith("Lagrangian"):
                return f"((evolve Lagrangian->state-derivative) {system.initial} {quiet} .5 2.)\n"
            return f"((evolve sysder 1.) {system.initial} {quiet} .5 2.)\n"
        if bad == "state-shape":
            return f"((state-advancer {system.sysder}) (up 0. 1.) 1.)\n"
        if bad == "integrator-name":
            return f"((state-advancer {system.sysder}) {system.initial} 1. 1e-10 'no-such-method)\n"
        if bad == "objective-not-number":
            return "(minimize (lambda (x) 'low) 0. 1.)\n"
        if bad == "advancer-negative-tolerance":
            return f"((state-advancer {system.sysder}) {system.initial} 1. -1e-10)\n"
        return (f"(car ((state-advancer {system.sysder}) {system.initial} 1.))\n")

    # --- whole programs ---------------------------------------------------------------

    def program(self) -> str:
        param_defs, params = self.parameters()
        system = self.system(params)
        text = ";; differential fuzz program\n" + param_defs + system.definition
        for _ in range(self.pick([1, 2, 2, 3, 4])):
            text += self.action(system, params)
        if self.chance(0.2):
            text += "(display \"before the error\") (newline)\n"
            text += self.bad_form(system)
        return text


def generate(seed: str, excluded: set[str], attempts: int = 200) -> Program:
    """The program of `seed` (any string: the runner passes "SEED:INDEX").

    A draw that hits an excluded feature is thrown away and drawn again from
    the same generator's continuing stream, so the result is still a
    function of the seed and the excluded set."""
    rng = random.Random(seed)
    for _ in range(attempts):
        g = Generator(rng, excluded)
        try:
            return Program(g.program(), g.features)
        except Excluded:
            continue
    raise RuntimeError(f"no program without {sorted(excluded)} in {attempts} draws")
