#!/usr/bin/env python3
"""Charts of `saltus bench` and `saltus optimize` results (python3 + matplotlib, Agg backend).

    charts.py work-precision DIR/work_precision.csv --png OUT.png --svg OUT.svg
        error vs CPU seconds per simulated second, log-log, one labelled point per dt
    charts.py stability DIR/stability.csv --png OUT.png --svg OUT.svg
        a grid (dt across; friction or restitution up; one panel per restitution when the scene
        has both) coloured by outcome
    charts.py replay-deviation DIR/replay.csv --png OUT.png --svg OUT.svg
        `saltus replay`: |q - q*| per coordinate and engine over time (log scale) with the
        tolerance, and below it the optimised vs the replayed positions
    charts.py replay-energy DIR/replay.csv --png OUT.png --svg OUT.svg
        `saltus replay`: energy over time, optimised and per engine
    charts.py trajectory DIR/trajectory.csv --png OUT.png --svg OUT.svg
        an optimised trajectory in the style of the paper's Figs. 3-4: positions, velocities (a
        velocity jump is a vertical segment: two rows share its t, before then after), contact
        normal and tangential forces at the collocation points (first order: at every step's end,
        the method from DIR/summary.json) with the impulses as stems at their instants
        (right-hand axis, N s); element boundaries as faint vertical lines, from the h[n,0]
        values of DIR/variables.csv when it is there
    charts.py sweep-time|sweep-error|sweep-cost DIR/summary.json --png OUT.png --svg OUT.svg
        `saltus sweep`: per cell and method, the range, interquartile range, mean and median of the
        solve time, mean local error or cost (normalised per case) of the successful solves, in
        the style of the paper's Figs. 6-8

The CSV files start with '# key: value' comment lines (scene, method, error, ...) that give the
titles. Each image is written to a temporary name beside the target and renamed into place.
Nothing is printed on standard output; errors go to standard error with exit status 1.
"""
import argparse
import csv
import math
import os
import signal
import socket
import sys
import textwrap

os.environ.setdefault("MPLBACKEND", "Agg")


def read_csv(path):
    """(metadata dict from '# key: value' lines, list of row dicts)."""
    meta, lines = {}, []
    with open(path, newline="") as f:
        for line in f:
            if line.startswith("#"):
                body = line[1:].strip()
                key, sep, value = body.partition(":")
                if sep:
                    meta.setdefault(key.strip(), value.strip())
            elif line.strip():
                lines.append(line)
    rows = list(csv.DictReader(lines))
    return meta, rows


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def save(fig, png, svg):
    for path, fmt in ((png, "png"), (svg, "svg")):
        # the temporary name saltus uses, so that a stale one is recognised and removed
        tmp = "%s.tmp-%d@%s" % (path, os.getpid(), socket.gethostname())
        try:
            fig.savefig(tmp, format=fmt, dpi=130, bbox_inches="tight")
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)


def scene_title(meta):
    scene = meta.get("scene", "?").split(" ")[0]
    return scene, meta.get("method", "")


ENGINE_COLOURS = {"saltus": "tab:blue", "bullet": "tab:orange", "mujoco": "tab:green"}


def work_precision(args):
    import matplotlib.pyplot as plt

    meta, rows = read_csv(args.csv)
    scene, method = scene_title(meta)
    series = {}  # engine -> points (a CSV without an engine column is one saltus series)
    for r in rows:
        dt, err, cpu = number(r.get("dt")), number(r.get("error")), number(r.get("cpu_seconds_per_simulated_second"))
        if all(math.isfinite(x) and x > 0 for x in (dt, err, cpu)):
            series.setdefault(r.get("engine") or "saltus", []).append((dt, cpu, err))
    if not series:
        raise SystemExit("charts.py: %s: no row with a positive, finite error and CPU time to plot" % args.csv)
    fig, ax = plt.subplots(figsize=(7, 5))
    colours = ENGINE_COLOURS
    for engine, points in series.items():
        points.sort(key=lambda p: p[1])
        ax.loglog([p[1] for p in points], [p[2] for p in points], "o-", color=colours.get(engine), label=engine)
        for dt, cpu, err in points:
            ax.annotate("dt=%g" % dt, (cpu, err), textcoords="offset points", xytext=(6, 4), fontsize=8)
    if len(series) > 1:
        ax.legend(fontsize=8)
    ax.set_xlabel("CPU seconds per simulated second")
    ax.set_ylabel("error")
    ax.grid(True, which="both", alpha=0.3)
    title = "\n".join(textwrap.wrap("%s: work-precision (%s)" % (scene, method), 110))
    error = meta.get("error")
    if error:
        title += "\n" + "\n".join(textwrap.wrap("error: " + error, 90))
    ax.set_title(title, fontsize=9)
    save(fig, args.png, args.svg)


