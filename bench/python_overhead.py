"""Overhead of a call from Python over the C++ kernel: RNEA, CRBA and ABA on the KUKA iiwa (7 DoF,
fixed base) through saltus (best of 7 timeit rounds of 20000 calls, random states, arrays made
once) against the same kernels in Google Benchmark (build/bench/saltus_bench). Prints a table
and exits 1 when RNEA's overhead exceeds the target, 1 µs.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [build/bench/saltus_bench]
"""
import json
import pathlib
import subprocess
import sys
import timeit

import numpy as np
import saltus

ROOT = pathlib.Path(__file__).resolve().parents[1]
BENCH = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "build/bench/saltus_bench")
TARGET_US = 1.0

model = saltus.Model.from_urdf(str(ROOT / "models/benchmark/iiwa.urdf"), base="fixed")
rng = np.random.default_rng(1)
q, v, a = (rng.uniform(-1, 1, model.nv) for _ in range(3))
calls = {
    "RNEA": lambda: saltus.rnea(model, q, v, a),
    "CRBA": lambda: saltus.crba(model, q),
    "ABA": lambda: saltus.aba(model, q, v, a),
}
python_us = {name: min(timeit.repeat(f, number=20000, repeat=7)) / 20000 * 1e6 for name, f in calls.items()}

out = subprocess.run([BENCH, "--benchmark_filter=BM_(RNEA|CRBA|ABA)/iiwa$", "--benchmark_format=json",
                      "--benchmark_min_time=0.2"], check=True, capture_output=True, text=True).stdout
cpp_us = {}
for b in json.loads(out)["benchmarks"]:
    name = b["name"].split("/")[0][3:]
    cpp_us[name] = b["real_time"] * {"us": 1, "ns": 1e-3, "ms": 1e3}[b["time_unit"]]

print("kernel,python_us,cpp_us,overhead_us")
for name in calls:
    print(f"{name},{python_us[name]:.3f},{cpp_us[name]:.3f},{python_us[name] - cpp_us[name]:.3f}")
sys.exit(0 if python_us["RNEA"] - cpp_us["RNEA"] <= TARGET_US else 1)
