"""Shared fixtures of the spar Python tests: where the repository, the corpus and the CLI are.

ctest (python/CMakeLists.txt) sets PYTHONPATH to the build tree's package and SPAR_SOURCE_DIR,
SPAR_CORPUS_DIR and SPAR_CLI (the `spar` command, empty when the build has no CLI).
"""
import json
import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("SPAR_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
CORPUS_DIR = pathlib.Path(os.environ.get("SPAR_CORPUS_DIR", SOURCE_DIR / "data"))
EXAMPLES = SOURCE_DIR / "examples"


def without_wall_clock(report):
    """A report without what changes from run to run: the search's wall-clock seconds."""
    report = json.loads(json.dumps(report))
    report["family"]["search"].pop("seconds", None)
    return report


@pytest.fixture(scope="session")
def fpbench():
    with open(CORPUS_DIR / "fpbench.jsonl", encoding="utf-8") as corpus:
        return [json.loads(line) for line in corpus if line.strip()]


@pytest.fixture(scope="session")
def puma_corpus():
    with open(CORPUS_DIR / "puma560.json", encoding="utf-8") as corpus:
        return json.load(corpus)
