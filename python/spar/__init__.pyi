"""spar: symbolic worst-case uncertainty analysis of robot task plans, from Python.

Expressions, sound bounds, robot forward and inverse kinematics, uncertain poses and the SPAR
planner. Errors are spar.Error and its subclasses, with the engine's messages::

    import spar
    f = spar.Expr("x^2 - y")
    r = spar.bound(f, {"x": (-1, 2), "y": (0, 1)}, tolerance=1e-6)   # r.lo, r.hi, r.argmax
    pose = spar.fk("puma560", [0, 0.7, 0.9, 0, -0.5, 0])              # 4x4 NumPy array
    solutions = spar.ik("puma560", pose).solutions                    # all eight, labelled
    report = spar.plan("examples/peg_block_face_down.yaml")           # `spar plan --json`

Long calls (plan, bound, scenario loading) release the GIL, so a thread pool runs them in
parallel; spar.dask spreads batches over a Dask cluster.
"""
# The typed interface of the `spar` package (PEP 561), installed beside it. The docstrings of the
# compiled part (spar._spar) are taken from this file at build time (python/docstrings.py); the
# pure-Python functions keep theirs in __init__.py. python/tests/test_stubs.py checks this file
# against the built module: the same names, parameters and defaults.
import os
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, Literal, Union

import numpy as np
import numpy.typing as npt

__version__: str

Matrix4 = npt.NDArray[np.float64]
ScenarioSource = Union[str, os.PathLike[str], bytes, Mapping[str, Any], "Scenario"]
Constraint = Union[str, tuple[Union["Expr", str], str], Mapping[str, str]]


class Error(Exception):
    """Base of every error spar raises, with the engine's message.

    A message names what is wrong and where: file:line:col for a scenario or domain file, the
    column of a bad token in an expression. Catch spar.Error for all of them, or a subclass
    (spar.ScenarioError, spar.BoundsError, ...) for one kind::

        try:
            spar.plan("my_task.yaml")
        except spar.ScenarioError as error:
            print(error)   # my_task.yaml:12:5: unknown key 'uncertanty' ...
    """


class BoundsError(Error): ...
class ShostakError(BoundsError): ...
class NumberError(Error): ...
class SymbolicError(Error): ...
class KinematicsError(Error): ...
class GeometryError(Error): ...
class CmsError(Error): ...
class ScenarioError(Error): ...
class DomainError(Error): ...
class PlanError(Error): ...
class QrError(Error): ...
class ReportError(Error): ...
class SensingError(Error): ...


class Expr:
    """A symbolic expression over named real variables.

    Parsed from infix text: numbers, variables, + - * / ^, parentheses and the functions sin,
    cos, tan, asin, acos, atan, atan2, sqrt, exp, log, abs, min, max and the constant pi.
    str() prints it back in a
    form that parses to the same expression; pickling keeps its text::

        f = spar.Expr("x*sin(y)")
        f.variables                      # ['x', 'y']
        f.evaluate({"x": 2, "y": 0.5})   # 0.958...
        str(f.diff("y"))                 # 'x*cos(y)'
    """

    def __init__(self, text: str) -> None:
        """Parses `text`; raises spar.SymbolicError naming the offending token and its column."""

    @staticmethod
    def parse(text: str) -> Expr:
        """The same as Expr(text)."""

    def simplify(self) -> Expr:
        """An equal expression in simplified form: constants folded, like terms collected,
        sin(x)^2 + cos(x)^2 -> 1::

            str(spar.Expr("sin(x)^2+cos(x)^2").simplify())   # '1'
        """

    def diff(self, variable: str) -> Expr:
        """The partial derivative with respect to `variable` (a name; 0 if it does not occur)::

            str(spar.Expr("x^2*y").diff("x"))   # '2*x*y'
        """

    def evaluate(self, values: Mapping[str, float]) -> float:
        """The value at a point: `values` gives every variable's value (raises
        spar.SymbolicError naming a missing one)."""

    @property
    def variables(self) -> list[str]:
        """Names of the free variables, sorted."""

    def __eq__(self, other: object) -> bool: ...


