"""spar.evidence and spar.aspects (issue 26): the same dicts as `spar evidence --json` and
`spar aspects --json`, errors as spar.SensingError / spar.GeometryError."""
import json
import math

import pytest

import spar
from conftest import EXAMPLES

PROBLEM = {"frame": ["a", "b", "c"], "sources": [
    [{"set": ["a", "b"], "mass": 0.8}, {"set": ["a", "b", "c"], "mass": 0.2}],
    [{"set": ["b"], "mass": 0.5}, {"set": ["c"], "mass": 0.5}]]}


def test_evidence_from_dict_text_and_file_agree():
    from_dict = spar.evidence(PROBLEM)
    assert from_dict == spar.evidence(json.dumps(PROBLEM))
    # Products: {b} 0.4 + 0.1, {c} 0.1, the empty set 0.4 (the conflict).
    assert from_dict["conflict"] == pytest.approx(0.4)
    assert from_dict["belief"]["b"] == pytest.approx(5 / 6)
    assert from_dict["pignistic"]["c"] == pytest.approx(1 / 6)
    ambiguity = -(5 / 6 * math.log2(5 / 6) + 1 / 6 * math.log2(1 / 6))
    assert from_dict["ambiguity"] == pytest.approx(ambiguity)
    from_file = spar.evidence(EXAMPLES / "evidence_identity.json")
    assert set(from_file["belief"]) == {"block", "cube", "peg"}


def test_evidence_errors_name_the_place():
    with pytest.raises(spar.SensingError, match=r"sources\[0\]\[0\]\.mass: must be a number"):
        spar.evidence({"frame": ["a"], "sources": [[{"set": ["a"], "mass": 2}]]})
    with pytest.raises(spar.SensingError, match="total conflict"):
        spar.evidence({"frame": ["a", "b"], "sources": [[{"set": ["a"], "mass": 1}],
                                                        [{"set": ["b"], "mass": 1}]]})
    assert issubclass(spar.SensingError, spar.Error)


def test_aspects_of_the_cube_and_the_block():
    cube = spar.aspects("cube")
    assert cube["method"] == "exact arrangement"
    assert len(cube["aspects"]) == 26
    assert sum(a["solid_angle"] for a in cube["aspects"]) == pytest.approx(4 * math.pi)
    assert [a["label"] for a in cube["aspects"]][:2] == ["A1", "A2"]
    block = spar.aspects(EXAMPLES / "objects" / "block.off", units="m")
    assert block["method"] == "view sphere" and block["view_sphere"]["cells"] == 1280
    faces = {f for a in block["aspects"] for f in a["faces"]}
    assert faces == set(range(1, 20))


def test_aspects_errors():
    with pytest.raises(spar.GeometryError, match="no such file, nor a built-in object"):
        spar.aspects("teapot")
    with pytest.raises(spar.SensingError, match=r"max_angle must be in \(0, 90\]"):
        spar.aspects("cube", max_angle=120)
    with pytest.raises(ValueError, match="units"):
        spar.aspects("cube", units="ft")


def test_sense_plan_of_the_example():
    plan = spar.sense_plan(EXAMPLES / "sensing_block_pose.yaml")
    assert plan["scenario"] == "sensing_block_pose"
    (block,) = plan["objects"]
    assert block["hypotheses"] == ["P1", "P2"]
    assert block["ambiguity_before"] == pytest.approx(1.0)
    assert block["resolved"] and block["sequence"]
    first = block["sequence"][0]
    assert first["predicted_max_ambiguity"] < block["threshold"]
    overhead = [c for c in block["candidates"] if c["viewpoint"] == "overhead"]
    assert overhead and overhead[0]["predicted_max_ambiguity"] > block["threshold"]
    unreachable = [c for c in block["candidates"] if not c["reachable"]]
    assert all(c["predicted_max_ambiguity"] is None for c in unreachable)
    assert len(block["view_spheres"][0]["samples"]) == 320
