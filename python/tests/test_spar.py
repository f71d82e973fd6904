"""The spar Python module against the corpus, the CLI and its own documented behaviour."""
import json
import math
import os
import pickle
import subprocess

import numpy as np
import pytest

import spar
from conftest import CORPUS_DIR, EXAMPLES, without_wall_clock

FACE_DOWN = EXAMPLES / "peg_block_face_down.yaml"


# ---- expressions ----

def test_print_parse_round_trip_on_the_corpus(fpbench):
    # The printed text parses back to the same expression (symbolic/parse.hpp); == reads the
    # other expression into this one's pool and compares nodes.
    for record in fpbench:
        e = spar.Expr(record["expr"])
        again = spar.Expr(str(e))
        assert again == e and e == again, record["name"]
        assert again.variables == e.variables
    with pytest.raises(TypeError):
        hash(spar.Expr("x"))  # equal expressions of two pools may print differently


def test_expressions_are_canonical_and_pickle():
    assert str(spar.Expr("x + x")) == "2*x"
    assert spar.Expr("y*x") == spar.Expr("x*y")
    assert spar.Expr("x + y") != spar.Expr("x - y")
    e = spar.Expr.parse("sin(x)*y + 2")
    assert pickle.loads(pickle.dumps(e)) == e
    assert repr(e) == f"spar.Expr('{e}')"


def test_simplify_diff_evaluate_variables():
    assert spar.Expr("sin(x)^2 + cos(x)^2").simplify() == spar.Expr("1")
    f = spar.Expr("x*sin(y) + z")
    assert f.variables == ["x", "y", "z"]
    dfdy = f.diff("y")
    point = {"x": 2.0, "y": 0.5, "z": -1.0}
    assert dfdy.evaluate(point) == pytest.approx(2.0 * math.cos(0.5), rel=1e-15)
    assert f.diff("w") == spar.Expr("0")
    assert f.evaluate(point) == pytest.approx(2.0 * math.sin(0.5) - 1.0, rel=1e-15)


# ---- bounds ----

def test_bound_encloses_the_fpbench_reference(fpbench):
    # Sound: [lo, hi] contains the corpus's attained range; inner bounds are attained values.
    records = [r for r in fpbench if not r["domain_issue"]][:12]
    for record in records:
        r = spar.bound(record["expr"], record["vars"], tolerance=1e-3,
                       constraints=record.get("constraints", ()))
        assert r.lo <= r.inner_lo <= r.inner_hi <= r.hi, record["name"]
        assert r.lo <= record["ref_min"] + 1e-12 * abs(record["ref_min"]), record["name"]
        assert r.hi >= record["ref_max"] - 1e-12 * abs(record["ref_max"]), record["name"]
        f = spar.Expr(record["expr"])
        assert set(r.argmax) == set(record["vars"])
        assert f.evaluate(r.argmax) == pytest.approx(r.inner_hi, rel=1e-9, abs=1e-12)
        assert f.evaluate(r.argmin) == pytest.approx(r.inner_lo, rel=1e-9, abs=1e-12)


def test_bound_of_the_first_record_is_tight(fpbench):
    record = fpbench[0]  # sqrt(x*x + y*y) over [1, 100]^2
    r = spar.bound(spar.Expr(record["expr"]), record["vars"], tolerance=1e-6)
    assert r.status == "converged"
    assert r.lo == pytest.approx(math.sqrt(2), rel=1e-6)
    assert r.hi == pytest.approx(100 * math.sqrt(2), rel=1e-6)
    assert r.argmin == {"x": 1.0, "y": 1.0} and r.argmax == {"x": 100.0, "y": 100.0}
    assert pickle.loads(pickle.dumps(r)).as_dict() == r.as_dict()
    # Everything but the wall-clock time is deterministic.
    again = spar.bound_record(record, tolerance=1e-6)
    assert again.pop("seconds") >= 0
    assert again == {"name": record["name"], **{k: v for k, v in r.as_dict().items()
                                                if k != "seconds"}}


