"""spar: symbolic worst-case uncertainty analysis of robot task plans, from Python.

The compiled engine (spar._spar) with Pythonic names; the typed interface, with every
docstring, is spar/__init__.pyi beside this file:

    import spar
    f = spar.Expr("x^2 - y")
    r = spar.bound(f, {"x": (-1, 2), "y": (0, 1)}, tolerance=1e-6)   # r.lo, r.hi, r.argmax
    pose = spar.fk("puma560", [0, 0.7, 0.9, 0, -0.5, 0])              # 4x4 NumPy array
    solutions = spar.ik("puma560", pose).solutions                    # all eight, labelled
    spar.fk("ur5", [0.3, -1.1, 1.4, -0.9, 1.2, 0.4])   # or "panda", or a URDF path (tip=, package_path=)
    report = spar.plan("examples/peg_block_face_down.yaml")           # `spar plan --json`

Errors are spar.Error and its subclasses (spar.ScenarioError, spar.BoundsError, ...) with the
engine's messages. Long calls (plan, bound, scenario loading) release the GIL, so a thread pool
runs them in parallel; spar.dask spreads batches over a Dask cluster.
"""

import json
import os
import warnings

from spar import _spar
from spar._spar import (  # noqa: F401 (re-exported)
    BoundResult,
    BoundsError,
    CmsError,
    DomainError,
    Error,
    Expr,
    GeometryError,
    IkResult,
    IkSolution,
    KinematicsError,
    NumberError,
    PlanError,
    PlanRun,
    QrError,
    ReportError,
    Scenario,
    ScenarioError,
    SensingError,
    ShostakError,
    SymbolicError,
    UncertainPose,
    __version__,
    fk,
    ik,
    possible_manipulator_pose,
    possible_object_pose,
    robot,
    robots,
)

__all__ = [
    "BoundResult", "BoundsError", "CmsError", "DomainError", "Error", "Expr", "GeometryError",
    "IkResult", "IkSolution", "KinematicsError", "NumberError", "PlanError", "PlanRun", "QrError",
    "ReportError", "Scenario", "ScenarioError", "SensingError", "ShostakError", "SymbolicError",
    "UncertainPose", "aspects", "bound", "bound_record", "evidence", "fk", "ik", "plan",
    "plan_run", "possible_manipulator_pose", "possible_object_pose", "robot", "robots",
    "scenario", "sense_plan",
]


def _expr(value):
    return value if isinstance(value, Expr) else Expr(str(value))


def _constraint(value):
    """'x + y <= 1', (g, '<=') meaning g <= 0, or {'g': g, 'rel': '<='} (the JSONL form)."""
    if isinstance(value, str):
        return _spar._Constraint(value)
    if isinstance(value, dict):
        return _spar._Constraint(_expr(value["g"]), value.get("rel", "<="))
    g, relation = value
    return _spar._Constraint(_expr(g), relation)


def bound(expr, box, *, tolerance=1e-3, constraints=(), max_box_evaluations=200_000,
          max_seconds=0.0, inner=True):
    """Sound bounds of `expr` (an Expr or its text) over `box` ({name: (lo, hi)}).

    Returns a BoundResult: lo <= inner_lo <= inner_hi <= hi, where [lo, hi] encloses every value
    on the (constrained) box and inner_lo / inner_hi are attained at argmin / argmax ({name:
    value}); inner_lo and inner_hi are None when no attained range is known (no_inner_range
    says why); status is converged, effort_limit, unbounded or infeasible. `constraints` are
    'lhs <= rhs' texts, (g, relation) pairs meaning g relation 0, or {'g', 'rel'} dicts.
    The GIL is released while bounding. Raises spar.BoundsError for a bad box or a variable of
    `expr` without a range.
    """
    ranges = [(str(name), float(lo), float(hi)) for name, (lo, hi) in box.items()]
    return _spar._bound(_expr(expr), ranges, [_constraint(c) for c in constraints],
                        float(tolerance), int(max_box_evaluations), float(max_seconds),
                        bool(inner))


