"""Formats Google Benchmark JSON from bench/dynamics_bench.cpp as a table against the peers."""
import json
import sys

# Best peer per kernel, µs per call (Pinocchio 3, RBDL 3.3, MuJoCo 2.2.2, DART 6.12, measured on
# this project's 2-core machine: 100k random samples, gravity 0).
PEERS = {
    ("RNEA", "iiwa"): (0.54, "RBDL"), ("RNEA", "hyq"): (0.90, "RBDL"), ("RNEA", "atlas"): (2.78, "RBDL"),
    ("CRBA", "iiwa"): (0.42, "Pinocchio"), ("CRBA", "hyq"): (0.60, "Pinocchio"), ("CRBA", "atlas"): (2.09, "Pinocchio"),
    ("ABA", "iiwa"): (1.35, "RBDL"), ("ABA", "hyq"): (1.98, "RBDL"), ("ABA", "atlas"): (6.21, "RBDL"),
    ("RNEA_AD_Jacobian", "iiwa"): (2.89, "Pinocchio analytic"), ("RNEA_AD_Jacobian", "hyq"): (4.58, "Pinocchio analytic"),
    ("RNEA_AD_Jacobian", "atlas"): (12.8, "Pinocchio analytic"),
    ("ABA_AD_Jacobian", "iiwa"): (3.92, "Pinocchio analytic"), ("ABA_AD_Jacobian", "hyq"): (6.39, "Pinocchio analytic"),
    ("ABA_AD_Jacobian", "atlas"): (25.2, "Pinocchio analytic"),
}

def main(path):
    with open(path) as f:
        runs = json.load(f)["benchmarks"]
    us = {}
    for r in runs:
        if r.get("aggregate_name", "median") != "median":
            continue
        kernel, model = r["run_name"].removeprefix("BM_").split("/")[:2]
        scale = {"us": 1.0, "ns": 1e-3, "ms": 1e3}[r["time_unit"]]
        us[(kernel, model)] = r["cpu_time"] * scale
    print(f"{'kernel':<18}{'model':<7}{'Saltus µs':>11}{'best peer µs':>14}  {'peer':<20}{'ratio':>7}")
    for (kernel, model), t in us.items():
        peer, who = PEERS.get((kernel, model), (float("nan"), "-"))
        print(f"{kernel:<18}{model:<7}{t:>11.3f}{peer:>14.2f}  {who:<20}{t / peer:>7.2f}")
    print()
    for model in ("iiwa", "hyq", "atlas"):
        if ("RNEA_AD_Jacobian", model) in us and ("RNEA", model) in us:
            ratio = us[("RNEA_AD_Jacobian", model)] / us[("RNEA", model)]
            print(f"AD Jacobian of RNEA / RNEA on {model}: {ratio:.1f}x (target <= 10x)")

if __name__ == "__main__":
    main(sys.argv[1])
