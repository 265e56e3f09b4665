"""Continuation in a problem's parameter: the problem solved at a sequence of values of one of its
parameters, each step seeded by the last step's solution (the paper's strategy 4, an earlier
solution, unperturbed), the first by the problem's own seed or by a solution folder. A hard
problem is reached from an easier one: the full-body Ollie from one whose rider is helped by an
external force on its base (`ollie`'s `assist`, in the rider's weights; 0 is the paper's
problem), the help lowered step by step:

    PYTHONPATH=build/python /usr/bin/python3 examples/python/ollie_retarget.py \\
      tests/data/solutions/ollie_simple_level --out SEED_DIR --set assist=3
    PYTHONPATH=build/python /usr/bin/python3 examples/python/continuation.py ollie --parameter assist \\
      --values 3,2,1.5,1,0.75,0.5,0.25,0 --seed-from SEED_DIR --out DIR --no-hints --task-max-iter 300 \\
      --feasibility-hessian limited-memory --ipopt mu_strategy=monotone --report rider_x,rider_z,rider_theta

Each step is `saltus optimize PROBLEM --seed-from PREVIOUS --seed-scale 0 --restarts 0 --set
NAME=VALUE` with the solve options given here, saved to DIR/NAME_VALUE. A step that ends
infeasible is solved once more from its own end (a feasibility stage stopped by its iteration
limit goes on from where it was; that end is kept in DIR/NAME_VALUE.unfinished). With
--feasibility-repeats K, a feasibility stage that Ipopt solves above the tolerance is repeated
within the step, before its tightening (saltus optimize --feasibility-repeats). If the retry fails
too, the step is halved (a value half way from the last feasible one), down to --min-step. The
chain can be stopped and started again: a step whose folder holds a feasible solution is read,
not solved again. Each step prints its result and, for the inputs named by --report, the largest
and root-mean-square |u| over the samples as fractions of their bounds.
"""
import argparse
import json
import os
import sys

import numpy as np
import saltus


def values_list(text):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas, got '{text}'")
    if len(set(values)) != len(values):
        raise argparse.ArgumentTypeError(f"expected distinct values, got '{text}'")
    return values


def assignment(text):
    name, sep, value = text.partition("=")
    if not sep or not name:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got '{text}'")
    return name, value


def folder_of(out, parameter, value):
    return os.path.join(out, f"{parameter}_{value:g}")


def saved_feasible(folder):
    try:
        with open(os.path.join(folder, "summary.json")) as f:
            return bool(json.load(f).get("feasible"))
    except (OSError, ValueError):
        return False


def input_use(solution, names):
    """For each named input: the largest and root-mean-square |u| over the collocation points (the
    bounded values; the element ends' are the polynomials' extrapolation), as fractions of the
    larger of its bounds' magnitudes (0 where both bounds are 0)."""
    inputs = list(solution.problem.inputs)
    lower, upper = np.asarray(solution.problem.input_lower), np.asarray(solution.problem.input_upper)
    u = np.abs(np.asarray(solution.u))
    per_element = solution.summary["P"] + 2  # an element's samples: its start, its points, its end
    if len(u) == solution.summary["elements"] * per_element:
        point = np.arange(len(u)) % per_element
        u = u[(point > 0) & (point < per_element - 1)]
    use = []
    for name in names:
        i = inputs.index(name)
        bound = max(abs(lower[i]), abs(upper[i]))
        fraction = u[:, i] / bound if bound > 0 else np.zeros(len(u))
        use.append((name, float(fraction.max()), float(np.sqrt(np.mean(fraction**2)))))
    return use


