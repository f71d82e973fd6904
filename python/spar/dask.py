"""spar.dask: plan and bound batches on a Dask cluster (one machine or many).

    from distributed import Client
    import spar.dask
    client = Client("tcp://scheduler:8786")      # or Client(LocalCluster(n_workers=2))
    reports = spar.dask.plan_many(client, ["a.yaml", "b.yaml"], chunk_size=8, probability=False)
    results = spar.dask.bound_many(client, records, tolerance=1e-6)

The work is cut into chunks of `chunk_size` items, one Dask task each. Results stream back as
tasks complete (as_completed; `on_result(index, result)` sees each one then), and the returned
list keeps the input order. A chunk whose task fails (a worker dies, an unexpected exception) is
submitted once more; a second failure raises. A bad item is not a failure: it gives an error
record {"error": message, "error_type": "ScenarioError", ...} in its place, as `spar plan
--batch` does, and the batch goes on.

Nothing assumes a shared filesystem: a scenario travels as its text, and the mesh files it
references travel by content (read on the client, written into a private temporary folder on the
worker, at the same relative paths). A domain file travels as text as well. Every worker needs
the spar package (cmake --install on each machine, see the README).
"""

import contextlib
import dataclasses
import json
import os
import pathlib
import tempfile

from distributed import as_completed

import spar


@dataclasses.dataclass(frozen=True)
class ScenarioPayload:
    """A scenario as it travels: its text, the name messages use, its meshes by content."""
    text: str
    source: str
    meshes: dict  # path as written in the scenario (relative) -> bytes


def scenario_payload(scenario, *, base_dir=None, name=None):
    """The payload of a scenario given as spar.plan takes it (path, dict or YAML text).

    Files are read here as spar reads them (regular files within its size limits, text that is
    UTF-8), mesh files relative to the scenario's folder (or `base_dir` for a dict or text).
    Raises ValueError for an absolute mesh path (it would not exist on another machine),
    spar.ScenarioError for a scenario file that cannot be read or a bad scenario that references
    meshes, and spar.GeometryError for a mesh file that cannot be read.
    """
    if isinstance(scenario, ScenarioPayload):
        return scenario
    if spar._is_path(scenario):
        path = pathlib.Path(scenario)
        text, source, folder = spar._spar._read_scenario_text(str(path)), str(scenario), path.parent
    elif isinstance(scenario, dict):
        text, source = json.dumps(scenario), name or "<dict>"
        folder = pathlib.Path(base_dir if base_dir is not None else ".")
    else:
        text, source = scenario, name or "<text>"
        folder = pathlib.Path(base_dir if base_dir is not None else ".")
    meshes = {}
    if "mesh" in text:  # only then can it reference a mesh file: parse it to find them
        for mesh in spar.scenario(text, base_dir=folder, name=source).meshes:
            if os.path.isabs(mesh):
                raise ValueError(f"{source}: mesh '{mesh}' is an absolute path, which another "
                                 "machine does not have: make it relative to the scenario")
            meshes[mesh] = spar._spar._read_mesh_bytes(str(folder / mesh))
    return ScenarioPayload(text, source, meshes)


@contextlib.contextmanager
def _mesh_folder(meshes):
    """A private folder holding `meshes` at their relative paths; yields the base_dir to use."""
    if not meshes:
        yield "."
        return
    with tempfile.TemporaryDirectory(prefix="spar-meshes-") as root:
        # A path that climbs out of the scenario's folder ("../parts/a.off") needs room above it.
        depth = max(pathlib.PurePath(m).parts.count("..") for m in meshes)
        base = pathlib.Path(root, *(["scenario"] * depth))
        for mesh, content in meshes.items():
            target = pathlib.Path(os.path.normpath(base / mesh))
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(content)
        yield str(base)


def _error_record(error):
    return {"error": str(error), "error_type": type(error).__name__}


