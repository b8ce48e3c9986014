"""Print the closed-form standstill ripple against the simulated one on the shipped real presets.

The table of ``docs/real_drive.md`` ("Noise gain with the shipped controller"): simulated/predicted
for the current-noise part (ideal encoder) and the quantization part at 2¹³, 2¹⁷ and 2²⁰ counts, with
the rotor's jitter in counts and the white Δ²/12 model beside the coloured one. The runs and the
predictions are those of ``tests/test_noise_tdv.py``.

Usage: ``python scripts/noise_table.py``
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pmsm_commissioning.control.fdsmc.noise import noise_gain  # noqa: E402
from tests.test_noise_tdv import REAL, hold_i_q, predicted  # noqa: E402

DITHER = ("sensors.i_adc_bits=0",)


def quantization_cell(name: str, bits: int) -> str:
    """``coloured (white), jitter`` for one preset and encoder, or why there is no linear loop."""
    ov = (*DITHER, f"sensors.encoder_cpr={2**bits}")
    p, d, g = predicted(name, ov)
    if d.gain.K_noise < p.controller.K:
        return "K > K_noise"
    ripple = float(np.std(hold_i_q(name, ov) - hold_i_q(name, (*DITHER, "sensors.encoder_cpr=0"))))
    c = p.controller
    white = noise_gain(d.loop, "slope", c.K, p.sensors.encoder_step, p.sensors.reading_noise, c.T_dv, coloured=False)
    return f"{ripple / g.i_q_quant_rms:.2f} ({ripple / white.i_q_quant_rms:.2f}), {g.jitter_counts:.2g}"


def main() -> None:
    print("| preset | current noise | 2¹³ counts | 2¹⁷ | 2²⁰ |")
    print("|---|---|---|---|---|")
    for name in REAL:
        ov = ("sensors.encoder_cpr=0",)
        _, _, g = predicted(name, ov)
        current = float(np.std(hold_i_q(name, ov))) / g.i_q_rms
        cells = [quantization_cell(name, bits) for bits in (13, 17, 20)]
        print(f"| {name} | {current:.2f} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
