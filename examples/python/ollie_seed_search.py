"""A seed for the Ollie found in Saltus' own time-stepper: a search over open-loop input schedules
of the riders' forces, written as the input schedule that `saltus optimize --seed-inputs` turns
into a simulation seed (the time-stepper's motion under these inputs, with its own contact
sequence: stamp, tail strike, lift by the front foot's friction, landing). No hint and no contact
sequence is given; the search knows only the task: both wheels above the air goal around [20, 0],
the feet never through the deck, and the board back at rest on its wheels with the riders on it
at the end.

The schedule holds each of the four forces (back_x, back_z, front_x, front_z) constant over
intervals of 0.03 s within the problem's bounds; the search is the cross-entropy method
(R. Y. Rubinstein and D. P. Kroese, "The Cross-Entropy Method", Springer, 2004): sample schedules
around a mean, keep the best tenth, move the mean and spread to them. Three stages: the air alone
over 0.5 s (the highest of several starts), then the whole horizon with the landing, then the same with the board within 0.5 rad
of level in the air. The simulation is the simulation seed's (θ = ½, dt = h_max / 40), so the
seed re-simulates the motion found here. A seed fixes every random choice: the same seed, the
same schedule (on one machine: the simulation's rounding depends on the instruction set).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/ollie_seed_search.py --out schedule.csv
    saltus optimize ollie_simple --seed-kind simulation --seed-inputs schedule.csv --no-hints --out DIR

About 35 minutes on one core.
"""
import argparse
import os
import sys
import tempfile

import numpy as np
import saltus

INTERVAL = 0.03  # [s] each force constant over this
POPULATION, ELITE = 200, 20


