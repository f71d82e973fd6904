"""The Python API under hostile input (issue 22): paths that are not scenario files are refused
as such (never parsed as YAML text), text that is not UTF-8 is a ScenarioError with line and
column (not a UnicodeDecodeError), and what loads but looks wrong is a UserWarning."""
import re
import warnings

import pytest

import spar
from conftest import EXAMPLES

FAST = {"probability": False, "chosen_extras": False, "instances": 1}


@pytest.mark.parametrize("path, message", [
    (str(EXAMPLES), "is a directory, not a scenario file"),
    ("/dev/zero", "is not a regular file (a character device)"),
    (EXAMPLES / "no_such.yaml", "no such scenario file"),
])
def test_a_path_that_is_not_a_scenario_file_is_refused_as_such(path, message):
    with pytest.raises(spar.ScenarioError, match=re.escape(message)):
        spar.plan(path, **FAST)


def test_a_fifo_never_blocks(tmp_path):
    import os
    fifo = tmp_path / "cell.yaml"
    os.mkfifo(fifo)
    with pytest.raises(spar.ScenarioError, match=r"is not a regular file \(a FIFO\)"):
        spar.scenario(str(fifo))


def test_a_domain_that_is_not_a_file_is_refused(tmp_path):
    with pytest.raises(spar.DomainError, match=r"/dev/zero: is not a regular file"):
        spar.plan(EXAMPLES / "peg_block_face_up.yaml", domain="/dev/zero", **FAST)
    with pytest.raises(spar.DomainError, match=r"is a directory, not a domain file"):
        spar.plan(EXAMPLES / "peg_block_face_up.yaml", domain=tmp_path, **FAST)


def test_text_that_is_not_utf8_is_a_scenario_error_at_line_and_column():
    with pytest.raises(spar.ScenarioError, match=r"<text>:2:9: invalid UTF-8 \(byte 0xff\)"):
        spar.scenario(b"objects: {}\nname: pe\xffg\n")
    with pytest.raises(spar.ScenarioError, match=r"holds a control character"):
        spar.scenario('name: "peg\\0block"\nobjects: {}\n')


def test_a_file_that_is_not_utf8_is_a_scenario_error(tmp_path):
    cell = tmp_path / "cell.yaml"
    cell.write_bytes((EXAMPLES / "peg_block_face_up.yaml").read_bytes().replace(
        b"name: peg_block_face_up", b"name: peg\xffblock"))
    with pytest.raises(spar.ScenarioError, match=r"cell.yaml:\d+:10: invalid UTF-8"):
        spar.plan(cell, **FAST)


def test_an_implausible_mesh_size_is_a_user_warning(tmp_path):
    (tmp_path / "cube.off").write_text(
        "OFF\n8 6 0\n0 0 0\n0.1 0 0\n0.1 0.1 0\n0 0.1 0\n0 0 0.1\n0.1 0 0.1\n0.1 0.1 0.1\n"
        "0 0.1 0.1\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n")
    text = "units: {length: in}\nobjects:\n  cube: {mesh: cube.off, pose: {xyz: [20, 0, 0]}}\n"
    with pytest.warns(UserWarning, match=r"implausibly small .* is the mesh in m\?"):
        scenario = spar.scenario(text, base_dir=tmp_path)
    assert len(scenario.warnings) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        spar.scenario(text.replace("length: in", "length: m").replace("[20, 0, 0]", "[0.5, 0, 0]"),
                      base_dir=tmp_path)
