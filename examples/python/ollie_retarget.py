"""A seed for the full-body Ollie (`ollie`) from a solution of the point-mass one (`ollie_simple`):
the board and every contact variable the two problems share (wheels, tail, the feet on the deck:
reactions, impulses, the free points, friction and slack variables) are copied by name, and the
rider is fitted to the point masses at every collocation point by inverse kinematics: its feet
(the shank tips) on the point masses, its centre of mass over their mean as when standing (its
height weighted lightly: the legs' reach decides it), the torso upright, within the hip and knee
stops (damped Gauss-Newton, each point's fit starting from the last). Velocities, accelerations and
velocity jumps follow through the same fit's Jacobian (least squares). The inputs are the rider's
inverse dynamics with each foot bearing the force its point mass bore, clipped to their bounds:
the joints' torques, and the assist on the rider's base where the problem allows one (`--set
assist=A`; none in the paper's problem).

The result is an earlier solution of `ollie` on disk (variables.csv), the paper's strategy 4
with a solution of the simpler model as the earlier one:

    PYTHONPATH=build/python /usr/bin/python3 examples/python/ollie_retarget.py SIMPLE_DIR --out SEED_DIR [--set assist=A]
    saltus optimize ollie --seed-from SEED_DIR --seed-scale 0 --no-hints --feasibility-hessian limited-memory \
      --ipopt mu_strategy=monotone [--set assist=A] --out DIR

The fit is kinematic: where the point masses move apart faster than legs can follow, or hold
themselves up by their forces where a rider would have to jump, the seed is not dynamically
consistent and the optimiser has to make it so.
"""
import argparse
import os
import re
import shutil
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
import saltus

SCENE = "skateboard_rider"
URDF = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "models", "biped", "biped.urdf")
RIDER = ["rider_x", "rider_z", "rider_theta", "hip_l", "knee_l", "hip_r", "knee_r"]
SHANKS = ("shank_r", "shank_l")  # the back foot's, the front foot's (scene skateboard_rider)
# Weights of the fit's residuals against the feet's 1: the centre of mass along x and z, the
# torso's angle, each joint's change from the previous point.
W_COM_X, W_COM_Z, W_TORSO, W_REST = 0.3, 0.05, 0.05, 1e-3
DAMPING = 0.05  # of the rates' least squares [m per rad]
FEET_FIRST = 10  # the feet's weight in the rates, times the fit's
MAX_STEP = 0.05  # [m or rad] per Gauss-Newton iteration


def read_variables(path):
    header, values = [], {}
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                header.append(line)
            elif not line.startswith("name,"):
                name, value = line.rstrip("\n").rsplit(",", 1)
                values[name] = float(value)
    return header, values


def template(problem, parameters):
    """Every variable of `problem` by name, at its null seed (a zero-iteration solve, saved)."""
    solution = saltus.optimize(problem, seed_kind="null", hints=False, restarts=0, ipopt={"max_iter": "0"},
                               task_max_iter=0, tighten_within=0, print_level=0, set=parameters)
    folder = tempfile.mkdtemp(prefix="saltus_retarget_")
    try:
        solution.save(folder)
        return read_variables(os.path.join(folder, "variables.csv"))
    finally:
        shutil.rmtree(folder)


def read_urdf(urdf):
    """From the rider's URDF: each link's mass [kg] and centre of mass in its frame [m], each
    joint's stops [rad] and each foot's point in its shank's frame [m] (its fixed joint)."""
    root = ET.parse(urdf).getroot()
    xyz = lambda element: np.array([float(c) for c in element.find("origin").get("xyz").split()])
    masses, stops, tips = {}, {}, {}
    for link in root.iter("link"):
        inertial = link.find("inertial")
        if inertial is not None:
            masses[link.get("name")] = (float(inertial.find("mass").get("value")), xyz(inertial))
    for joint in root.iter("joint"):
        limit = joint.find("limit")
        if joint.get("type") == "revolute" and limit is not None:
            stops[joint.get("name")] = (float(limit.get("lower")), float(limit.get("upper")))
        if joint.get("type") == "fixed":
            tips[joint.find("parent").get("link")] = xyz(joint)
    return masses, stops, tips


