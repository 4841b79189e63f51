"""Shared fixtures of the Python tests: the repository's sample files and the
command-line tool (the Rust example `waam`), whose outputs the tests compare
the module's against."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PARTS = REPO / "parts"
CELLS = PARTS / "cells"


@pytest.fixture(scope="session")
def waam_cli():
    """Runs the `waam` CLI example (`cargo run --example waam`, or the binary
    named by $WAAM_CLI) with the given arguments; returns its exit code."""
    exe = os.environ.get("WAAM_CLI")
    if exe:
        prefix = [exe]
    elif shutil.which("cargo"):
        prefix = ["cargo", "run", "--quiet", "--example", "waam", "--"]
    else:
        pytest.skip("neither $WAAM_CLI nor cargo: cannot run the CLI to compare with")

    def run(*args):
        done = subprocess.run(
            [*prefix, "--quiet", *map(str, args)],
            cwd=REPO,
            capture_output=True,
            text=True,
            timeout=1200,
        )
        return done.returncode, done.stderr

    return run


def read_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)
