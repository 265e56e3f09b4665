"""Type stubs of the module saltus (python/*.cpp), checked against the compiled module by tests/python/test_stubs.py."""
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]
ArrayLike = npt.ArrayLike
Parameters = Dict[str, float]

class SimulationError(RuntimeError): ...
class SolveError(RuntimeError): ...

class Model:
    @staticmethod
    def from_urdf(path: str, base: str = "fixed") -> "Model": ...
    @staticmethod
    def builtin(name: str, base: str = "fixed") -> "Model": ...
    @staticmethod
    def from_scene(scene: str, set: Parameters = ...) -> "Model": ...
    name: str
    nq: int
    nv: int
    coordinate_names: List[str]
    position_names: List[str]
    body_names: List[str]
    total_mass: float
    gravity: Array

def rnea(model: Model, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> Array: ...
def crba(model: Model, q: ArrayLike) -> Array: ...
def aba(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike) -> Array: ...
def nonlinear_effects(model: Model, q: ArrayLike, v: ArrayLike) -> Array: ...
def forward_kinematics(model: Model, q: ArrayLike) -> List[Array]: ...
def point_jacobian(model: Model, q: ArrayLike, body: str, point: ArrayLike = ...) -> Array: ...
def kinetic_energy(model: Model, q: ArrayLike, v: ArrayLike) -> float: ...
def potential_energy(model: Model, q: ArrayLike) -> float: ...
def rnea_derivatives(model: Model, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> Tuple[Array, Array, Array]: ...
def aba_derivatives(model: Model, q: ArrayLike, v: ArrayLike, tau: ArrayLike) -> Tuple[Array, Array, Array]: ...

class Scene:
    name: str
    duration: float
    parameters: Parameters
    coordinate_names: List[str]
    position_names: List[str]
    contact_names: List[str]
    surface_names: List[str]
    q0: Array
    v0: Array

def load_scene(name: str, set: Parameters = ...) -> Scene: ...

class Stepper:
    def __init__(self, scene: Union[Scene, str], *, dt: float = 1e-3, theta: float = 1.0, solver: str = "lemke",
                 set: Parameters = ...) -> None: ...
    def step(self, steps: int = 1) -> None: ...
    def set_input(self, tau: ArrayLike) -> None: ...
    def reset(self, q: ArrayLike, v: ArrayLike, t: float = 0.0) -> None: ...
    def energy(self) -> float: ...
    t: float
    q: Array
    v: Array
    scene: Scene
    contacts: Dict[str, Dict[str, Any]]
    stats: Dict[str, float]

class Simulation:
    t: Array
    q: Array
    v: Array
    coordinate_names: List[str]
    position_names: List[str]
    contacts: Dict[str, Dict[str, Array]]
    stats: Dict[str, float]
    energy_start: float
    energy_end: float
    wall_seconds: float
    def save(self, path: str) -> None: ...

def simulate(scene: Union[Scene, str], *, dt: float = 1e-3, duration: float = 0.0, theta: float = 1.0,
             solver: str = "lemke", set: Parameters = ..., every: int = 1) -> Simulation: ...

class Problem:
    name: str
    description: str
    N: int
    P: int
    h_max: float
    parameters: Parameters
    scene: Scene
    inputs: List[str]
    input_lower: Array
    input_upper: Array

def load_problem(name: str, set: Parameters = ...) -> Problem: ...

class Solution:
    feasible: bool
    converged: bool
    status: str
    summary: Dict[str, Any]
    problem: Problem
    t: Array
    q: Array
    v: Array
    u: Array
    mesh_times: List[float]
    contacts: Dict[str, Dict[str, Array]]
    def at(self, t: float, side: str = "after") -> Dict[str, Array]: ...
    def save(self, dir: str) -> None: ...

def optimize(problem: Union[Problem, str], *, method: str = "impulsive", N: Optional[int] = None,
             P: Optional[int] = None, seed: Optional[int] = None, seed_kind: Optional[str] = None,
             seed_from: str = "", seed_method: Optional[str] = None, seed_inputs: str = "", seed_scale: Optional[float] = None, restarts: Optional[int] = None,
             resimulations: Optional[int] = None, resimulation_tracking: Optional[float] = None,
             hessian: Optional[str] = None, feasibility_hessian: Optional[str] = None,
             ipopt: Dict[str, str] = ..., print_level: int = 0,
             tighten_within: Optional[float] = None, tighten_factor: Optional[float] = None,
             feasibility_repeats: Optional[int] = None,
             task_max_iter: Optional[int] = None,
             penalty_iterations: Optional[int] = None, task_penalty: Optional[bool] = None,
             task_ipopt: Dict[str, str] = ..., hints: bool = True, continuation: bool = True,
             require_feasible: bool = False,
             set: Parameters = ...) -> Solution: ...

def replay(solution: str, *, out: str = "", engine: str = "saltus", dt: float = 1e-4, theta: float = 0.5,
           feedback: str = "none", kp: float = 100.0, kd: float = 20.0, restart: str = "none", tolerance: float = 0.0,
           charts: bool = True, allow_changed_problem: bool = False) -> Dict[str, Any]: ...

def render(trajectory: str, *, video: str = "", frames: str = "", scene: Union[Scene, str, None] = None,
           set: Parameters = ..., fps: float = 60.0, speed: float = 1.0, width: int = 1280, height: int = 720,
           antialias: int = 1, camera: str = "auto", allow_changed_problem: bool = False) -> int: ...

class FrameRenderer:
    def __init__(self, trajectory: str, *, scene: Union[Scene, str, None] = None, set: Parameters = ...,
                 fps: float = 60.0, speed: float = 1.0, width: int = 640, height: int = 360, antialias: int = 1,
                 camera: str = "auto") -> None: ...
    frames: int
    def time(self, frame: int) -> float: ...
    def draw(self, frame: int) -> npt.NDArray[np.uint8]: ...