OUTCOME_COLOURS = {
    "ok": "#4caf50",
    "energy_gain": "#ff9800",
    "drift": "#00acc1",
    "penetration": "#9c27b0",
    "lcp_failure": "#e53935",
    "nan": "#212121",
    "error": "#9e9e9e",
    "solver_fallback": "#fdd835",
}


def stability(args):
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    meta, rows = read_csv(args.csv)
    if not rows:
        raise SystemExit("charts.py: %s: no rows" % args.csv)
    scene, method = scene_title(meta)
    # the grid's parameter axes present, in order: the first is the y axis, the second the panels
    present_axes = [name for name in ("friction", "restitution", "mass_ratio") if any(r.get(name) for r in rows)]
    dts = sorted({number(r["dt"]) for r in rows})
    y_name = present_axes[0] if present_axes else None
    panel_name = present_axes[1] if len(present_axes) > 1 else None
    ys = sorted({number(r[y_name]) for r in rows}) if y_name else [0.0]
    values = sorted({number(r[panel_name]) for r in rows}) if panel_name else [None]
    engines = sorted({r.get("engine") or "" for r in rows}, key=lambda e: (e != "saltus", e))
    panels = [(e, v) for e in engines for v in values]

    fig, axes = plt.subplots(1, len(panels), figsize=(1.1 + 0.9 * len(dts) * len(panels), 1.6 + 0.55 * len(ys)),
                             squeeze=False)
    for ax, (engine, panel) in zip(axes[0], panels):
        for r in rows:
            if (r.get("engine") or "") != engine:
                continue
            if panel is not None and number(r[panel_name]) != panel:
                continue
            x = dts.index(number(r["dt"]))
            y = ys.index(number(r[y_name])) if y_name else 0
            outcome = r.get("outcome", "")
            ax.add_patch(plt.Rectangle((x - 0.5, y - 0.5), 1, 1, color=OUTCOME_COLOURS.get(outcome, "#ffffff"),
                                       ec="white", lw=1.5))
            if outcome != "ok":
                ax.text(x, y, outcome.replace("_", "\n"), ha="center", va="center", fontsize=6,
                        color="white" if outcome in ("nan", "lcp_failure", "penetration") else "black")
        ax.set_xlim(-0.5, len(dts) - 0.5)
        ax.set_ylim(-0.5, len(ys) - 0.5)
        ax.set_xticks(range(len(dts)))
        ax.set_xticklabels(["%g" % d for d in dts], rotation=45, fontsize=8)
        ax.set_yticks(range(len(ys)))
        ax.set_yticklabels(["%g" % y for y in ys] if y_name else [""], fontsize=8)
        ax.set_xlabel("dt [s]")
        if y_name:
            ax.set_ylabel(y_name)
        title = [engine] if engine else []
        if panel is not None:
            title.append("%s = %g" % (panel_name, panel))
        if title:
            ax.set_title(", ".join(title), fontsize=9)
        ax.set_aspect("auto")
    present = [o for o in OUTCOME_COLOURS if any(r.get("outcome") == o for r in rows)]
    # the title wrapped to the figure's width, the legend below it, the panels below both
    lines = textwrap.wrap("%s: stability (%s)" % (scene, method), 60 + 60 * len(panels))
    inches = fig.get_size_inches()[1]
    title_height = (0.2 * len(lines) + 0.1) / inches
    fig.suptitle("\n".join(lines), fontsize=10, y=0.99)
    fig.tight_layout(rect=(0, 0, 1, 1 - title_height - 0.25 / inches))
    fig.legend(handles=[Patch(color=OUTCOME_COLOURS[o], label=o) for o in present], loc="upper center",
               fontsize=8, ncol=len(present), bbox_to_anchor=(0.5, 0.99 - title_height), frameon=False)
    save(fig, args.png, args.svg)