def test_bound_record_has_the_keys_of_the_cli_json():
    r = spar.bound("x^2 - x", {"x": (0, 1)})
    assert list(r.as_dict()) == ["lo", "hi", "inner_lo", "inner_hi", "argmin", "argmax",
                                 "status", "possibly_undefined", "time_limited", "relative_gap",
                                 "evaluations", "seconds"]
    assert r.evaluations > 0 and r.seconds >= 0 and r.time_limited is False
    cli = os.environ.get("SPAR_CLI")
    if cli:
        out = subprocess.run([cli, "bound", "x^2 - x", "--var", "x=0:1", "--json"], check=True,
                             capture_output=True, text=True).stdout
        cli_record = json.loads(out)
        assert list(cli_record) == list(r.as_dict())
        assert cli_record["lo"] == r.lo and cli_record["argmax"] == r.argmax


def test_bound_constraints_in_three_forms():
    box = {"x": (0, 1), "y": (0, 1)}
    for constraint in ["x + y <= 1", ("x + y - 1", "<="), {"g": "1 - x - y", "rel": ">="}]:
        r = spar.bound("x + y", box, constraints=[constraint], tolerance=1e-6)
        assert 1.0 <= r.hi <= 1.0 + 1e-5, constraint
        assert r.inner_hi <= 1.0


def test_bound_infeasible_constraints():
    r = spar.bound("x", {"x": (0, 1)}, constraints=["x >= 2"])
    assert r.status == "infeasible"
    # No attained range: None and why (issue 22: they were inf > -inf).
    assert r.inner_lo is None and r.inner_hi is None
    assert r.no_inner_range.startswith("no point of the box satisfies the constraints")
    assert r.as_dict()["inner_lo"] is None


def test_bound_of_sin_far_out_attains_its_true_value():
    # Issue 22: the witness at 1e15 "attained" 0; sin(1e15) = 0.858...
    r = spar.bound("sin(x)", {"x": (1e15, 1e15)})
    assert r.inner_lo == pytest.approx(math.sin(1e15), abs=1e-9)
    assert r.no_inner_range is None


# ---- kinematics ----

def test_fk_matches_the_corpus(puma_corpus):
    for name in ["puma560", "puma762"]:
        for vector in puma_corpus[name]["fk_vectors"]:
            pose = spar.fk(name, vector["q"])
            assert isinstance(pose, np.ndarray) and pose.shape == (4, 4)
            np.testing.assert_allclose(pose, vector["T"], atol=1e-9, err_msg=vector["name"])


def wrapped(angle):
    return math.remainder(angle, 2 * math.pi)


def test_ik_gives_the_corpus_solutions(puma_corpus):
    for vector in puma_corpus["puma560"]["ik_vectors"]:
        result = spar.ik("puma560", np.array(vector["T"]))
        assert result.solved and len(result) == 8
        assert [s.configuration for s in result.solutions] == [
            "lun", "luf", "ldn", "ldf", "run", "ruf", "rdn", "rdf"]
        for expected in vector["solutions"]:
            solution = result[expected["config"]]
            assert solution.q.shape == (6,)
            for got, want in zip(solution.q, expected["q"]):
                assert abs(wrapped(got - want)) < 1e-8, (vector["name"], expected["config"])
            assert solution.within_limits == expected["within_limits"]
            np.testing.assert_allclose(spar.fk("puma560", solution.q), vector["T"], atol=1e-9)


def test_robots_and_joint_limits():
    assert spar.robots() == ["puma560", "puma762", "ur5", "panda"]
    robot = spar.robot("puma560")
    assert len(robot["joints"]) == 6
    assert robot["joints"][0]["upper"] == pytest.approx(math.radians(160))
    assert robot["joints"][0]["d"] == pytest.approx(0.67183)
    panda = spar.robot("panda")
    assert (panda["base"], panda["tip"]) == ("panda_link0", "panda_link8")
    assert panda["method"].startswith("closed form over q7")
    assert panda["joints"][3]["name"] == "panda_joint4"


def test_ur5_and_panda_round_trip_by_name_and_by_urdf_path():
    ur5_file = (CORPUS_DIR / "robots/example-robot-data/robots/ur_description/urdf/"
                "ur5_robot.urdf")
    q = [0.3, -1.1, 1.4, -0.9, 1.2, 0.4]
    pose = spar.fk("ur5", q)
    by_path = spar.fk(str(ur5_file), q, tip="tool0", package_path=[str(CORPUS_DIR / "robots")])
    np.testing.assert_allclose(by_path, pose, atol=1e-12)  # the file's root is world = base_link
    result = spar.ik("ur5", pose)
    assert [s.configuration for s in result.solutions] == [
        "lun", "luf", "ldn", "ldf", "run", "ruf", "rdn", "rdf"]
    assert any(max(abs(wrapped(a - b)) for a, b in zip(s.q, q)) < 1e-7 for s in result.solutions)
    q7 = [0.2, -0.4, 0.1, -2.0, 0.3, 1.8, math.radians(20)]
    panda_pose = spar.fk("panda", q7)
    solutions = spar.ik("panda", panda_pose, redundancy_step=math.radians(10)).solutions
    assert solutions and all(s.within_limits for s in solutions)
    for s in solutions:
        assert s.q.shape == (7,)
        np.testing.assert_allclose(spar.fk("panda", s.q), panda_pose, atol=1e-9)
    assert any(max(abs(a - b) for a, b in zip(s.q, q7)) < 1e-7 for s in solutions)