class Search:
    def __init__(self, problem, goal):
        self.problem = problem
        self.scene = problem.scene
        self.names = list(self.scene.coordinate_names)
        self.inputs = [self.names.index(n) for n in problem.inputs]
        self.lower, self.upper = np.asarray(problem.input_lower), np.asarray(problem.input_upper)
        self.dt = problem.h_max / 40
        self.horizon = problem.N * problem.h_max
        self.air = 20 * problem.h_max  # [20, 0] on the uniform mesh the seed starts from
        self.goal = goal
        contacts = list(self.scene.contact_names)
        self.wheels = [c for c in contacts if c.endswith("wheel")]
        self.feet = [c for c in contacts if c.endswith("foot")]
        self.rest_z = self.scene.q0[self.names.index("board_z")]

    def intervals(self, horizon):
        return int(np.ceil(horizon / INTERVAL - 1e-9))

    def forces(self, x):
        """Schedule parameters (in [-1, 1] of each bound) to forces [N], one row per interval."""
        x = np.clip(x.reshape(-1, len(self.inputs)), -1, 1)
        return np.where(x >= 0, x * self.upper, -x * self.lower)

    def score(self, x, horizon, landing, level, record=False):
        """Minus the task's shortfall (0 at best; for the air stage the highest clearance of both
        wheels instead): the wheels' clearance below goal + 2 cm within 0.03 s of [20, 0],
        penetration of the feet or tail, the distance from rest at the end (landing), the board's
        tilt beyond 0.5 rad there (level; the air stage: beyond 0.8 rad before it)."""
        u = self.forces(x)
        stepper = saltus.Stepper(self.scene, dt=self.dt, theta=0.5)
        tau = np.zeros(len(self.names))
        clearance, tilt, penetration, rows = 1e9, 0.0, 0.0, []
        steps = int(round(horizon / self.dt))
        best_air = -1e9
        for k in range(steps):
            tau[self.inputs] = u[min(int((k + 0.5) * self.dt / INTERVAL), len(u) - 1)]
            stepper.set_input(tau)
            try:
                stepper.step()
            except saltus.SimulationError:
                return -10.0, rows
            c = stepper.contacts
            wheels = min(c[w]["gap"] for w in self.wheels)
            t = (k + 1) * self.dt
            if landing:
                if abs(t - self.air) <= 0.03 + 1e-9:
                    clearance = min(clearance, wheels)
                    tilt = max(tilt, abs(stepper.q[self.names.index("board_theta")]))
            elif t <= self.air + 0.02:
                tilt = max(tilt, abs(stepper.q[self.names.index("board_theta")]))
                if t > 0.1:
                    best_air = max(best_air, wheels)
            penetration = max([penetration] + [-c[f]["gap"] for f in self.feet + ["tail"]])
            if penetration > 0.05:  # a foot through the deck: no Ollie, and slow to simulate
                return -10.0, rows
            if record:
                rows.append((t, *stepper.q))
        s = -10 * max(0.0, penetration - 1e-3)
        if not landing:
            return s + min(best_air, 1.0) - 2 * max(0.0, tilt - 0.8), rows
        q, v, c = stepper.q, stepper.v, stepper.contacts
        board_x = q[self.names.index("board_x")]
        end = abs(q[self.names.index("board_z")] - self.rest_z) + abs(q[self.names.index("board_theta")])
        end += 0.1 * np.abs(v).sum() + sum(abs(c[f]["gap"]) for f in self.feet)
        end += sum(max(0.0, abs(q[self.names.index(f.replace("_foot", "_x"))] - board_x) - 0.25) for f in self.feet)
        s += -20 * max(0.0, self.goal + 0.02 - clearance) - end
        if level:
            s -= 2 * max(0.0, tilt - 0.5)
        return s, rows

    def cem(self, rng, mean, spread, horizon, landing, level, iterations, label):
        for it in range(iterations):
            samples = np.clip(mean + spread * rng.standard_normal((POPULATION, mean.size)), -1, 1)
            samples[0] = mean
            scores = np.array([self.score(x, horizon, landing, level)[0] for x in samples])
            elite = samples[np.argsort(-scores)[:ELITE]]
            mean, spread = elite.mean(axis=0), elite.std(axis=0) + 0.01
            print(f"{label} {it + 1}/{iterations}: best {scores.max():.4f}", file=sys.stderr, flush=True)
        return elite[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True, help="the schedule CSV to write")
    ap.add_argument("--problem", default="ollie_simple", help="built-in problem or problem file (default ollie_simple)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="a problem parameter")
    ap.add_argument("--seed", type=int, default=0, help="random seed of the search (default 0)")
    ap.add_argument("--starts", type=int, default=4, help="independent starts of the air stage (default 4)")
    ap.add_argument("--iterations", type=int, nargs=3, default=[40, 60, 80], metavar=("AIR", "LANDING", "LEVEL"),
                    help="iterations of the three stages (default 40 60 80)")
    a = ap.parse_args()
    overrides = {}
    for s in a.set:
        name, _, value = s.partition("=")
        overrides[name] = float(value)
    problem = saltus.load_problem(a.problem, overrides)
    goal = problem.parameters["clearance_goal"]
    search = Search(problem, goal)
    rng = np.random.default_rng(a.seed)
    n = len(search.inputs)
    # Start from the riders' weights held by their forces (standing still).
    support = np.zeros(n)
    for i, name in enumerate(problem.inputs):
        if name.endswith("_z"):
            support[i] = problem.parameters["rider_mass"] * problem.parameters["g"] / search.upper[i]
    # The air stage often settles on a hop of a few centimetres (the board tipped about its rear
    # wheel): several independent starts, the highest kept.
    air_horizon = search.air + 0.1
    mean = np.tile(support, search.intervals(air_horizon))
    best, x = -np.inf, None
    for start in range(a.starts):
        y = search.cem(rng, mean, np.full(mean.size, 0.5), air_horizon, False, False, a.iterations[0], f"air {start + 1}")
        height = search.score(y, air_horizon, False, False)[0]
        print(f"air start {start + 1}: {height:.3f} m", file=sys.stderr, flush=True)
        if height > best:
            best, x = height, y
    mean = np.tile(support, search.intervals(search.horizon))
    mean[: x.size] = x
    x = search.cem(rng, mean, np.full(mean.size, 0.33), search.horizon, True, False, a.iterations[1], "landing")
    x = search.cem(rng, x, np.full(x.size, 0.33), search.horizon, True, True, a.iterations[2], "level")
    score, _ = search.score(x, search.horizon, True, True)
    print(f"shortfall {-score:.4g} (0: every condition of the search met)", file=sys.stderr)

    u = search.forces(x)
    names = ["u." + n for n in problem.inputs]
    out_dir = os.path.dirname(os.path.abspath(a.out))
    with tempfile.NamedTemporaryFile("w", dir=out_dir, delete=False, suffix=".tmp") as f:
        f.write(",".join(["t"] + names) + "\n")
        for k, row in enumerate(u):
            if k * INTERVAL < search.horizon - 1e-9:
                f.write(",".join(f"{v:.12g}" for v in [k * INTERVAL, *row]) + "\n")
        f.write(",".join(f"{v:.12g}" for v in [search.horizon, *u[-1]]) + "\n")
    os.replace(f.name, a.out)


if __name__ == "__main__":
    main()