LINESTYLES = ["-", "--", ":", "-."]


def replay_columns(meta, rows):
    coordinates = meta.get("coordinates", "").split()
    engines = meta.get("engines", "").split()
    t = [number(r["t"]) for r in rows]
    return coordinates, engines, t


def replay_title(meta):
    return "%s (%s): replay, dt %s, feedback %s" % (meta.get("problem", "?"), meta.get("method", ""),
                                                    meta.get("dt", "?"), meta.get("feedback", "?"))


def replay_events(ax, meta):
    """Optimised impacts as thin vertical lines."""
    for token in meta.get("events", "").split():
        kind, _, t = token.partition("@")
        if kind.startswith("impact"):
            ax.axvline(number(t), color="0.75", lw=0.6, zorder=0)


def replay_deviation(args):
    import matplotlib.pyplot as plt
    meta, rows = read_csv(args.csv)
    coordinates, engines, t = replay_columns(meta, rows)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    floor = 1e-16  # zero deviations (the initial state) on a log axis
    for e in engines:
        for i, c in enumerate(coordinates):
            pts = [(tk, abs(number(r["%s.dq.%s" % (e, c)]))) for tk, r in zip(t, rows)
                   if not math.isnan(number(r["%s.dq.%s" % (e, c)]))]
            if pts:
                top.plot([p[0] for p in pts], [max(p[1], floor) for p in pts], color=ENGINE_COLOURS.get(e, None),
                         ls=LINESTYLES[i % len(LINESTYLES)], lw=1.0, label="%s %s" % (e, c))
    tol = number(meta.get("tolerance"))
    if not math.isnan(tol):
        top.axhline(tol, color="tab:red", lw=1.0, ls="-.", label="tolerance %g" % tol)
    top.set_yscale("log")
    top.set_ylim(bottom=1e-12)
    top.set_ylabel("|q - q*| [m or rad]")
    top.grid(True, which="both", alpha=0.3)
    top.legend(fontsize=7, ncol=2)
    replay_events(top, meta)
    for i, c in enumerate(coordinates):
        bottom.plot(t, [number(r["opt.q.%s" % c]) for r in rows], color="black", ls=LINESTYLES[i % len(LINESTYLES)],
                    lw=2.2, alpha=0.35, label="optimised %s" % c)
        for e in engines:
            pts = [(tk, number(r["%s.q.%s" % (e, c)])) for tk, r in zip(t, rows)
                   if not math.isnan(number(r["%s.q.%s" % (e, c)]))]
            bottom.plot([p[0] for p in pts], [p[1] for p in pts], color=ENGINE_COLOURS.get(e, None),
                        ls=LINESTYLES[i % len(LINESTYLES)], lw=0.9, label="%s %s" % (e, c))
    bottom.set_xlabel("t [s]")
    bottom.set_ylabel("q [m or rad]")
    bottom.grid(True, alpha=0.3)
    bottom.legend(fontsize=7, ncol=2)
    replay_events(bottom, meta)
    fig.suptitle(replay_title(meta), fontsize=10)
    fig.tight_layout()
    save(fig, args.png, args.svg)


def mesh_times(csv_path):
    """Element boundaries from the h[n,0] values of variables.csv beside the trajectory, or None."""
    path = os.path.join(os.path.dirname(os.path.abspath(csv_path)), "variables.csv")
    if not os.path.exists(path):
        return None
    hs = []
    with open(path) as f:
        for line in f:
            # name,value with the name unquoted (it holds commas: h[1,0]): split at the last comma
            name, _, value = line.strip().rpartition(",")
            if name.startswith("h[") and name.endswith(",0]"):
                hs.append((int(name[2:].split(",")[0]), number(value)))
    if not hs:
        return None
    hs.sort()
    times, t = [0.0], 0.0
    for _, h in hs:
        t += h
        times.append(t)
    return times