def describe(parameter, value, seeded_from, solution, attempt, report):
    s = solution.summary
    stages = " + ".join(str(st["iterations"]) for st in s["stages"])
    kept = s["stages"][s.get("kept_stage", -1)]  # the stage whose point is the solution
    line = (f"{parameter} {value:g} (from {seeded_from}, attempt {attempt}): "
            f"{'feasible' if s['feasible'] else 'infeasible'} (the {kept['name']} stage: "
            f"{kept['status']}), "
            f"largest product {s['largest_product']:.2g}, constraints {s['largest_violation']:.2g}, "
            f"iterations {stages}, {s['wall_seconds']:.0f} s")
    if s["feasible"] and report:
        line += "; |u| max / rms of the bound: " + ", ".join(f"{n} {m:.2f} / {r:.2f}" for n, m, r in
                                                             input_use(solution, report))
    return line


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("problem", help="built-in problem name or problem file")
    parser.add_argument("--parameter", required=True, help="the problem's parameter to step")
    parser.add_argument("--values", required=True, type=values_list, help="its values in order, comma-separated")
    parser.add_argument("--out", required=True, help="folder for the steps' solutions (PARAMETER_VALUE each)")
    parser.add_argument("--seed-from", default="", help="the first step's seed: a solution folder (variables.csv)")
    parser.add_argument("--set", type=assignment, action="append", default=[], metavar="NAME=VALUE",
                        help="another parameter, fixed over the chain (repeatable)")
    parser.add_argument("--method", default="impulsive")
    parser.add_argument("--no-hints", action="store_true", help="solve without the problem file's hints")
    parser.add_argument("--task-max-iter", type=int, default=None, help="the task stage's iteration limit")
    parser.add_argument("--feasibility-hessian", choices=["exact", "limited-memory"], default=None)
    parser.add_argument("--feasibility-repeats", type=int, default=None, metavar="K",
                        help="repeats of a feasibility stage solved above the tolerance (saltus optimize's option)")
    parser.add_argument("--ipopt", type=assignment, action="append", default=[], metavar="NAME=VALUE",
                        help="an Ipopt option (repeatable)")
    parser.add_argument("--min-step", type=float, default=0.1, help="the smallest step when halving")
    parser.add_argument("--report", default="", help="inputs whose use to print, comma-separated")
    parser.add_argument("--print-level", type=int, default=0, help="Ipopt's print level")
    args = parser.parse_args(argv)
    if args.seed_from and not os.path.isfile(os.path.join(args.seed_from, "variables.csv")):
        parser.error(f"--seed-from {args.seed_from}: expected a solution folder holding variables.csv")
    if args.feasibility_repeats is not None and args.feasibility_repeats < 0:
        parser.error(f"--feasibility-repeats: expected a count of 0 or more, got {args.feasibility_repeats}")
    if args.min_step <= 0:
        parser.error(f"--min-step: expected a positive step, got {args.min_step}")
    fixed = {}
    for name, value in args.set:
        try:
            fixed[name] = float(value)
        except ValueError:
            parser.error(f"--set {name}={value}: expected a number")
    if args.parameter in fixed:
        parser.error(f"--set {args.parameter}: the parameter stepped cannot be fixed too")
    problem = saltus.load_problem(args.problem, set=fixed)  # a bad name, file or parameter fails here
    if args.parameter not in problem.parameters:
        parser.error(f"--parameter {args.parameter}: {problem.name} has no such parameter "
                     f"(it has {', '.join(sorted(problem.parameters))})")
    report = [n for n in args.report.split(",") if n]
    for name in report:
        if name not in problem.inputs:
            parser.error(f"--report {name}: {problem.name} has no such input (it has {', '.join(problem.inputs)})")

    def solve(seed_dir, value, attempt):
        options = dict(method=args.method, seed_scale=0.0, restarts=0, hints=not args.no_hints,
                       task_max_iter=args.task_max_iter, feasibility_hessian=args.feasibility_hessian,
                       feasibility_repeats=args.feasibility_repeats,
                       ipopt=dict(args.ipopt), print_level=args.print_level, set={**fixed, args.parameter: value})
        if seed_dir:
            options["seed_from"] = seed_dir
        solution = saltus.optimize(args.problem, **options)
        print(describe(args.parameter, value, seed_dir or "the problem's seed", solution, attempt, report), flush=True)
        return solution

    return chain(args.values, solve, lambda value: folder_of(args.out, args.parameter, value), args.seed_from,
                 args.min_step, lambda text: print(f"{args.parameter} {text}", flush=True))


def chain(values, solve, folder_of, first_seed, min_step, log):
    """Solves at each value in turn (solve(seed_folder, value, attempt) -> a Solution), each seeded
    by the last feasible step's folder (folder_of(value)); 0 if every step ends feasible, else 1."""
    previous, previous_value = first_seed, None
    targets = list(values)
    while targets:
        value = targets[0]
        folder = folder_of(value)
        if saved_feasible(folder):
            log(f"{value:g}: a feasible solution in {folder}, kept")
        else:
            seed, solution = previous, None
            for attempt in (1, 2):
                solution = solve(seed, value, attempt)
                if solution.feasible:
                    break
                seed = folder + ".unfinished"  # the retry goes on from this attempt's end
                solution.save(seed)
            if not solution.feasible:
                if previous_value is None or abs(previous_value - value) <= 2 * min_step:
                    log(f"{value:g}: not feasible from {previous or 'the problem seed'}; stopped")
                    return 1
                targets.insert(0, round(0.5 * (previous_value + value), 6))  # half the step
                continue
            solution.save(folder)
        previous, previous_value = folder, value
        targets.pop(0)
    log(f"{values[-1]:g}: every step feasible; the last in {previous}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