def plan_payload(payload, options):
    """spar.plan on a payload (on a worker): the report, or an error record for anything one
    scenario raises (a spar.Error, or any other exception: one item never fails its chunk)."""
    try:
        with _mesh_folder(payload.meshes) as base_dir:
            scenario = spar._spar._parse_scenario(payload.text, payload.source, base_dir)
            return spar.plan(scenario, **options)
    except Exception as error:  # noqa: BLE001 (the record says what it was)
        return _error_record(error)


def _plan_chunk(payloads, options):
    return [plan_payload(payload, options) for payload in payloads]


def _bound_chunk(records, options):
    return [spar.bound_record(record, **options) for record in records]


def map_chunks(client, function, items, *, chunk_size, options=None, on_result=None):
    """function(chunk, options) on consecutive chunks of `items` as Dask tasks.

    `function` returns one result per item of its chunk. Results are handed to on_result(index,
    result) as their chunks complete and returned in input order. A failed chunk is retried once.
    """
    if chunk_size < 1:
        raise ValueError(f"chunk_size must be at least 1, not {chunk_size}")
    items = list(items)
    options = dict(options or {})
    chunks = [items[i:i + chunk_size] for i in range(0, len(items), chunk_size)]
    results = [None] * len(items)
    owner = {}  # future key -> (chunk index, attempt)

    def submit(index, attempt):
        future = client.submit(function, chunks[index], options, pure=False)
        owner[future.key] = (index, attempt)
        return future

    stream = as_completed([submit(index, 0) for index in range(len(chunks))])
    for future in stream:
        index, attempt = owner.pop(future.key)
        if future.status != "finished":
            if attempt == 0:
                stream.add(submit(index, 1))
                continue
            future.result()  # raises the task's exception, with its remote traceback
        chunk_results = future.result()
        if len(chunk_results) != len(chunks[index]):
            raise RuntimeError(f"chunk {index} gave {len(chunk_results)} results for "
                               f"{len(chunks[index])} items")
        for offset, result in enumerate(chunk_results):
            results[index * chunk_size + offset] = result
            if on_result is not None:
                on_result(index * chunk_size + offset, result)
        future.release()
    return results


def plan_many(client, scenarios, *, chunk_size=4, on_result=None, base_dir=None, domain=None,
              **options):
    """Plans every scenario (path, dict, YAML text or ScenarioPayload) on the cluster.

    Returns one item per scenario, in input order: its report (what spar.plan returns) or an
    error record {"error", "error_type"}, also for a scenario that cannot even be read here (a
    missing file, a folder, text that is not UTF-8, a missing or bad mesh): such an item never
    reaches the cluster and never stops the batch. `options` are spar.plan's (instances,
    max_nodes, max_steps, probability, chosen_extras); `domain` (a file, read once here: a bad
    domain raises spar.DomainError) travels as text; `base_dir` resolves the meshes of dict and
    text scenarios.
    """
    scenarios = list(scenarios)
    results = [None] * len(scenarios)
    payloads, positions = [], []  # the items that go to the cluster, and where they came from
    for index, scenario in enumerate(scenarios):
        try:
            payloads.append(scenario_payload(scenario, base_dir=base_dir))
            positions.append(index)
        except (spar.Error, OSError, TypeError, ValueError) as error:
            results[index] = _error_record(error)
            if on_result is not None:
                on_result(index, results[index])
    if domain is not None:
        options["domain_text"] = (spar._spar._read_domain_text(os.fspath(domain)), str(domain))
    forward = None if on_result is None else (lambda i, result: on_result(positions[i], result))
    planned = map_chunks(client, _plan_chunk, payloads, chunk_size=chunk_size, options=options,
                         on_result=forward)
    for index, result in zip(positions, planned):
        results[index] = result
    return results


def bound_many(client, records, *, chunk_size=32, on_result=None, **options):
    """spar.bound_record on every FPBench-style record on the cluster, in input order.

    `options` are spar.bound's keywords (tolerance, max_box_evaluations, ...). Bounding is
    deterministic (its effort limits count work, not time), so the results equal serial ones
    but for `seconds`, the wall-clock time each bound took.
    """
    return map_chunks(client, _bound_chunk, records, chunk_size=chunk_size, options=options,
                      on_result=on_result)
