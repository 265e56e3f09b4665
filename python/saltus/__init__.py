"""Saltus: rigid multibody systems with impacts and friction.

The C++ library's dynamics kernels, scenes, time-stepper and (in later releases of this module)
trajectory optimisation, on NumPy float64 arrays. Units are SI: metres, radians, seconds,
kilograms, newtons.

    import numpy as np, saltus
    m = saltus.Model.from_urdf("models/benchmark/iiwa.urdf", base="fixed")
    tau = saltus.rnea(m, q, v, a)
    r = saltus.simulate("ball_drop", dt=1e-3, duration=1.0, set={"restitution": 0.5})
    r.t, r.q, r.v

Errors: bad input raises ValueError with the command line's located message (file:line:col:
key: ...); a failed time step raises saltus.SimulationError.
"""
from ._saltus import *  # noqa: F401,F403
from ._saltus import __doc__ as _core_doc  # noqa: F401