def test_uncertain_object_pose_evaluates_and_bounds():
    ideal = np.eye(4)
    ideal[:3, 3] = [0.5, 0.2, 0.0]
    pose = spar.possible_object_pose(ideal, {"dx": 0.01, "dy": 0.02, "dz": 0.0,
                                             "dtheta": 0.1})
    assert pose.variables == {"dx_o": (-0.01, 0.01), "dy_o": (-0.02, 0.02), "dz_o": (0.0, 0.0),
                              "dtheta_o": (-0.1, 0.1)}
    zero = dict.fromkeys(pose.variables, 0.0)
    np.testing.assert_allclose(pose.evaluate(zero), ideal, atol=1e-15)
    # eq. 2: trans(dx, dy, dz) Tr_O rotz(dtheta) R_O, so x = 0.5 + dx exactly.
    x = pose[0, 3]
    assert x.variables == ["dx_o"]
    r = spar.bound(x, pose.variables, tolerance=1e-9)
    assert r.lo == pytest.approx(0.49, abs=1e-12) and r.hi == pytest.approx(0.51, abs=1e-12)
    assert len(pose.matrix) == 4 and str(pose.matrix[3][3]) == "1"
    gripper = spar.possible_manipulator_pose(ideal, {"dtheta": 0.05}, tag="g")
    assert set(gripper.variables) == {"dx_g", "dy_g", "dz_g", "dtheta_g"}


# ---- planner ----

def cli_report(scenario):
    cli = os.environ.get("SPAR_CLI")
    if not cli:
        pytest.skip("no spar command in this build (SPAR_CLI)")
    out = subprocess.run([cli, "plan", str(scenario), "--json"], check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out)


@pytest.fixture(scope="module")
def face_down_run():
    return spar.plan_run(FACE_DOWN)


def test_plan_equals_the_cli_json(face_down_run):
    report = spar.plan(FACE_DOWN)
    assert report["schema"] == "spar-report/1" and report["status"] == "planned"
    assert without_wall_clock(report) == without_wall_clock(face_down_run.report)
    assert without_wall_clock(report) == without_wall_clock(cli_report(FACE_DOWN))


def test_plan_from_text_and_dict_equals_from_file():
    text = FACE_DOWN.read_text()
    options = {"probability": False, "chosen_extras": False}
    from_file = without_wall_clock(spar.plan(str(FACE_DOWN), **options))
    assert without_wall_clock(spar.plan(text, **options)) == from_file
    yaml = pytest.importorskip("yaml")
    assert without_wall_clock(spar.plan(yaml.safe_load(text), **options)) == from_file


def test_plan_on_two_threads_gives_the_same_report():
    on_back = FACE_DOWN.parent / "peg_block_on_back.yaml"
    one = without_wall_clock(spar.plan(on_back, threads=1))
    assert without_wall_clock(spar.plan(on_back, threads=2)) == one
    assert without_wall_clock(spar.plan(on_back, threads=0)) == one
    for wrong in (-1, 257, 10**12):
        with pytest.raises(ValueError, match="threads must be 0"):
            spar.plan(on_back, threads=wrong)


def test_plan_options_skip_the_chosen_extras():
    report = spar.plan(FACE_DOWN, probability=False, chosen_extras=False)
    assert "probability" not in report["chosen"]
    assert report["chosen"]["errors"] == 0


