"""spar.dask on a LocalCluster of 2 worker processes: the results equal the serial ones exactly."""
import shutil

import pytest

import spar
import spar.dask
from conftest import EXAMPLES, without_wall_clock

distributed = pytest.importorskip("distributed")
pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # tornado in Debian 12

FAST = {"probability": False, "chosen_extras": False}


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=40)
    with distributed.Client(cluster) as client:
        yield client
    cluster.close()


def comparable(results):
    return [without_wall_clock(r) if "schema" in r else r for r in results]


def test_plan_many_equals_serial_in_input_order(client):
    text = (EXAMPLES / "peg_block_face_down.yaml").read_text()
    scenarios = [
        EXAMPLES / "peg_block_face_up.yaml",
        str(EXAMPLES / "peg_block_face_down.yaml"),
        text.replace("dtheta: 5.5}", "dtheta: 9}"),              # another tolerance
        text.replace("builtin: peg", "bultin: peg"),              # a bad scenario: error record
        EXAMPLES / "peg_block_on_back.yaml",
    ]
    seen = []
    results = spar.dask.plan_many(client, scenarios, chunk_size=2,
                                  on_result=lambda i, r: seen.append(i), **FAST)
    assert sorted(seen) == list(range(len(scenarios)))
    serial = []
    for scenario in scenarios:
        try:
            serial.append(spar.plan(scenario, **FAST))
        except spar.Error as error:
            serial.append({"error": str(error), "error_type": type(error).__name__})
    assert serial[3]["error_type"] == "ScenarioError"
    assert comparable(results) == comparable(serial)


def test_meshes_travel_by_content(client, tmp_path):
    # The scenario's mesh lives beside it; the payload is made, then the files are deleted, so
    # the workers can only plan from what travelled.
    folder = tmp_path / "cell"
    (tmp_path / "parts").mkdir()
    folder.mkdir()
    shutil.copy(EXAMPLES / "objects/block.off", tmp_path / "parts/block.off")
    text = (EXAMPLES / "peg_block_face_down.yaml").read_text()
    text = text.replace("builtin: block", "mesh: ../parts/block.off")
    (folder / "cell.yaml").write_text(text)
    serial = spar.plan(folder / "cell.yaml", **FAST)
    payload = spar.dask.scenario_payload(folder / "cell.yaml")
    assert list(payload.meshes) == ["../parts/block.off"]
    shutil.rmtree(tmp_path / "parts")
    [result] = spar.dask.plan_many(client, [payload], **FAST)
    assert without_wall_clock(result) == without_wall_clock(serial)


def test_bound_many_equals_serial(client, fpbench):
    records = fpbench[:30] + [{"name": "bad", "expr": "x +", "vars": {"x": [0, 1]}}]
    results = spar.dask.bound_many(client, records, chunk_size=7, max_box_evaluations=5000)
    serial = [spar.bound_record(r, max_box_evaluations=5000) for r in records]
    # Equal but for the wall-clock time each bound took.
    for result in results + serial:
        result.pop("seconds", None)
    assert results == serial
    assert results[-1]["error_type"] == "SymbolicError"


def test_a_failed_chunk_is_retried_once(client, tmp_path):
    marker = tmp_path / "failed-once"

    def flaky(chunk, options):  # fails the first time it runs (workers share this machine)
        if not marker.exists():
            marker.write_text("x")
            raise RuntimeError("worker lost")
        return [item * 2 for item in chunk]

    assert spar.dask.map_chunks(client, flaky, range(5), chunk_size=5) == [0, 2, 4, 6, 8]
    assert marker.exists()

    attempts = tmp_path / "attempts"
    attempts.mkdir()

    def broken(chunk, options):  # one file per attempt
        (attempts / f"{chunk[0]}-{len(list(attempts.iterdir()))}").write_text("x")
        raise RuntimeError("always broken")

    with pytest.raises(RuntimeError, match="always broken"):
        spar.dask.map_chunks(client, broken, [7], chunk_size=2)
    assert len(list(attempts.iterdir())) == 2  # the first run and one retry


def test_plan_many_gives_one_error_record_per_bad_item(client, tmp_path):
    # Issue 22: a missing file, a folder, a file that is not UTF-8 and a missing mesh aborted the
    # whole batch; each is now its own record and the good items are planned.
    not_utf8 = tmp_path / "not_utf8.yaml"
    not_utf8.write_bytes(b"name: pe\xffg\nobjects: {}\n")
    no_mesh = (EXAMPLES / "peg_block_face_down.yaml").read_text().replace(
        "builtin: block", "mesh: parts/missing.off")
    scenarios = [EXAMPLES / "peg_block_face_up.yaml", tmp_path / "missing.yaml", str(tmp_path),
                 not_utf8, no_mesh, EXAMPLES / "peg_block_on_back.yaml"]
    seen = []
    results = spar.dask.plan_many(client, scenarios, chunk_size=2, base_dir=tmp_path,
                                  on_result=lambda i, r: seen.append(i), **FAST)
    assert sorted(seen) == list(range(len(scenarios)))
    assert results[0]["schema"] == "spar-report/1" and results[5]["schema"] == "spar-report/1"
    assert "no such scenario file" in results[1]["error"]
    assert "is a directory, not a scenario file" in results[2]["error"]
    assert "not_utf8.yaml:1:9: invalid UTF-8" in results[3]["error"]
    assert "missing.off: no such mesh file" in results[4]["error"]
    assert [r.get("error_type") for r in results[1:5]] == ["ScenarioError"] * 4