def trajectory(args):
    import matplotlib.pyplot as plt

    meta, rows = read_csv(args.csv)
    if not rows:
        raise SystemExit("charts.py: %s: no rows" % args.csv)
    columns = list(rows[0].keys())
    if "t" not in columns:
        raise SystemExit("charts.py: %s: no column 't'" % args.csv)
    t = [number(r["t"]) for r in rows]
    qs = [c for c in columns if c.startswith("q.")]
    vs = [c for c in columns if c.startswith("v.")]
    if not qs:
        raise SystemExit("charts.py: %s: no position column q.<coordinate>" % args.csv)
    contacts = []  # contact names with a normal force column, in column order
    for c in columns:
        if c.startswith("contact.") and c.endswith(".rn"):
            contacts.append(c[len("contact."):-len(".rn")])

    def tangential(name, prefix):
        # .rt, or .rt1/.rt2 for pyramids of 4 or more directions (drawn as two series)
        single = "contact.%s.%s" % (name, prefix)
        if single in columns:
            return [single]
        return [c for c in ("%s1" % single, "%s2" % single) if c in columns]

    mesh = mesh_times(args.csv)
    # Rows that carry a finite force: the collocation points. Mesh-point rows hold no force
    # variable (their columns are 0); they are found from the element boundaries, or else as rows
    # whose force columns are all exactly zero.
    def is_mesh_row(i):
        if steps is None:
            return False
        tol = 1e-9 * max(1.0, abs(steps[-1]))
        return any(abs(t[i] - m) <= tol for m in steps)

    force_cols = [c for name in contacts for c in ["contact.%s.rn" % name] + tangential(name, "rt")]
    method, elements = "", None
    summary_path = os.path.join(os.path.dirname(os.path.abspath(args.csv)), "summary.json")
    if os.path.exists(summary_path):
        import json
        with open(summary_path) as f:
            summary = json.load(f)
        method, elements = summary.get("method", ""), summary.get("N")
    steps = mesh  # first order: every step's boundary; the lines below mark whole elements
    if mesh and isinstance(elements, int) and elements > 0 and (len(mesh) - 1) % elements == 0:
        mesh = mesh[::(len(mesh) - 1) // elements]
    if method == "first-order":
        # backward-Euler steps: every row after the first is a step's end and carries its force
        force_rows = list(range(1, len(rows)))
    elif steps is not None:
        force_rows = [i for i in range(len(rows)) if not is_mesh_row(i)]
    else:
        force_rows = [i for i in range(len(rows)) if any(number(rows[i][c]) != 0 for c in force_cols)]

    panels = 3 if contacts else 2
    fig, axes = plt.subplots(panels, 1, figsize=(7.5, 2.3 * panels + 0.6), sharex=True)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]

    def boundaries(ax):
        if mesh:
            for m in mesh:
                ax.axvline(m, color="0.55", lw=0.6, ls=":", zorder=1)

    ax = axes[0]
    boundaries(ax)
    for k, c in enumerate(qs):
        ax.plot(t, [number(r[c]) for r in rows], ".-", ms=3, lw=1.2, color=colours[k % len(colours)], label=c[2:])
    ax.set_ylabel("position q")
    ax.legend(fontsize=7, loc="best")
    ax.grid(True, axis="y", alpha=0.25)

    ax = axes[1]
    boundaries(ax)
    jumps = [i for i in range(1, len(rows)) if t[i] == t[i - 1]]
    for k, c in enumerate(vs):
        colour = colours[k % len(colours)]
        v = [number(r[c]) for r in rows]
        # One line per stretch between jumps; the jump itself a dashed vertical segment.
        start = 0
        for j in jumps + [len(rows)]:
            ax.plot(t[start:j], v[start:j], ".-", ms=3, lw=1.2, color=colour, label=c[2:] if start == 0 else None)
            start = j
        for j in jumps:
            if v[j] != v[j - 1]:
                ax.plot([t[j], t[j]], [v[j - 1], v[j]], "--", lw=1.0, color=colour)
    ax.set_ylabel("velocity q\u0307")
    if vs:
        ax.legend(fontsize=7, loc="best")
    ax.grid(True, axis="y", alpha=0.25)

    if contacts:
        ax = axes[2]
        boundaries(ax)
        impulses = []  # (t, value, label, colour)
        series = 0
        for name in contacts:
            for c in ["contact.%s.rn" % name] + tangential(name, "rt"):
                colour = colours[series % len(colours)]
                series += 1
                label = "%s %s" % (name, c.rsplit(".", 1)[1])
                ax.plot([t[i] for i in force_rows], [number(rows[i][c]) for i in force_rows], ".-", ms=3, lw=1.2,
                        color=colour, label=label)
                head, _, last = c.rpartition(".")
                pc = head + ".p" + last[1:]  # rn -> pn, rt -> pt, rt1 -> pt1
                if pc not in columns:
                    continue
                values = [number(r[pc]) for r in rows]
                largest = max([abs(x) for x in values if math.isfinite(x)] + [0.0])
                for i, x in enumerate(values):
                    if math.isfinite(x) and abs(x) > max(1e-6, 1e-3 * largest):
                        impulses.append((t[i], x, "%s %s" % (name, pc.rsplit(".", 1)[1]), colour))
        shown = set()
        ax_p = ax.twinx() if impulses else None
        for ti, x, label, colour in impulses:
            ax_p.vlines(ti, 0, x, color=colour, lw=2.0, alpha=0.8)
            ax_p.plot([ti], [x], "D", color=colour, ms=5, label=None if label in shown else label + " (impulse)")
            shown.add(label)
        handles_p, labels_p = [], []
        if impulses:
            top = max(abs(x) for _, x, _, _ in impulses)
            ax_p.set_ylim(-1.15 * top, 1.15 * top)
            ax_p.axhline(0, color="0.3", lw=0.5)
            ax_p.set_ylabel("impulse [N s]")
            handles_p, labels_p = ax_p.get_legend_handles_labels()
        ax.set_ylabel("force [N]")
        handles, labels = ax.get_legend_handles_labels()
        ax.legend(handles + handles_p, labels + labels_p, fontsize=7, loc="best")
        ax.grid(True, axis="y", alpha=0.25)

    axes[-1].set_xlabel("t [s]")
    name = os.path.basename(os.path.dirname(os.path.abspath(args.csv)))
    title = args.title or name
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    save(fig, args.png, args.svg)


