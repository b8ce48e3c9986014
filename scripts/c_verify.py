"""Print the exported C controller's closed-loop agreement with the simulator and its golden-vector replay.

Both builds (double, float32), the paper preset and every real-motor preset with its own sensors; the
figures of ``docs/firmware.md`` ("Verification"). Needs a C compiler (``scripts/ensure_cc.sh``).

Usage: ``python scripts/c_verify.py [--controller optimum]``
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from pmsm_commissioning.app.exports.firmware.vectors import c_files
from pmsm_commissioning.app.exports.firmware.verify import measure, replay
from pmsm_commissioning.app.io.presets import list_presets, load_preset
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.design import run_checks
from pmsm_commissioning.sim.fdsmc.engine import compare


def main(argv: list[str] | None = None) -> None:
    """Print closed-loop agreement (both builds) and the golden-vector replay, paper and real-motor presets.

    The real-motor presets run with their own sensors (encoder, current noise, ADC). ``--controller
    optimum``: the tracked optimum's module (the paper drive with K = 0.3 and limits instead of K = 1000).
    """
    ap = argparse.ArgumentParser(prog="python scripts/c_verify.py",
                                 description=main.__doc__.splitlines()[0])
    ap.add_argument("--controller", choices=("fdsmc", "optimum"), default="fdsmc")
    law = ap.parse_args(argv).controller
    limits = ["controller.K=0.3", "controller.delay_samples=1", "controller.V_dc=300", "controller.i_max=40"]
    cases = ([("paper, K = 1000", "paper_12kw_pmsm", [])] if law == "fdsmc" else
             [("paper, K = 0.3, limits", "paper_12kw_pmsm", limits)])
    cases += [("paper, K = 0.3", "paper_12kw_pmsm", ["controller.K=0.3"])]
    cases += [(n, n, []) for n in list_presets()
              if n != "paper_12kw_pmsm" and isinstance(load_preset(n), DriveParams)]
    for label, preset, sets in cases:
        params = load_preset(preset, sets)
        cmp = compare(params, ("fdsmc", "conventional", "optimum") if law == "optimum" else ("fdsmc", "conventional"))
        run = cmp.optimum if law == "optimum" else cmp.fdsmc
        with tempfile.TemporaryDirectory() as tmp:
            for name, text in c_files(cmp, run_checks(params, run), force=True, controller=law).items():
                (Path(tmp) / name).write_text(text, encoding="utf-8")
            same = [replay(Path(tmp), single) for single in (False, True)]
        for single in (False, True):
            err = measure(params, single, law)
            text = "  ".join(f"{k} {v:.1e}" for k, v in err.items())
            print(f"{label:22s} {'float32' if single else 'double':7s} closed loop: {text}; same readings: "
                  f"u {same[single]:.1e}", flush=True)


if __name__ == "__main__":
    main()