class Rider:
    def __init__(self, model, urdf):
        self.model = model
        self.names = list(model.coordinate_names)
        self.bodies = list(model.body_names)
        self.cols = [self.names.index(n) for n in RIDER]
        self.masses, stops, tips = read_urdf(urdf)
        self.tips = [(shank, tips[shank]) for shank in SHANKS]
        self.mass = sum(m for m, _ in self.masses.values())
        self.lower = np.full(len(self.names), -np.inf)
        self.upper = np.full(len(self.names), np.inf)
        for joint in RIDER[3:]:
            i = self.names.index(joint)
            self.lower[i], self.upper[i] = stops[joint]

    def points(self, q):
        """The feet and the centre of mass (x, z), and their Jacobians in the rider's coordinates."""
        poses = saltus.forward_kinematics(self.model, q)
        rows = []
        jac = []
        for shank, tip in self.tips:
            T = poses[self.bodies.index(shank)]
            rows.append((T[:3, :3] @ tip + T[:3, 3])[[0, 2]])
            jac.append(saltus.point_jacobian(self.model, q, shank, tip)[[0, 2]][:, self.cols])
        com = np.zeros(3)
        jcom = np.zeros((3, len(self.cols)))
        for body, (m, c) in self.masses.items():
            T = poses[self.bodies.index(body)]
            com += m * (T[:3, :3] @ c + T[:3, 3])
            jcom += m * saltus.point_jacobian(self.model, q, body, c)[:, self.cols]
        rows.append((com / self.mass)[[0, 2]])
        jac.append((jcom / self.mass)[[0, 2]])
        return np.concatenate(rows), np.vstack(jac)

    def weights(self):
        return np.array([1, 1, 1, 1, W_COM_X, W_COM_Z])

    def fit(self, q, targets, iterations=200):
        """Gauss-Newton on the weighted feet and centre-of-mass residuals, the torso held upright
        and the joints drawn weakly to where they were, projected into the stops."""
        q = q.copy()
        start = q[self.cols].copy()
        w = self.weights()
        theta = self.names.index("rider_theta")
        for _ in range(iterations):
            x, J = self.points(q)
            r = np.concatenate([w * (x - targets), [W_TORSO * q[theta]], W_REST * (q[self.cols] - start)])
            A = np.vstack([w[:, None] * J, W_TORSO * np.eye(len(self.cols))[[2]], W_REST * np.eye(len(self.cols))])
            step = np.linalg.lstsq(A, -r, rcond=None)[0]
            if np.linalg.norm(step) < 1e-10:
                break
            step *= min(1.0, MAX_STEP / np.abs(step).max())
            q[self.cols] += step
            q = np.clip(q, self.lower, self.upper)
        return q

    def rates(self, q, target_rates):
        """Coordinate rates that move the fitted points at the given rates: damped least squares
        with the feet first (their weight FEET_FIRST times the fit's), so that the centre of mass
        and the torso take what the feet leave; the damping keeps a leg straight or at a stop,
        whose Jacobian is singular, from turning a rate its foot cannot follow into an infinite
        one."""
        _, J = self.points(q)
        w = self.weights() * np.array([FEET_FIRST] * 4 + [1, 1])
        n = len(self.cols)
        A = np.vstack([w[:, None] * J, W_TORSO * np.eye(n)[[2]], DAMPING * np.eye(n)])
        b = np.concatenate([w * target_rates, [0.0], np.zeros(n)])
        return np.linalg.lstsq(A, b, rcond=None)[0]


def inverse_dynamics(model, problem, q, v, a, foot_forces, tips):
    """The rider's inputs that move it at (q, v, a) under the feet's forces (world x, z) [N]: its
    generalized forces by inverse dynamics (RBDA 5.3), tau = M a + C v + g - sum_i J_i^T f_i, on
    each input's coordinate, clipped to the input's bounds."""
    tau = saltus.rnea(model, q, v, a)
    for (shank, tip), f in zip(tips, foot_forces):
        tau -= saltus.point_jacobian(model, q, shank, tip)[[0, 2]].T @ f
    names = list(model.coordinate_names)
    u = np.array([tau[names.index(n)] for n in problem.inputs])
    return np.clip(u, problem.input_lower, problem.input_upper)