def bound_record(record, **options):
    """Bounds one FPBench-style record ({"name", "expr", "vars": {x: [lo, hi]}, "constraints"}).

    Returns the result as a dict (BoundResult.as_dict() plus "name"), or {"name", "error",
    "error_type"} when the record is bad or bounding fails: one bad record never stops a batch
    (like `spar bound --jsonl`). `options` are bound()'s keywords.
    """
    name = record.get("name") if isinstance(record, dict) else None
    try:
        result = bound(record["expr"], record["vars"], constraints=record.get("constraints", ()),
                       **options).as_dict()
    except (Error, KeyError, TypeError, ValueError) as error:
        message = f"missing key {error}" if isinstance(error, KeyError) else str(error)
        return {"name": name, "error": message, "error_type": type(error).__name__}
    return {"name": name, **result}


def _is_path(source):
    """A PathLike, or a str without a newline that names something on the file system (a file, a
    folder, a device, a dangling link) or ends in .yaml / .yml. spar's loader then says what is
    wrong with a path that is not a scenario file ("is a directory"); it is never read as text."""
    return isinstance(source, os.PathLike) or (
        isinstance(source, str) and "\n" not in source
        and (source.endswith((".yaml", ".yml")) or os.path.lexists(source)))


def _warn(scenario):
    """Issues the scenario's warnings (Scenario.warnings) as UserWarnings; returns it."""
    for warning in scenario.warnings:
        warnings.warn(warning, UserWarning, stacklevel=3)
    return scenario


def scenario(source, *, base_dir=None, name=None):
    """A Scenario from a path, a dict (the YAML's structure) or YAML text.

    A str without a newline that names something on the file system (or ends in .yaml / .yml) is
    a path; other strs are YAML text, and bytes are YAML text that must be UTF-8. Mesh paths in a
    dict or text resolve against `base_dir` (default: the current folder); `name` names a dict or
    text in messages (and becomes the scenario's name when it has no `name:`). Raises
    spar.ScenarioError with file:line:col for a bad scenario (a folder, a FIFO or /dev/zero given
    as a path, text that is not UTF-8 included); the scenario's warnings (Scenario.warnings) are
    issued as UserWarnings.
    """
    if isinstance(source, Scenario):
        return source
    if _is_path(source):
        return _warn(_spar._load_scenario(os.fspath(source)))
    if isinstance(source, dict):
        text, default_name = json.dumps(source), "<dict>"  # JSON is YAML
    elif isinstance(source, (str, bytes)):
        text, default_name = source, "<text>"  # bytes: spar checks the UTF-8 (file:line:col)
    else:
        raise TypeError("a scenario is a path, a dict or YAML text, not "
                        f"{type(source).__name__}")
    return _warn(_spar._parse_scenario(text, name or default_name,
                                       os.fspath(base_dir) if base_dir is not None else "."))


def _settings(instances, max_nodes, max_steps, domain, domain_text, probability, chosen_extras,
              threads):
    settings = _spar._PlanSettings()
    settings.instances = int(instances)
    settings.max_nodes = int(max_nodes)
    settings.max_steps = int(max_steps)
    if domain is not None:
        settings.domain_path = os.fspath(domain)
    if domain_text is not None:
        settings.domain_text, settings.domain_source = domain_text
    settings.probability = bool(probability)
    settings.chosen_extras = bool(chosen_extras)
    if not 0 <= int(threads) <= 256:
        raise ValueError(f"threads must be 0 (one per core) to 256 (as spar plan --jobs), "
                         f"not {threads}")
    settings.threads = int(threads)
    return settings


_PLAN_OPTIONS_DOC = """
    Options (the defaults are `spar plan`'s): instances (plan instances enumerated, 16),
    max_nodes (partial plans the search may expand, 200000), max_steps (actions in one plan, 64),
    domain (a domain file; default the built-in planner/domain.yaml), domain_text ((text, name):
    a domain given as text), probability (False: skip the chosen instance's probabilistic
    analysis and tolerance allocation), chosen_extras (False: skip its reverse analysis, blame
    and Monte Carlo; the verdicts do not change), threads (threads for this plan's parts: grasp
    searches, later instances, margins, tolerance verification; 1, 0 for one per core; the report
    is the same on any number; at most 256). base_dir and name as in spar.scenario().
    The GIL is released while planning.
"""