class BoundResult:
    """Sound bounds of an expression over a box: what spar.bound() returns.

    Every value of the expression over the (constrained) box lies in [lo, hi]; inner_lo and
    inner_hi are values it attains, at the points argmin and argmax ({name: value}), so
    lo <= inner_lo <= inner_hi <= hi; both are None when no attained range is known
    (no_inner_range says why). The attributes are the keys of `spar bound --json`
    (as_dict() gives them as a dict)::

        r = spar.bound("x^2 - x", {"x": (0, 1)})
        r.lo, r.hi           # (-0.25, 0.0), up to the tolerance
        r.argmin             # {'x': 0.5}
        r.status             # 'converged'
    """

    @property
    def name(self) -> str | None:
        """The corpus record's name (None for a plain spar.bound() call)."""
    @property
    def lo(self) -> float:
        """Sound lower bound."""
    @property
    def hi(self) -> float:
        """Sound upper bound."""
    @property
    def inner_lo(self) -> float | None:
        """The smallest value found (attained at argmin); None when no attained range is known."""
    @property
    def inner_hi(self) -> float | None:
        """The largest value found (attained at argmax); None when no attained range is known."""
    @property
    def no_inner_range(self) -> str | None:
        """Why inner_lo / inner_hi are None (None when they are known)."""
    @property
    def argmin(self) -> dict[str, float]:
        """Where inner_lo is attained: {variable: value} (empty when there is none)."""
    @property
    def argmax(self) -> dict[str, float]:
        """Where inner_hi is attained: {variable: value} (empty when there is none)."""
    @property
    def status(self) -> Literal["converged", "effort_limit", "unbounded", "infeasible"]:
        """How bounding ended."""
    @property
    def possibly_undefined(self) -> bool:
        """True if the expression may be undefined somewhere in the box (a division by an
        interval holding 0, the log of a negative number)."""
    @property
    def time_limited(self) -> bool:
        """True if max_seconds stopped it (the answer then depends on the machine)."""
    @property
    def relative_gap(self) -> float:
        """The gap between the inner and the outer bounds over the attained width."""
    @property
    def evaluations(self) -> int:
        """Box evaluations spent."""
    @property
    def seconds(self) -> float:
        """Wall-clock time of the bound (varies run to run; the rest is deterministic)."""

    def as_dict(self) -> dict[str, Any]:
        """The attributes as a dict: the keys of `spar bound --json`, in its order."""


class IkSolution:
    """One inverse kinematics solution of spar.ik()."""

    @property
    def configuration(self) -> str:
        """Its label: "run" (Puma, UR: left/right arm, up/down elbow, flip/no-flip wrist),
        "run@q7=35deg" (Panda, q7 sampled), "n1" (numeric solver)."""
    @property
    def q(self) -> npt.NDArray[np.float64]:
        """Joint values, radians (metres for a prismatic joint)."""
    @property
    def within_limits(self) -> bool:
        """True if every joint value lies within the robot's limits."""
    @property
    def singularities(self) -> str:
        """The singularities this solution is at: "none", or e.g. "shoulder+wrist"."""


class IkResult:
    """Every inverse kinematics solution of a pose (spar.ik()), in the robot's order: lun luf
    ldn ldf run ruf rdn rdf for Puma and UR arms. Empty when the pose is out of reach::

        result = spar.ik("puma560", spar.fk("puma560", [0, 0.7, 0.9, 0, -0.5, 0]))
        len(result), result.solved     # (8, True)
        result["lun"].q                # the joint values of one configuration
    """

    @property
    def solved(self) -> bool:
        """True if the pose is within reach (there is at least one solution)."""
    @property
    def singularities(self) -> str:
        """The singularities of any of its solutions: "none", or e.g. "shoulder+wrist"."""
    @property
    def solutions(self) -> list[IkSolution]:
        """The solutions, in the robot's order."""
    def __len__(self) -> int: ...
    def __getitem__(self, configuration: str) -> IkSolution:
        """The solution labelled `configuration` (KeyError if there is none)."""


