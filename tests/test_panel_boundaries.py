"""The page's panels act through narrow interfaces: no panel reaches into another's privates.

* The drive-log panel and the studies use only what :class:`app.ui.case.CasePort` declares.
* No module of ``app/ui`` reads or writes a private attribute (``x._name``) of another object.
* The case a panel reads is a frozen snapshot: it cannot rewrite the origin or the parameters.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

from pmsm_commissioning.app.ui.case import Case, CasePort, CaseState

ROOT = Path(__file__).resolve().parents[1]
PORT_MEMBERS = {n for n in dir(CasePort) if not n.startswith("_")}


@pytest.mark.parametrize(("module", "receiver"), [("app/ui/log.py", "self._port"),
                                                  ("app/ui/studies_robustness.py", "self._s"),
                                                  ("app/ui/studies_multiaxis.py", "self._s"),
                                                  ("app/ui/studies.py", "port")])
def test_panels_use_only_the_port(module, receiver):
    text = (ROOT / module).read_text(encoding="utf-8")
    used = set(re.findall(re.escape(receiver) + r"\.(\w+)", text))
    assert used, f"{module} does not use {receiver}"
    assert used <= PORT_MEMBERS, f"{module} uses {sorted(used - PORT_MEMBERS)} beyond the CasePort"


def test_no_ui_module_touches_another_objects_privates():
    private = re.compile(r"([A-Za-z_][\w.]*)\.(_[a-z]\w*)\b")
    offenders = []
    for path in sorted((ROOT / "app" / "ui").rglob("*.py")):
        if path.name == "viser_adapter.py":  # viser's private API, on purpose (tests/test_viser_adapter.py)
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            code = line.split("#", 1)[0]
            for m in private.finditer(code):
                if m.group(1) not in ("self", "cls"):
                    offenders.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert offenders == []
    assert private.search("self.s._run(params)").group(1) == "self.s"  # what LogPanel once did


def test_the_case_is_a_frozen_snapshot_replaced_whole(paper_params):
    state = CaseState(Case(paper_params, "paper", comparison=None))  # type: ignore[arg-type]
    before = state.current
    with pytest.raises(dataclasses.FrozenInstanceError):
        before.origin = "rewritten"  # type: ignore[misc]
    after = state.opened(paper_params, "paper + identified")
    assert before.origin == "paper" and after.origin == "paper + identified" and state.current is after
    refused = state.refused("motor.L_d = -1 is out of range")
    assert refused.error and refused.runs == 0 and refused.params is paper_params
    ran = state.ran(paper_params, comparison=None)  # type: ignore[arg-type]
    assert ran.error is None and ran.runs == 1
