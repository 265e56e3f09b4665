#!/usr/bin/env python3
"""Charts of `saltus bench` results (python3 + matplotlib, Agg backend).

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

The CSV files start with '# key: value' comment lines (scene, method, error, ...) that give the
titles. Each image is written to a temporary name beside the target and renamed into place.
Nothing is printed on standard output; errors go to standard error with exit status 1.
"""
import argparse
import csv
import math
import os
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
        tmp = "%s.tmp-%d" % (path, os.getpid())
        try:
            fig.savefig(tmp, format=fmt, dpi=130, bbox_inches="tight")
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)


def scene_title(meta):
    scene = meta.get("scene", "?").split(" ")[0]
    return scene, meta.get("method", "")


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
    colours = {"saltus": "tab:blue", "bullet": "tab:orange"}
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
    title = "%s: work-precision (%s)" % (scene, method)
    error = meta.get("error")
    if error:
        title += "\n" + "\n".join(textwrap.wrap("error: " + error, 90))
    ax.set_title(title, fontsize=9)
    save(fig, args.png, args.svg)


OUTCOME_COLOURS = {
    "ok": "#4caf50",
    "energy_gain": "#ff9800",
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
    has_mu = any(r.get("friction") for r in rows)
    has_e = any(r.get("restitution") for r in rows)
    dts = sorted({number(r["dt"]) for r in rows})
    if has_mu:
        y_name, panel_name = "friction", ("restitution" if has_e else None)
    elif has_e:
        y_name, panel_name = "restitution", None
    else:
        y_name, panel_name = None, None
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
    fig.suptitle("%s: stability (%s)" % (scene, method), fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.9))
    fig.legend(handles=[Patch(color=OUTCOME_COLOURS[o], label=o) for o in present], loc="upper center",
               fontsize=8, ncol=len(present), bbox_to_anchor=(0.5, 0.955), frameon=False)
    save(fig, args.png, args.svg)


ENGINE_COLOURS = {"saltus": "tab:blue", "bullet": "tab:orange"}
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


KINDS = {"work-precision": work_precision, "stability": stability, "replay-deviation": replay_deviation,
         "replay-energy": replay_energy}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="kind", required=True)
    for name in KINDS:
        p = sub.add_parser(name)
        p.add_argument("csv")
        p.add_argument("--png", required=True)
        p.add_argument("--svg", required=True)
    args = parser.parse_args()
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
