"""Attacking the CLI: run it in a child under the memory budget and a timeout, and check how it refuses."""

from __future__ import annotations

import resource
import subprocess
import sys
from pathlib import Path
from typing import Any

import yaml

from softdesign.limits import MEMORY_BUDGET_BYTES
from tests.helpers.paths import DEMO

#: A refusal must come this fast, s: python start-up and imports, ingest of the demo (about 3 s), the check.
REFUSAL_TIMEOUT_S = 60
#: A whole coarse build of the demo, s (a few seconds on an idle machine; generous for a loaded CI).
BUILD_TIMEOUT_S = 300


def _limit_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_BUDGET_BYTES, MEMORY_BUDGET_BYTES))


def run_limited(*args: str, timeout: float = REFUSAL_TIMEOUT_S) -> subprocess.CompletedProcess[str]:
    """``softdesign ARGS`` in a child whose address space is the memory budget; TimeoutExpired if it hangs."""
    code = "import sys; from softdesign.cli import main; sys.argv[0] = 'softdesign'; main()"
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        preexec_fn=_limit_memory,
        capture_output=True,
        text=True,
        timeout=timeout,
        stdin=subprocess.DEVNULL,
    )


def assert_refused(result: Any, *needles: str) -> str:
    """Exit 2, no traceback, every needle in the message (stderr, or the output of CliRunner); returns it."""
    text = getattr(result, "stderr", "") or result.output
    code = result.returncode if hasattr(result, "returncode") else result.exit_code
    assert code == 2, text
    assert "Traceback" not in text, text
    for needle in needles:
        assert needle in text, f"{needle!r} not in {text!r}"
    return text


def demo_case(folder: Path, name: str = "demo", **sections: Any) -> Path:
    """configs/demo.yaml with absolute inputs, a coarse export, and ``sections`` merged in (None drops a key)."""
    case = yaml.safe_load(DEMO.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((DEMO.parent / case["final"][key]).resolve())
    case["export"] = {"q": [0, 1], "angular_count": 48, "spacing_mm": 1.0}
    for key, value in sections.items():
        if value is None:
            case.pop(key, None)
        elif isinstance(value, dict) and isinstance(case.get(key), dict):
            merged = {**case[key], **value}
            case[key] = {k: v for k, v in merged.items() if v is not None}
        else:
            case[key] = value
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path
