"""Compiled duty-cycle run: the moves of a cycle back to back in one continuous simulation.

The same plant, FDC inner loops, observer and outer laws as the single-move kernel
(:func:`sim.fdsmc.kernel_run.run_kernel`, whose inlined steps are reused here, not rewritten), with
the state — currents, position, speed, the observer's estimates, the held voltages and the
energy integrals — carried from one segment (a move and its dwell) into the next. At a segment's
start the outer loop switches to that move's design (row of ``prm_all``: its θ_dem as an absolute
target, its profile, gains and reference); the outer law's time restarts at 0, the plant's (load
steps and ramp) runs on.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pmsm_commissioning.sim.common.borrowed import borrowed
from pmsm_commissioning.sim.fdsmc import kernel as kn
from pmsm_commissioning.sim.fdsmc import kernel_run
from pmsm_commissioning.sim.fdsmc import layout as lay

#: Per-segment values stored in ``seg_info`` (row per segment): the state at its end.
SEG_X = lay.N_X


@njit(cache=True, nogil=True, error_model="numpy")
def run_cycle(prm_all: np.ndarray, seg_steps: np.ndarray, ref_all: np.ndarray, ref_off: np.ndarray,
              step_t: np.ndarray, step_v: np.ndarray, Phi: np.ndarray, Gam: np.ndarray, Lo: np.ndarray,
              continuous: bool, h: float, n_sub: int, delay: int, decim: int, out: np.ndarray,
              seg_info: np.ndarray, noise: np.ndarray) -> int:
    """Integrate the whole cycle from rest.

    Returns the number of trace points written to ``out`` (N_CH × points, every ``decim``-th
    step), or −(points + 1) when the run diverged.

    Segment j lasts ``seg_steps[j]`` samples (digital; RK4 steps in continuous mode) with the
    parameters ``prm_all[j]`` and the reference ``ref_all[:, ref_off[j]:ref_off[j + 1]]``.
    ``seg_info[j]`` receives the kernel state (``X_*`` of :mod:`sim.fdsmc.kernel`) at its end.
    ``noise`` is the sensors' table (:func:`sim.common.sensors.noise_table`), read by sample number.
    """
    prm_all, seg_steps, ref_all, ref_off = borrowed(prm_all), borrowed(seg_steps), borrowed(ref_all), borrowed(ref_off)
    step_t, step_v, Phi, Gam, Lo = borrowed(step_t), borrowed(step_v), borrowed(Phi), borrowed(Gam), borrowed(Lo)
    out, seg_info, noise = borrowed(out), borrowed(seg_info), borrowed(noise)  # no reference counts in the loop
    p: kn.Floats = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    o: kn.Floats = (0.0, 0.0, 0.0, 0.0)
    hold: kn.Floats = kn.HOLD0
    t, k_all, n_out = 0.0, 0, 0
    for j in range(seg_steps.size):
        prm = prm_all[j]
        ref = ref_all[:, ref_off[j]: ref_off[j + 1]]
        t_start = t
        for _ in range(seg_steps[j]):
            u, o_next, hold, rec, sat = kn.step_sample(k_all, t - t_start, p, o, hold, continuous, delay, prm,
                                                       Phi, Gam, Lo, ref, noise)
            if k_all % decim == 0 and n_out < out.shape[1]:
                kernel_run.record(out[:, n_out], t, p, o, rec, prm, step_t, step_v)
                n_out += 1
            o = o_next
            for _ in range(n_sub):
                if continuous:
                    p, o = kn.rk4_continuous(t - t_start, h, p, o, prm, step_t, step_v, ref)
                else:
                    p = kn.rk4_plant(t, h, p, u[0], u[1], prm, step_t, step_v)
                t += h
            k_all += 1
            if kernel_run.diverged(p, o, prm):
                return -(n_out + 1)
        kernel_run.store_state(seg_info[j], 0, p, o, 1.0, p)
    return n_out