def replay_energy(args):
    import matplotlib.pyplot as plt
    meta, rows = read_csv(args.csv)
    _, engines, t = replay_columns(meta, rows)
    fig, ax = plt.subplots(figsize=(7.5, 4))
    ax.plot(t, [number(r["opt.energy"]) for r in rows], color="black", lw=2.2, alpha=0.35, label="optimised")
    for e in engines:
        pts = [(tk, number(r["%s.energy" % e])) for tk, r in zip(t, rows) if not math.isnan(number(r["%s.energy" % e]))]
        ax.plot([p[0] for p in pts], [p[1] for p in pts], color=ENGINE_COLOURS.get(e, None), lw=1.0, label=e)
    replay_events(ax, meta)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("kinetic + potential energy [J]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(replay_title(meta), fontsize=10)
    fig.tight_layout()
    save(fig, args.png, args.svg)


SWEEP_METRICS = {
    "time": ("wall_seconds", "solve time [s] (both stages, all attempts)", "paper Fig. 6"),
    "error": ("mean_local_error", "mean local error (relative to the largest state magnitude)", "paper Fig. 7"),
    "cost": ("objective", "cost", "paper Fig. 8"),
}


def sweep_chart(metric, args):
    """Per cell (problem and parameter values) and method (with its variant), over the successful solves: the range
    (thin line), the interquartile range (thick line), the mean (circle, the paper's marker) and
    the median (tick), in the style of the paper's Figs. 6-8. Cost is normalised per case (problem, parameters, seed) by the lowest cost
    any method reached there, as in Fig. 8, when there are several methods and every cost is
    positive; otherwise it is drawn as it is."""
    import json

    import matplotlib.pyplot as plt
    import numpy as np

    key, label, figure = SWEEP_METRICS[metric]
    with open(args.csv) as f:
        summary = json.load(f)
    records = [r for r in summary.get("records", []) if r.get("success")]
    every = summary.get("records", [])
    if not every:
        raise SystemExit("charts.py: %s: no records" % args.csv)

    def case_of(r):
        params = ", ".join("%s=%g" % (k, v) for k, v in sorted(r["set"].items()))
        return r["problem_name"] + (" (" + params + ")" if params else "")

    def series_of(r):  # the method, and the spec's variant when it has them
        return r["method"] + (" [" + r["variant"] + "]" if r.get("variant") else "")

    cases = []
    for r in every:
        c = case_of(r)
        if c not in cases:
            cases.append(c)
    methods = []
    for r in every:
        if series_of(r) not in methods:
            methods.append(series_of(r))
    values = {}
    normalised = False
    if metric == "cost":
        best = {}
        for r in records:
            k = (case_of(r), r["seed"])
            best[k] = min(best.get(k, math.inf), r[key])
        normalised = len(methods) > 1 and records and all(r[key] > 0 for r in records)
        for r in records:
            v = r[key] / best[(case_of(r), r["seed"])] if normalised else r[key]
            values.setdefault((case_of(r), series_of(r)), []).append(v)
        if normalised:
            label = "cost / lowest cost of any method on the same case"
    else:
        for r in records:
            values.setdefault((case_of(r), series_of(r)), []).append(r[key])

    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    fig, ax = plt.subplots(figsize=(8, 1.2 + 0.45 * len(cases) * max(1, len(methods)) ** 0.5))
    spread = 0.6 / max(1, len(methods))
    positive = all(v > 0 for vs in values.values() for v in vs)
    for mi, m in enumerate(methods):
        for ci, c in enumerate(cases):
            vs = values.get((c, m))
            y = ci + (mi - (len(methods) - 1) / 2) * spread
            if not vs:
                ax.plot([], [])
                ax.annotate("no success", (0, y), xycoords=("axes fraction", "data"), fontsize=7, color=colours[mi % 10],
                            va="center", xytext=(4, 0), textcoords="offset points")
                continue
            lo, q1, med, q3, hi = np.percentile(vs, [0, 25, 50, 75, 100])
            ax.plot([lo, hi], [y, y], "-", color=colours[mi % 10], linewidth=1)
            ax.plot([q1, q3], [y, y], "-", color=colours[mi % 10], linewidth=5, alpha=0.6)
            ax.plot([float(np.mean(vs))], [y], "o", color=colours[mi % 10], markersize=6,
                    label=m if ci == next(i for i, cc in enumerate(cases) if values.get((cc, m))) else None)
            ax.plot([med], [y], "|", color="black", markersize=9, markeredgewidth=1.5)
    ax.set_yticks(range(len(cases)))
    ax.set_yticklabels(["\n".join(textwrap.wrap(c, 40)) for c in cases], fontsize=8)
    ax.invert_yaxis()
    if positive and values and metric != "cost":
        ax.set_xscale("log")
    ax.set_xlabel(label)
    ax.grid(True, axis="x", which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:  # a legend only of the methods with a success
        ax.legend(fontsize=8, loc="best")
    n_ok = len(records)
    ax.set_title("%s over the successful solves (%d of %d);\nmean (circle), median (tick), interquartile range, "
                 "range (as in %s)"
                 % (label.split(" (")[0], n_ok, len(every), figure), fontsize=9)
    save(fig, args.png, args.svg)



KINDS = {"work-precision": work_precision, "stability": stability, "replay-deviation": replay_deviation,
         "replay-energy": replay_energy, "trajectory": trajectory,
         "sweep-time": lambda a: sweep_chart("time", a), "sweep-error": lambda a: sweep_chart("error", a),
         "sweep-cost": lambda a: sweep_chart("cost", a)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="kind", required=True)
    for name in KINDS:
        p = sub.add_parser(name)
        p.add_argument("csv")
        p.add_argument("--png", required=True)
        p.add_argument("--svg", required=True)
        if name == "trajectory":
            p.add_argument("--title", help="chart title (default: the CSV's directory name)")
    args = parser.parse_args()
    # SIGTERM (saltus stopping its children) unwinds like Ctrl-C, so save() removes its temporary
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    try:
        KINDS[args.kind](args)
    except SystemExit:
        raise
    except Exception as e:  # a short message instead of a traceback
        print("charts.py %s: %s: %s" % (args.kind, type(e).__name__, e), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
