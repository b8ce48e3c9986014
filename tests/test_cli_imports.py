"""The CLI imports only what the chosen sub-command needs, and runs BLAS on one thread."""

from __future__ import annotations

import json
import subprocess
import sys

from pmsm_commissioning.app.cli.main import COMMANDS

PROBE = """
import json, sys
from pmsm_commissioning.app.cli.main import main
code = main(sys.argv[1:])
from threadpoolctl import threadpool_info
print(json.dumps({"code": code, "modules": sorted(m for m in ("plotly", "viser", "yaml", "numba", "cvxpy")
                                                   if m in sys.modules),
                  "blas_threads": sorted({i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"})}))
"""


def _probe(*argv: str) -> dict:
    out = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def test_derive_imports_neither_plotly_nor_viser_and_uses_one_blas_thread() -> None:
    r = _probe("derive", "paper_12kw_pmsm", "--json")
    assert r["code"] == 0
    assert "plotly" not in r["modules"] and "viser" not in r["modules"] and "cvxpy" not in r["modules"]
    assert r["blas_threads"] == [1]  # every BLAS library loaded (numpy's, scipy's) limited to one thread


def test_top_level_help_lists_every_command_without_importing_them() -> None:
    res = subprocess.run([sys.executable, "-c", "import sys; from pmsm_commissioning.app.cli.main import main\n"
                          "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
                          "print('numpy' in sys.modules)"], capture_output=True, text=True, check=True)
    for name in COMMANDS:
        assert name in res.stdout
    assert res.stdout.strip().splitlines()[-1] == "False"  # no sub-command module (nor numpy) imported