def plan(source, *, instances=16, max_nodes=200_000, max_steps=64, domain=None,
         domain_text=None, probability=True, chosen_extras=True, threads=1, base_dir=None,
         name=None):
    """Plans a scenario (path, dict, YAML text or Scenario) and returns its report.

    The report is the JSON of `spar plan --json` (schema spar-report/1, docs/report-schema.md)
    as dicts and lists; non-finite numbers are the strings "inf", "-inf", "nan" as there.
    """
    return _spar._plan(scenario(source, base_dir=base_dir, name=name),
                       _settings(instances, max_nodes, max_steps, domain, domain_text,
                                 probability, chosen_extras, threads))


def plan_run(source, *, instances=16, max_nodes=200_000, max_steps=64, domain=None,
             domain_text=None, probability=True, chosen_extras=True, threads=1, base_dir=None,
             name=None):
    """Plans a scenario and keeps the run: PlanRun.report is plan()'s result, and
    PlanRun.analyse(i) runs phase 2 on plan instance i (0 <= i < PlanRun.instance_count).
    """
    return _spar._plan_run(scenario(source, base_dir=base_dir, name=name),
                           _settings(instances, max_nodes, max_steps, domain, domain_text,
                                     probability, chosen_extras, threads))


plan.__doc__ += _PLAN_OPTIONS_DOC
plan_run.__doc__ += _PLAN_OPTIONS_DOC


def evidence(source):
    """Dempster's combination of mass functions: the dict of `spar evidence --json`.

    `source` is a dict {"frame": [names], "sources": [[{"set": [names], "mass": x}, ...], ...]},
    its JSON text, or a path to a JSON file. Returns {"frame", "masses", "conflict", "belief",
    "plausibility", "pignistic", "ambiguity", "nonspecificity", "ambiguity_measure"}; the
    ambiguity is the entropy of the pignistic probability in bits. Raises spar.SensingError for
    a bad problem (naming the place) or total conflict.
    """
    if isinstance(source, dict):
        return _spar._evidence_text(json.dumps(source), "<dict>")
    if isinstance(source, os.PathLike) or (isinstance(source, str)
                                           and not source.lstrip().startswith("{")):
        return _spar._evidence_file(os.fspath(source))
    return _spar._evidence_text(source, "<text>")


_METRES_PER_UNIT = {"m": 1.0, "mm": 0.001, "in": 0.0254}


def aspects(obj, *, units="m", max_angle=75.0, level=3, resolution=128, view_sphere=False):
    """The aspects of an object: the dict of `spar aspects --json`.

    `obj` is a built-in name (peg, block, cube, l-shape) or an .off / .obj file whose coordinates
    are in `units` (m, mm or in; also the unit of the output). A face is seen within `max_angle`
    degrees of its normal. Convex objects get the exact arrangement; others a view sphere of
    20 * 4**level directions with `resolution` samples across (view_sphere=True forces it).
    Returns {"object", "units", "method", "max_angle", "aspects": [{"label", "faces",
    "solid_angle", "direction", "features"}]}. The GIL is released while computing.
    """
    if units not in _METRES_PER_UNIT:
        raise ValueError(f"units must be one of m, mm, in, not {units!r}")
    settings = _spar._AspectSettings()
    settings.units = units
    settings.metres_per_unit = _METRES_PER_UNIT[units]
    settings.max_angle_degrees = float(max_angle)
    settings.level = int(level)
    settings.resolution = int(resolution)
    settings.view_sphere = bool(view_sphere)
    return _spar._aspects(os.fspath(obj), settings)


def sense_plan(source, *, base_dir=None, name=None):
    """Sense planning: the dict of `spar sense-plan --json` for a scenario (path, dict, YAML text
    or Scenario; base_dir and name as in spar.scenario()).

    For every object whose identity or stable pose is uncertain: its hypotheses, the candidate
    sensing operations (sensor x viewpoint class) with their predicted ambiguity per true
    hypothesis and its maximum, the chosen sequence (least maximum ambiguity first, until it is
    below sensing.ambiguity_threshold) with the beliefs it leaves, and each identity's aspects.
    The GIL is released while planning.
    """
    return _spar._sense_plan(scenario(source, base_dir=base_dir, name=name))
