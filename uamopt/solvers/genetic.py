"""Genetic scheduling (Sec. 5.2.2): the standard GA (``ga``) and the paper's SOA (``soa``).

Chromosome (Fig. 14)
--------------------
One integer gene per flight, laid out aircraft by aircraft (genes 1..M_1 are aircraft e_1's
flights in order, then e_2's, ...). Gene k ≥ 0 asks for a departure delay of at least k·ΔT_a;
gene −1 (:data:`~uamopt.solvers.greedy.CANCEL`, our extension of Fig. 14) cancels the flight.
Alleles of flight f: −1, 0, 1, ..., ⌊Δd_f / ΔT_a⌋.

Decoding (repair) is the preliminary strategy of Sec. 5.2.1 run with these wishes
(:class:`~uamopt.solvers.greedy.Decoder`): flights in order of planned departure, each at the
earliest multiple of ΔT_a ≥ its wish that respects its aircraft's turnaround and every placed
flight's forbidden gaps, cancelled (with its return) when that exceeds Δd_f. So every individual
decodes to a feasible schedule; the all-zero chromosome is the greedy schedule, and every feasible
schedule on the ΔT_a grid is the decoding of its own delays, so nothing is out of reach.

Fitness (Eqs. 36-37): Q_q = (W_max − W_q) / (W_max − W_min) over the generation (1 for all when
W_max = W_min); every decoded individual meets the requirements, so Eq. 37's 0 never applies.
W is the problem's objective (Eq. 20 or the lexicographic variant), vectorised over the population.

``ga`` — the paper's baseline: roulette-wheel selection on Q, single-point crossover, single-point
mutation, generational replacement (no elitism, as the paper says of the standard GA); the best
individual ever seen is returned.

``soa`` — the paper's scheduling optimisation algorithm (Table 1): parents are paired at random;
a pair whose mean Q is below the population mean gets single-point crossover, otherwise two-point;
a child whose parent is below the mean gets multi-point mutation, otherwise single-point. Each
child competes with its parent for the parent's place (simulated-annealing selection, Table 1
steps 7-12): it is accepted when not worse, else with probability exp(−Δ/T), Δ = s·(W_child −
W_parent)/(W_max − W_min) the loss in percent of the generation's range (s = ``fitness_scale`` =
100: Table B.3's T is on that scale), T = T_0·ξ^l (step 15). Elitism (step 16): the best 10 % of
I(l) that lost their place come back in place of the worst of I(l+1). Stop after l generations or
when T < T_F. With Table B.3 (T_0 = 100, ξ = 0.99, l = 200) T ends at 13.4, so T_F = 0.1 is never
reached (it would take 688 generations).

Options (profile ``[options]``): population (50), generations (l = 200), crossover_rate (0.8),
mutation_rate (0.3, per child), multi_points (4, genes of a multi-point mutation), init_rate
(0.1, share of genes perturbed in the initial individuals), cancel_prob (0.1, share of mutations
drawing the cancel allele), elite_fraction (0.1), t0 (100), xi (0.99), t_final (0.1),
fitness_scale (100), step_s (ΔT_a = 10 s), exact_gaps (false). ``profile.seed`` seeds a numpy
Generator (same seed, same result, unless the time limit cuts the run); ``profile.time_limit_s``
is checked between generations (termination ``time_limit`` when it stopped the run, else ``stopped``, status "feasible";
``no_solution`` when a must-operate flight is left out).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

import numpy as np

from uamopt.bounds import MAX_TIME_S, Range, check_number, shown
from uamopt.errors import UamoptError
from uamopt.schedule.model import Schedule, SchedulingProblem, Termination, make_schedule
from uamopt.solvers.greedy import (  # noqa: F401  (SHAPES, OBJECTIVES: the decoder's, uamopt.solvers.check_supported)
    CANCEL,
    DEFAULT_STEP_S,
    EPS_S,
    OBJECTIVES,
    SHAPES,
    base_genes,
    decoder_for,
)
from uamopt.solvers.options import refuse_unknown

if TYPE_CHECKING:
    from uamopt.solvers import SolverProfile


@dataclass(frozen=True)
class GeneticOptions:
    """GA/SOA settings; defaults from Table B.3 where the paper gives them."""

    population: int = 50
    generations: int = 200  # l (Table B.3)
    crossover_rate: float = 0.8
    mutation_rate: float = 0.3  # probability that a child is mutated
    multi_points: int = 4  # genes changed by a multi-point mutation (SOA)
    init_rate: float = 0.1
    cancel_prob: float = 0.1
    elite_fraction: float = 0.1  # Table 1: 10 % of the population
    t0: float = 100.0  # T_0 (Table B.3)
    xi: float = 0.99  # ξ, cooling factor per generation (Table B.3)
    t_final: float = 0.1  # T_F (Table B.3)
    fitness_scale: float = 100.0  # Δ of the acceptance test in percent of the generation's W range
    step_s: float = DEFAULT_STEP_S  # ΔT_a, s (Table B.3)
    exact_gaps: bool = False

    @classmethod
    def from_options(cls, options: dict, solver: str) -> GeneticOptions:
        """Validated options (one-line errors naming the option and its range, :data:`GENETIC_RANGES`)."""
        names = {f.name: f.type for f in fields(cls)}
        refuse_unknown(options, set(names), solver)
        kw = {}
        for key, value in options.items():
            kind = {"int": int, "float": float, "bool": bool}[str(names[key])]
            if kind is bool:
                if not isinstance(value, bool):
                    raise UamoptError(f"option {key} must be bool, got {shown(value)}", f"solver {solver}", "fix the profile")
                kw[key] = value
                continue
            if kind is int and isinstance(value, float) and value.is_integer():
                value = int(value)  # 50.0 is 50 (TOML writes what a table generator gave)
            if isinstance(value, bool) or (kind is int and not isinstance(value, int)):
                raise UamoptError(f"option {key} must be {kind.__name__}, got {shown(value)}", f"solver {solver}",
                                  "fix the profile")
            valid = GENETIC_RANGES[key]
            kw[key] = check_number(value, f"option {key}", f"solver {solver}", f"use {valid.text()}", valid, error=UamoptError)
        return cls(**kw)


#: the range of each numeric GA/SOA option: what it can mean (a population of at most 10⁴ individuals,
#: the paper's is 50; a delay grid of a millisecond to 10⁷ s)
GENETIC_RANGES = {
    "population": Range(2, 10_000, integer=True), "generations": Range(0, 10**7, integer=True),
    "multi_points": Range(1, 10**6, integer=True), "step_s": Range(1e-3, MAX_TIME_S),
    "t0": Range(0.0, 1e12, lo_open=True), "xi": Range(0.0, 1.0, lo_open=True), "t_final": Range(0.0, 1e12),
    "fitness_scale": Range(0.0, 1e12, lo_open=True),
    **{k: Range(0.0, 1.0) for k in ("crossover_rate", "mutation_rate", "init_rate", "cancel_prob", "elite_fraction")},
}


def objective_values(problem: SchedulingProblem, operated: np.ndarray, delay_s: np.ndarray) -> np.ndarray:
    """W of each row (Eqs. 20-22, or the lexicographic scalar; ``problem.objective``) plus, for each
    must-operate flight cancelled, a penalty above the whole range of W (so any such row is worse
    than every feasible one)."""
    obj = problem.objective
    w = obj.values(operated, delay_s)
    if not problem.must_operate.any():
        return w
    worst = np.maximum(obj.delay_cost(np.zeros(problem.n_flights)), obj.delay_cost(problem.delay_upper_s))  # convex in d
    penalty = obj.per_flight * problem.n_flights + float(np.sum(worst)) + 1.0
    return w + penalty * np.sum(problem.must_operate & ~np.asarray(operated, dtype=bool), axis=-1)


def fitness(w: np.ndarray) -> np.ndarray:
    """Q = (W_max − W) / (W_max − W_min) (Eqs. 36-37); all ones when the generation is uniform."""
    spread = float(w.max() - w.min())
    return np.ones_like(w) if spread <= 1e-12 else (w.max() - w) / spread


class _Population:
    """Genetic operators on (P, n) gene arrays in flight order, positions in Fig. 14's layout."""

    def __init__(self, problem: SchedulingProblem, opts: GeneticOptions, rng: np.random.Generator) -> None:
        self.problem, self.opts, self.rng = problem, opts, rng
        self.n = problem.n_flights
        layout = np.concatenate(problem.chains)  # Fig. 14: aircraft by aircraft
        self.locus = np.empty(self.n, dtype=np.int64)  # position of each flight's gene in the layout
        self.locus[layout] = np.arange(self.n)
        self.top = np.floor(problem.delay_upper_s / opts.step_s + EPS_S).astype(np.int64)  # largest allele
        self.decoder = decoder_for(problem)
        self.evaluations = 0

    def evaluate(self, genes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        operated, delay = self.decoder.decode(self.problem, genes, self.opts.step_s, self.opts.exact_gaps)
        self.evaluations += len(genes)
        return objective_values(self.problem, operated, delay), operated, delay

    def alleles(self, flights: np.ndarray) -> np.ndarray:
        """Random alleles of the given flights: cancel with probability ``cancel_prob``, else a delay
        0..⌊Δd/ΔT_a⌋ drawn uniformly."""
        draw = np.floor(self.rng.random(flights.shape) * (self.top[flights] + 1)).astype(np.int64)
        return np.where(self.rng.random(flights.shape) < self.opts.cancel_prob, CANCEL, draw)

    def initial(self, size: int) -> np.ndarray:
        """Individual 0: the greedy schedule (:func:`base_genes`: all zeros but for the
        earliness/tardiness objective's targets); the others perturb it at ``init_rate``."""
        genes = np.tile(base_genes(self.problem, self.opts.step_s), (size, 1))
        mask = self.rng.random((size, self.n)) < self.opts.init_rate
        mask[0] = False
        rows, cols = np.nonzero(mask)
        genes[rows, cols] = self.alleles(cols)
        return genes

    def crossover(self, a: np.ndarray, b: np.ndarray, two_point: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Single-point (tails swapped) or two-point (middle segment swapped) crossover, Fig. 15,
        on the chromosome layout; a pair is crossed with probability ``crossover_rate``."""
        m = len(a)
        if self.n < 2:
            return a.copy(), b.copy()
        cut = np.sort(self.rng.integers(1, self.n, size=(m, 2)), axis=1)
        lo, hi = cut[:, 0], np.where(two_point, cut[:, 1], self.n)  # the swapped segment [lo, hi)
        swap = (self.locus[None, :] >= lo[:, None]) & (self.locus[None, :] < hi[:, None])
        swap &= (self.rng.random(m) < self.opts.crossover_rate)[:, None]
        return np.where(swap, b, a), np.where(swap, a, b)

    def mutate(self, genes: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Replace ``points[i]`` random genes of child i by random alleles (Fig. 16), with
        probability ``mutation_rate`` per child."""
        genes = genes.copy()
        m = len(genes)
        points = np.where(self.rng.random(m) < self.opts.mutation_rate, np.minimum(points, self.n), 0)
        order = np.argsort(self.rng.random((m, self.n)), axis=1)  # distinct loci per child
        rows, k = np.nonzero(np.arange(self.n)[None, :] < points[:, None])
        cols = order[rows, k]
        genes[rows, cols] = self.alleles(cols)
        return genes


def _run_ga(pop: _Population, genes, w, deadline, best) -> tuple[int, bool]:
    """Standard GA: roulette wheel, single-point crossover and mutation, generational replacement."""
    opts, rng, size = pop.opts, pop.rng, len(genes)
    for gen in range(opts.generations):
        if time.perf_counter() > deadline:
            return gen, True
        q = fitness(w)
        prob = q / q.sum() if q.sum() > 0 else np.full(size, 1.0 / size)
        parents = rng.choice(size, size=2 * math.ceil(size / 2), p=prob)
        one_point = np.zeros(len(parents) // 2, dtype=bool)
        a, b = pop.crossover(genes[parents[0::2]], genes[parents[1::2]], one_point)
        children = np.concatenate([a, b])[:size]
        genes = pop.mutate(children, np.ones(size, dtype=np.int64))
        w, operated, delay = pop.evaluate(genes)
        best.offer(gen + 1, genes, w, operated, delay)
    return opts.generations, False


def _run_soa(pop: _Population, genes, w, deadline, best) -> tuple[int, bool]:
    """The SOA of Table 1: SA selection between each child and its parent, elitism, and crossover
    and mutation operators chosen by fitness against the population mean."""
    opts, rng, size = pop.opts, pop.rng, len(genes)
    n_elite = max(1, math.ceil(opts.elite_fraction * size)) if opts.elite_fraction > 0 else 0
    for gen in range(opts.generations):
        temperature = opts.t0 * opts.xi ** gen  # Table 1 step 15
        if temperature < opts.t_final:
            return gen, False
        if time.perf_counter() > deadline:
            return gen, True
        q = fitness(w)
        above = q >= q.mean()
        perm = rng.permutation(size)
        if size % 2:
            perm = np.append(perm, perm[0])
        pa, pb = perm[0::2], perm[1::2]
        two_point = (q[pa] + q[pb]) / 2 >= q.mean()
        a, b = pop.crossover(genes[pa], genes[pb], two_point)
        slots = np.concatenate([pa, pb])  # child k takes the place of parent slots[k]
        children = np.concatenate([a, b])
        keep = np.unique(slots, return_index=True)[1]  # an odd population: the repeated parent once
        slots, children = slots[keep], children[keep]
        children = pop.mutate(children, np.where(above[slots], 1, opts.multi_points))
        wc, operated, delay = pop.evaluate(children)
        best.offer(gen + 1, children, wc, operated, delay)
        spread = max(float(w.max() - w.min()), 1e-12)
        loss = opts.fitness_scale * (wc - w[slots]) / spread
        accept = (loss <= 0) | (rng.random(len(slots)) < np.exp(-np.maximum(loss, 0) / temperature))
        new_genes, new_w = genes.copy(), w.copy()
        new_genes[slots[accept]], new_w[slots[accept]] = children[accept], wc[accept]
        if n_elite:  # Table 1 step 16: the elite of I(l) that lost its place comes back
            elite = np.argsort(w, kind="stable")[:n_elite]
            lost = elite[new_w[elite] > w[elite]]
            if len(lost):
                rank = new_w.copy()
                rank[np.setdiff1d(elite, lost)] = -np.inf  # never evict an elite that kept its place
                worst = np.argsort(-rank, kind="stable")[:len(lost)]
                new_genes[worst], new_w[worst] = genes[lost], w[lost]
        genes, w = new_genes, new_w
    return opts.generations, False


class _Best:
    """The best individual seen so far (the solver's answer) and the per-generation history."""

    def __init__(self) -> None:
        self.w = math.inf
        self.generation = 0
        self.history: list[float] = []

    def offer(self, gen: int, genes, w, operated, delay) -> None:
        i = int(np.argmin(w))
        if w[i] < self.w - 1e-12:
            self.w, self.generation = float(w[i]), gen
            self.genes, self.operated, self.delay = genes[i].copy(), operated[i].copy(), delay[i].copy()
        self.history.append(self.w)


def solve(problem: SchedulingProblem, profile: SolverProfile) -> Schedule:
    """Run ``ga`` or ``soa`` (``profile.solver``) on the problem; see the module docstring."""
    if profile.solver not in ("ga", "soa"):
        raise UamoptError(f"genetic.solve cannot run solver '{profile.solver}'", "uamopt.solvers.genetic", "use ga or soa")
    opts = GeneticOptions.from_options(profile.options, profile.solver)
    if "step_s" not in profile.options:  # ΔT_a of the scenario (schedule.time_step_s)
        opts = dataclasses.replace(opts, step_s=problem.time_step_s)
    start = time.perf_counter()
    deadline = start + profile.time_limit_s
    rng = np.random.default_rng(profile.seed)
    pop = _Population(problem, opts, rng)
    genes = pop.initial(opts.population)
    w, operated, delay = pop.evaluate(genes)
    best = _Best()
    best.offer(0, genes, w, operated, delay)
    run = _run_soa if profile.solver == "soa" else _run_ga
    generations, timed_out = run(pop, genes, w, deadline, best)
    extras = {"generations": generations, "evaluations": pop.evaluations, "best_generation": best.generation,
              "greedy_objective": float(w[0]), "history": best.history}
    if profile.solver == "soa":
        extras["final_temperature"] = opts.t0 * opts.xi ** max(generations - 1, 0)
    termination: Termination = ("no_solution" if np.any(problem.must_operate & ~best.operated)
                                else "time_limit" if timed_out else "stopped")
    return make_schedule(problem, profile.solver, termination, best.operated, best.delay,
                         solve_seconds=time.perf_counter() - start, seed=profile.seed, extras=extras)