class UncertainPose:
    """A 4x4 homogeneous transform whose entries are spar.Expr over the pose's uncertainty
    variables (SPAR's "possible pose"): a nominal pose displaced by dx, dy, dz and turned by
    dtheta about z. `variables` maps each variable to its range, ready as the box of
    spar.bound()::

        pose = spar.possible_object_pose(np.eye(4), {"dx": 0.01, "dtheta": 0.05}, tag="peg")
        x = pose[0, 3]                                # an Expr: the x translation
        spar.bound(x, pose.variables)                 # within [-0.01, 0.01]
        pose.evaluate({name: 0 for name in pose.variables})   # the nominal pose (NumPy)
    """

    def entry(self, row: int, column: int) -> Expr:
        """Entry (row, column) as an expression."""
    def __getitem__(self, index: tuple[int, int]) -> Expr: ...
    @property
    def matrix(self) -> list[list[Expr]]:
        """The 16 entries, row by row."""
    @property
    def variables(self) -> dict[str, tuple[float, float]]:
        """Each uncertainty variable's range: {name: (lo, hi)}."""
    def evaluate(self, values: Mapping[str, float]) -> Matrix4:
        """The numeric pose (4x4 NumPy array) at a point: every variable's value."""


class Scenario:
    """A loaded scenario: the objects, their poses and uncertainties, the robot and the goal
    (docs/scenario.md). Made by spar.scenario(); spar.plan() also takes one::

        s = spar.scenario("examples/peg_block_face_down.yaml")
        s.name, s.meshes
    """

    @property
    def name(self) -> str:
        """The scenario's name (its `name:`, or the file's stem)."""
    @property
    def description(self) -> str:
        """Its `description:` text ("" when it has none)."""
    @property
    def meshes(self) -> list[str]:
        """The mesh files the scenario references, as written."""
    @property
    def warnings(self) -> list[str]:
        """What loads but looks wrong (file:line:col: ...), e.g. a mesh whose size is
        implausible in the scenario's length unit. spar.scenario() and spar.plan() issue each
        as a UserWarning."""


class PlanRun:
    """A finished planning run (spar.plan_run()): its report, and phase 2 on any of its plan
    instances::

        run = spar.plan_run("examples/peg_block_face_down.yaml")
        run.report["chosen"]["errors"]      # the report spar.plan() returns
        run.analyse(1)["errors"]            # phase 2 on another instance
    """

    @property
    def report(self) -> dict[str, Any]:
        """The report: the JSON of `spar plan --json` as dicts and lists."""
    @property
    def instance_count(self) -> int:
        """How many plan instances the run enumerated."""
    def analyse(self, index: int, extras: bool = False) -> dict[str, Any]:
        """Phase 2 on plan instance `index` (0 <= index < instance_count): its uncertainty
        analysis as the report's `chosen` record (steps, preconditions with sound bounds,
        repairs, errors). extras=True adds the reverse analysis, blame and Monte Carlo. The GIL
        is released while it runs."""


def bound(expr: Expr | str, box: Mapping[str, tuple[float, float]], *,
          tolerance: float = 1e-3, constraints: Iterable[Constraint] = (),
          max_box_evaluations: int = 200_000, max_seconds: float = 0.0,
          inner: bool = True) -> BoundResult: ...
def bound_record(record: Mapping[str, Any], **options: Any) -> dict[str, Any]: ...
def scenario(source: ScenarioSource, *, base_dir: str | os.PathLike[str] | None = None,
             name: str | None = None) -> Scenario: ...
