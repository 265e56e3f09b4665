"""The paper's Fig. 3 in Python: a 1 kg point mass dropped from 0.1 m with restitution e = 0.5,
optimised by the impulsive method; its height, velocity (the jump at the impact) and impulse.
Shield, Johnson & Patel, "Contact-implicit direct collocation with a discontinuous velocity
state", IEEE Transactions on Robotics, 2023.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/drop_figure.py drop.png
"""
import sys

import matplotlib.pyplot as plt
import saltus

s = saltus.optimize("point_mass_drop", set={"restitution": 0.5}, require_feasible=True)
fig, (z, v, p) = plt.subplots(3, 1, sharex=True, figsize=(5, 6))
z.plot(s.t, s.q[:, 0]), z.set_ylabel("z [m]")
v.plot(s.t, s.v[:, 0]), v.set_ylabel("ż [m/s]")
p.stem(s.t, s.contacts["ball"]["pn"]), p.set_ylabel("impulse [N s]"), p.set_xlabel("t [s]")
fig.savefig(sys.argv[1] if len(sys.argv) > 1 else "drop.png", dpi=130, bbox_inches="tight")