def test_per_instance_analysis(face_down_run):
    report = face_down_run.report
    assert face_down_run.instance_count == report["instances"]["count"]
    chosen = report["chosen"]["index"]
    analysis = face_down_run.analyse(chosen)
    assert analysis["index"] == chosen and analysis["errors"] == report["chosen"]["errors"]
    preconditions = [p for s in analysis["steps"] for p in s["preconditions"]]
    assert len(preconditions) == report["instances"]["examined"][-1]["preconditions"]
    for p in preconditions:
        assert p["verdict"] in ("satisfied", "violated", "undecided")
        # The expression is re-boundable: its bound over its box agrees with the reported one.
        if p["verdict"] == "satisfied" and p["box"]:
            r = spar.bound(p["expression"], {k: tuple(v) for k, v in p["box"].items()},
                           max_box_evaluations=2000)
            assert r.lo <= p["inner_lo"] and r.hi >= p["inner_hi"]
    with pytest.raises(IndexError, match="does not exist"):
        face_down_run.analyse(face_down_run.instance_count)


def test_analysis_with_extras_reproduces_the_reported_chosen_instance(face_down_run):
    report = face_down_run.report
    analysis = face_down_run.analyse(report["chosen"]["index"], extras=True)
    reported = [p for s in report["chosen"]["steps"] for p in s.get("preconditions", [])]
    analysed = [p for s in analysis["steps"] for p in s["preconditions"]]
    keys = ["name", "kind", "expression", "relation", "lo", "hi", "inner_lo", "inner_hi",
            "verdict"]
    assert [{k: p[k] for k in keys} for p in analysed] == [{k: p[k] for k in keys}
                                                          for p in reported]


def test_analysis_gives_the_report_records(face_down_run):
    # PlanRun.analyse(i) is the report's `chosen` record for instance i: the same keys.
    report = face_down_run.report
    analysis = face_down_run.analyse(report["chosen"]["index"], extras=True)
    chosen = report["chosen"]
    assert [list(s) for s in analysis["steps"]] == [list(s) for s in chosen["steps"]]
    reported = [p for s in chosen["steps"] for p in s.get("preconditions", [])]
    analysed = [p for s in analysis["steps"] for p in s["preconditions"]]
    assert [list(p) for p in analysed] == [list(p) for p in reported]
    assert list(analysis) == [k for k in chosen if k != "probability"]


def test_version_is_the_cli_version():
    assert spar.__version__.count(".") == 2
    cli = os.environ.get("SPAR_CLI")
    if cli:
        out = subprocess.run([cli, "--version"], check=True, capture_output=True, text=True).stdout
        assert out == spar.__version__ + "\n"


# ---- errors ----

def test_errors_are_a_hierarchy_with_the_engine_messages():
    for name in ["SymbolicError", "BoundsError", "KinematicsError", "GeometryError",
                 "ScenarioError", "DomainError", "PlanError", "ReportError", "NumberError"]:
        assert issubclass(getattr(spar, name), spar.Error)
    assert issubclass(spar.ShostakError, spar.BoundsError)
    with pytest.raises(spar.SymbolicError, match=r"expected '\)' at column 6"):
        spar.Expr("sin(x")
    with pytest.raises(spar.BoundsError, match="'z'"):
        spar.bound("x + z", {"x": (0, 1)})
    with pytest.raises(spar.BoundsError, match="no relation"):
        spar.bound("x", {"x": (0, 1)}, constraints=["x + 1"])
    with pytest.raises(spar.KinematicsError, match="puma560"):
        spar.fk("puma999", [0] * 6)
    with pytest.raises(spar.KinematicsError):
        spar.ik("puma560", np.ones((4, 4)))
    with pytest.raises(spar.ScenarioError, match="no such scenario file"):
        spar.plan("missing.yaml")
    bad = FACE_DOWN.read_text().replace("builtin: peg", "bultin: peg")
    with pytest.raises(spar.ScenarioError, match=r"cell\.yaml:\d+:\d+: .*unknown key 'bultin'"):
        spar.plan(bad, name="cell.yaml")
    with pytest.raises(ValueError, match="dx, dy, dz"):
        spar.possible_object_pose(np.eye(4), {"dq": 1.0})
    record = spar.bound_record({"name": "broken", "expr": "x +", "vars": {"x": [0, 1]}})
    assert record["name"] == "broken" and record["error_type"] == "SymbolicError"
    assert "column" in record["error"]


def test_docstrings_are_python_with_examples():
    # The compiled part's come from spar/__init__.pyi (test_stubs.py checks them all).
    assert "spar.Expr(" in spar.Expr.__doc__ and "(from " not in spar.bound.__doc__
    assert "spar-report/1" in spar.plan.__doc__