def retarget(simple_dir, out_dir, problem_name="ollie", parameters=None):
    """Writes out_dir/variables.csv, a seed of `problem_name` (its parameters overridden by
    `parameters`) from the ollie_simple solution in simple_dir; returns the largest distance of a
    fitted foot from its point mass [m] and the number of variables copied by name."""
    simple_header, simple = read_variables(os.path.join(simple_dir, "variables.csv"))
    source = next(line.split(":", 1)[1].strip() for line in simple_header if line.startswith("# source:"))
    simple_problem = saltus.load_problem(source.removeprefix("builtin:"))
    simple_names = list(simple_problem.scene.coordinate_names)
    header, full = template(problem_name, parameters or {})
    problem = saltus.load_problem(problem_name, parameters or {})
    model = saltus.Model.from_scene(SCENE)
    rider = Rider(model, URDF)
    names = rider.names
    nq = len(names)
    board = [names.index(n) for n in ("board_x", "board_z", "board_theta")]
    simple_board = [simple_names.index(n) for n in ("board_x", "board_z", "board_theta")]
    point = {side: [simple_names.index(f"{side}_x"), simple_names.index(f"{side}_z")] for side in ("back", "front")}

    # Shared variables by name: element lengths and every variable of the shared contacts.
    shared = 0
    for name in full:
        if name in simple and not re.match(r"(q|v|a|dv|u)\[", name):
            full[name] = simple[name]
            shared += 1

    def simple_vec(kind, key):
        return np.array([simple[f"{kind}[{key}].{i}"] for i in range(len(simple_names))])

    def feet(x):
        return x[point["back"]], x[point["front"]]

    def put(kind, key, value):
        for i in range(nq):
            full[f"{kind}[{key}].{i}"] = value[i]

    mass = simple_problem.parameters["rider_mass"]
    gravity = np.array(model.gravity)[[0, 2]]
    q0 = np.array(problem.scene.q0, dtype=float)
    back0, front0 = feet(simple_vec("q", "1,0"))
    offset = rider.points(q0)[0][4:] - 0.5 * (back0 + front0)

    def targets(x, with_offset):
        back, front = feet(x)
        return np.concatenate([back, front, 0.5 * (back + front) + (offset if with_offset else 0)])

    keys = sorted({m.group(1) for m in (re.match(r"q\[(\d+,\d+)\]", n) for n in full) if m},
                  key=lambda k: tuple(int(c) for c in k.split(",")))
    q = q0.copy()
    worst = 0.0
    for key in keys:
        x = simple_vec("q", key)
        q[board] = x[simple_board]
        q = rider.fit(q, targets(x, True))
        worst = max(worst, np.abs(rider.points(q)[0][:4] - targets(x, True)[:4]).max())
        put("q", key, q)
        # Rates (v, a, dv) through the fit's Jacobian at q.
        rates = {}
        for kind in ("v", "a", "dv"):
            if f"{kind}[{key}].0" not in simple:
                continue
            s = simple_vec(kind, key)
            rates[kind] = np.zeros(nq)
            rates[kind][board] = s[simple_board]
            rates[kind][rider.cols] = rider.rates(q, targets(s, False))
            put(kind, key, rates[kind])
        if "a" in rates:
            # The inputs by inverse dynamics, each foot bearing the force its point mass did:
            # m (a - g) - u.
            u_simple = dict(zip(simple_problem.inputs, (simple[f"u[{key}].{i}"] for i in range(len(simple_problem.inputs)))))
            a_simple = simple_vec("a", key)
            forces = [mass * (a_simple[point[side]] - gravity) - np.array([u_simple[f"{side}_x"], u_simple[f"{side}_z"]])
                      for side in ("back", "front")]
            u = inverse_dynamics(model, problem, q, rates["v"], rates["a"], forces, rider.tips)
            for i, value in enumerate(u):
                full[f"u[{key}].{i}"] = value

    os.makedirs(out_dir, exist_ok=True)
    tmp = os.path.join(out_dir, "variables.csv.tmp")
    with open(tmp, "w") as f:
        f.writelines(header)
        f.write("name,value\n")
        for name, value in full.items():
            f.write(f"{name},{value!r}\n")
    os.replace(tmp, os.path.join(out_dir, "variables.csv"))
    return worst, shared


def assignment(text):
    name, equals, value = text.partition("=")
    try:
        if not name or not equals:
            raise ValueError
        return name, float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected NAME=NUMBER, got '{text}'") from None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("simple", help="an ollie_simple solution (its --out directory)")
    ap.add_argument("--out", required=True, help="directory for the seed (variables.csv)")
    ap.add_argument("--problem", default="ollie", help="the full-body problem (name or file; scene skateboard_rider)")
    ap.add_argument("--set", action="append", default=[], type=assignment, metavar="NAME=VALUE",
                    help="override a problem parameter (as saltus optimize --set)")
    args = ap.parse_args()
    worst, shared = retarget(args.simple, args.out, args.problem, dict(args.set))
    print(f"{args.out}/variables.csv: {shared} variables copied from {args.simple}; "
          f"the feet off the point masses by up to {worst:.3f} m")


if __name__ == "__main__":
    sys.exit(main())
