"""What every export says about itself, and the gate every export passes.

* :func:`parameter_hash`: one pure hash of the inputs (SHA-256 of the preset's canonical JSON, first
  16 hex digits): two files with the same hash were made from the same inputs.
* :func:`failed_checks`: the clean verdict of the simulated FDSMC run,
  ``[c for c in run_checks(params, comparison.fdsmc) if c.violated]`` (:func:`sim.fdsmc.design.run_checks`);
  an infeasible manoeuvre (no run) fails the ``T_m`` check.
* :func:`gate`: refuses an export of a design that is not clean, naming the failed checks, unless
  ``force`` (then the checks are written inside the file).
* :func:`header_lines`: the header of the stock-drive files: preset, tool version, parameter hash,
  verdicts and the simulated energies of FDSMC, the optimum and the stock route.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence

from pmsm_commissioning.app.exports.tool_id import tool_version
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.presets import to_raw
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import Controller
from pmsm_commissioning.sim.fdsmc.design import Constraint, run_checks
from pmsm_commissioning.sim.fdsmc.engine import Comparison, RunResult
from pmsm_commissioning.sim.fdsmc.recommend import run_supply_J


class ExportRefusedError(ParameterError):
    """An export of a design that is not clean (``--force`` writes it with the warnings inside)."""


def parameter_hash(params: object) -> str:
    """Return the first 16 hex digits of SHA-256 over the inputs' canonical JSON (sorted keys, SI values)."""
    text = json.dumps(to_json(to_raw(params)), sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(text.encode("ascii")).hexdigest()[:16]


def failed_checks(cmp: Comparison, controller: str = "fdsmc") -> list[Constraint]:
    """Return the violated checks of the simulated run (empty: the design is clean).

    The FDSMC's run, or with ``controller`` ``"optimum"`` the tracked optimum's (its C module's verdict).
    """
    params = cmp.derived.params
    run = cmp.optimum if controller == "optimum" else cmp.fdsmc
    if run is None:
        pr = cmp.derived.profile
        return [Constraint("T_m", params.manoeuvre.T_m, pr.T_m_min, "s", True,
                           f"The manoeuvre is infeasible: T_m = {params.manoeuvre.T_m:g} s < "
                           f"T_m,min = {pr.T_m_min:.4g} s, nothing was simulated.")]
    return [c for c in run_checks(params, run) if c.violated]


def check_text(c: Constraint) -> str:
    """One line naming a failed check: ``name: value unit (limit …) — text``."""
    return f"{c.name}: {c.value:.4g} {c.unit} (limit {c.limit:.4g} {c.unit}) — {c.text.rstrip('.')}"


def gate(fmt: str, cmp: Comparison, force: bool, controller: str = "fdsmc") -> list[Constraint]:
    """Return the failed checks of ``controller``'s run; raise :class:`ExportRefusedError` naming them unless force."""
    failed = failed_checks(cmp, controller)
    if failed and not force:
        names = "; ".join(check_text(c) for c in failed)
        run = " (the tracked optimum's run)" if controller == "optimum" else ""
        raise ExportRefusedError(f"export --format {fmt} refused: the design of {cmp.derived.params.name!r} is not "
                                 f"clean{run} — {names}. Fix the design (pmsm-commission design …) or export with "
                                 "--force to write it with these warnings inside")
    return failed


def verdict_lines(failed: Sequence[Constraint]) -> list[str]:
    """Return the verdict as text lines: clean, or NOT CLEAN (forced) and each failed check."""
    if not failed:
        return ["verdict: clean (simulated FDSMC run within the drive's limits, on time, no chatter)"]
    return ["verdict: NOT CLEAN — written with --force; failed checks:"] + [f"  {check_text(c)}" for c in failed]


def _energy(run: RunResult | None, controller: Controller) -> str:
    """One run's energies: from the supply under the DC-link choice (named), net, friction, copper."""
    if run is None:
        return "not simulated"
    m = run.metrics
    if not m.stable:
        return f"unstable ({m.reason})"
    return (f"from the supply {run_supply_J(run, controller):.5g} J (DC link {controller.dc_link}), "
            f"net electrical {m.electrical_in_total_J:.5g} J (friction {m.friction_total_J:.5g} J, "
            f"copper {m.copper_total_J:.5g} J), peak torque {m.torque_peak_Nm:.4g} N·m")


def route_verdict_lines(route: str, failed: Sequence[Constraint], in_position_s: float | None) -> list[str]:
    """Return the stock route's verdict lines: what was simulated, clean or NOT CLEAN and each failed check."""
    where = f"{route}, simulated from this file's own numbers with the case's sensors and limits"
    settled = "never" if in_position_s is None else f"at {in_position_s:.4g} s"
    if not failed:
        return [f"verdict: clean — stock route ({where}); in position {settled}"]
    return [f"verdict: NOT CLEAN — stock route ({where}); written with --force; failed checks:"] + \
        [f"  {check_text(c)}" for c in failed]


def header_lines(cmp: Comparison, failed: Sequence[Constraint], route: tuple[str, RunResult | None,
                 Sequence[Constraint]] | None = None) -> list[str]:
    """Header of a stock-drive file (no date: the same inputs give the same bytes).

    ``route`` = (the firmware's name, the stock route's run simulated from the file, its failed checks):
    the file's own verdict; None while the file is being drafted. ``failed`` are the FDSMC design's.
    """
    p = cmp.derived.params
    lines = [f"preset: {escaped(p.name)} — {escaped(p.source)}", f"written by: {tool_version()}",
             f"parameter hash: {parameter_hash(p)} (SHA-256 of the inputs' canonical JSON)"]
    if route is not None:
        run = route[1]
        lines += route_verdict_lines(route[0], route[2], None if run is None else run.metrics.in_position_s)
    lines += [f"FDSMC design (C module, not this file): {'clean' if not failed else 'NOT CLEAN'}"]
    lines += [f"design warning: {w}" for w in cmp.derived.warnings]
    stock = None if route is None else route[1]
    lines += [f"simulated whole-run energy, {name}: {_energy(run, p.controller)}" for name, run in
              (("FDSMC", cmp.fdsmc), ("tracked optimum", cmp.optimum), ("stock route (this file)", stock))]
    return lines