def plan(source: ScenarioSource, *, instances: int = 16, max_nodes: int = 200_000,
         max_steps: int = 64, domain: str | os.PathLike[str] | None = None,
         domain_text: tuple[str, str] | None = None, probability: bool = True,
         chosen_extras: bool = True, threads: int = 1,
         base_dir: str | os.PathLike[str] | None = None,
         name: str | None = None) -> dict[str, Any]: ...
def plan_run(source: ScenarioSource, *, instances: int = 16, max_nodes: int = 200_000,
             max_steps: int = 64, domain: str | os.PathLike[str] | None = None,
             domain_text: tuple[str, str] | None = None, probability: bool = True,
             chosen_extras: bool = True, threads: int = 1,
             base_dir: str | os.PathLike[str] | None = None,
             name: str | None = None) -> PlanRun: ...


def evidence(source: Mapping[str, Any] | str | os.PathLike[str]) -> dict[str, Any]: ...
def aspects(obj: str | os.PathLike[str], *, units: Literal["m", "mm", "in"] = "m",
            max_angle: float = 75.0, level: int = 3, resolution: int = 128,
            view_sphere: bool = False) -> dict[str, Any]: ...
def sense_plan(source: ScenarioSource, *, base_dir: str | os.PathLike[str] | None = None,
               name: str | None = None) -> dict[str, Any]: ...


def robots() -> list[str]:
    """Names of the built-in robots: puma560, puma762, ur5, panda."""


def robot(robot: str, tip: str = "", package_path: Sequence[str] | None = None) -> dict[str, Any]:
    """What spar knows of a robot: a built-in name or a URDF file (`tip`: the link the chain
    ends at, default the URDF's only leaf; `package_path`: folders that package:// URIs resolve
    in). A dict with name, source, base, tip, method (the inverse kinematics solver) and joints
    (name, type, lower, upper; d, a, alpha, offset for a DH table)::

        [j["name"] for j in spar.robot("ur5")["joints"]]
    """


def fk(robot: str, q: Sequence[float], tip: str = "",
       package_path: Sequence[str] | None = None) -> Matrix4:
    """Forward kinematics: the tip's pose in the base frame (4x4 NumPy array, metres) for joint
    values `q` (radians; one per joint). `robot` is puma560, puma762, ur5, panda or a URDF file
    (tip and package_path as in spar.robot())::

        spar.fk("panda", [0, -0.3, 0, -2.2, 0, 2.0, 0.8])[:3, 3]   # the flange's position
    """


def ik(robot: str, pose: Matrix4, tip: str = "", package_path: Sequence[str] | None = None,
       redundancy_step: float = ...) -> IkResult:
    """Inverse kinematics: every joint solution that puts the tip at `pose` (4x4, base frame).
    Closed forms for Puma and UR arms (eight labelled configurations), q7 sampled every
    `redundancy_step` radians (default 5 degrees) for the Panda, a numeric solver for other
    chains. The GIL is released while it runs::

        pose = spar.fk("puma560", [0, 0.7, 0.9, 0, -0.5, 0])
        [s.configuration for s in spar.ik("puma560", pose).solutions]
    """


def possible_object_pose(ideal: Matrix4, uncertainty: Mapping[str, float],
                         tag: str = "o") -> UncertainPose:
    """An object's possible pose (SPAR eq. 2): the ideal pose displaced in world coordinates
    by dx, dy, dz and turned by dtheta about the world's z axis through the object's origin,
    each within +-its half-width (`uncertainty`: {"dx", "dy", "dz" in metres, "dtheta" in
    radians}; missing ones are 0). The variables are named after `tag`: dx_peg, dtheta_peg."""


def possible_manipulator_pose(ideal: Matrix4, uncertainty: Mapping[str, float],
                              tag: str = "g") -> UncertainPose:
    """The gripper's possible pose (SPAR eq. 1): the ideal pose composed with a displacement
    dx, dy, dz and a turn dtheta about z in the gripper's own frame (`uncertainty` and `tag` as
    in spar.possible_object_pose())."""
