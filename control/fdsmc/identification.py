"""Least-squares identification of the PMSM model of [1] from a sampled drive log.

Nothing is differentiated: each equation is integrated over consecutive windows of the log
and the window integrals are fitted by least squares (instrumental variables for the current
differences Δi, whose sample noise would otherwise bias the inductances towards zero).

* Electrical, eqs. (1)–(2) in [1] multiplied out (amplitude-invariant dq, ω_r mechanical)::

      ∫u_d dt = R_s·∫i_d dt + L_d·Δi_d − L_q·p·∫i_q dθ_r
      ∫u_q dt = R_s·∫i_q dt + L_q·Δi_q + L_d·p·∫i_d dθ_r + Ψ_PM·p·Δθ_r

  The logged voltages are taken as zero-order-held over each sample; the sample delay between
  the logged (commanded) voltage and the applied one is chosen among 0…3 samples by the
  smallest residual.
* Mechanical, eqs. (4a), (5), (6) in [1] with a constant external torque Γ_Le::

      ∫Γ_em dt = J_total·Δω_r + F_v·Δθ_r + Γ_Le·Δt

  with Γ_em of eq. (5) from the identified Ψ_PM, L_d − L_q, and ω_r at the window ends from a
  Savitzky–Golay derivative of θ_r (cubic, over half a mechanical window) when θ_r is logged.

A parameter the log does not excite is refused with the reason instead of being reported.

Standard errors are the classical ones of the fit. Consecutive windows share their edge
samples, so the current noise enters as a difference (negatively correlated rows) and the
intervals are conservative, most for the slowly varying terms: on the example logs the standard
errors are 1.3× (J) to 13× (Ψ_PM) the scatter of the estimates over noise draws.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import savgol_filter
from scipy.stats import t as student_t

from pmsm_commissioning.control.common.arrays import FloatArray
from pmsm_commissioning.control.fdsmc.model import electromagnetic_torque

#: Largest relative standard error of a reported estimate [-]; above it the parameter is refused.
MAX_REL_STDERR = 0.2
#: Sample delays tried between logged and applied voltage [samples].
DELAYS = (0, 1, 2, 3)
#: Samples either side averaged into the instrument of Δi [-].
NEIGHBOURS = 5


@dataclass(frozen=True)
class Estimate:
    """One identified parameter (SI) or the reason it was refused.

    Attributes
    ----------
    name : str  Symbol, e.g. ``"R_s"``.
    unit : str  SI unit of value, stderr and ci95.
    value, stderr : float or None  Estimate and its standard error.
    ci95 : tuple of float or None  95 % confidence interval (Student t).
    refused : str or None  Why the log does not determine the parameter.
    """

    name: str
    unit: str
    value: float | None = None
    stderr: float | None = None
    ci95: tuple[float, float] | None = None
    refused: str | None = None


@dataclass(frozen=True)
class Identification:
    """Result of :func:`identify`.

    Attributes
    ----------
    estimates : tuple of Estimate  R_s, L_d, L_q, psi_pm, J_total, F_v, Gamma_Le (in that order).
    voltage_delay_samples : int or None  Chosen delay of the applied voltage [samples].
    residual_electrical_V : float or None  RMS of the window-mean voltage residual [V].
    residual_mechanical_Nm : float or None  RMS of the window-mean torque residual [N·m].
    windows_electrical, windows_mechanical : int  Rows of each fit.
    """

    estimates: tuple[Estimate, ...]
    voltage_delay_samples: int | None
    residual_electrical_V: float | None
    residual_mechanical_Nm: float | None
    windows_electrical: int
    windows_mechanical: int

    def get(self, name: str) -> Estimate:
        """Return the estimate called ``name``."""
        return next(e for e in self.estimates if e.name == name)


@dataclass(frozen=True)
class _Fit:
    x: np.ndarray
    se: np.ndarray
    dof: int
    rss: float
    rows: int


ELECTRICAL = (("R_s", "Ω"), ("L_d", "H"), ("L_q", "H"), ("psi_pm", "Wb"))
MECHANICAL = (("J_total", "kg·m²"), ("F_v", "N·m·s/rad"), ("Gamma_Le", "N·m"))


def _ols(A: np.ndarray, y: np.ndarray, Z: np.ndarray | None = None) -> _Fit:
    """Solve by least squares, or by instrumental variables when instruments ``Z`` are given.

    Least squares comes with the classical standard errors σ̂²·(AᵀA)⁻¹; with instruments ``Z`` (same shape as
    ``A``) the instrumental-variable estimate (ZᵀA)⁻¹Zᵀy and its covariance σ̂²·(ZᵀA)⁻¹ZᵀZ(AᵀZ)⁻¹, which stays
    unbiased when a regressor carries noise.
    """
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0.0] = 1.0
    As = A / scale
    Zs = As if Z is None else Z / scale
    ZA_inv = np.linalg.pinv(Zs.T @ As)
    x = ZA_inv @ (Zs.T @ y)
    r = y - As @ x
    dof = max(1, A.shape[0] - A.shape[1])
    cov = float(r @ r) / dof * ZA_inv @ (Zs.T @ Zs) @ ZA_inv.T
    return _Fit(x / scale, np.sqrt(np.maximum(np.diag(cov), 0.0)) / scale, dof, float(r @ r), A.shape[0])


def _windows(n: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Start and end sample indices of consecutive windows of ``w`` intervals in ``n`` samples."""
    a = np.arange(0, n - w, w)
    return a, a + w


def _window_sums(per_interval: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Sum of a per-interval quantity over each window [a, b) of intervals."""
    c = np.concatenate([[0.0], np.cumsum(per_interval)])
    sums: FloatArray = c[b] - c[a]
    return sums


def _estimates(fit: _Fit | None, spec: tuple[tuple[str, str], ...], refused: dict[str, str],
               active: list[str]) -> list[Estimate]:
    out = []
    q = float(student_t.ppf(0.975, fit.dof)) if fit is not None else 0.0
    for name, unit in spec:
        if name in refused or fit is None:
            out.append(Estimate(name, unit, refused=refused.get(name, "not identified")))
            continue
        j = active.index(name)
        v, se = float(fit.x[j]), float(fit.se[j])
        if not (np.isfinite(v) and np.isfinite(se)) or se > MAX_REL_STDERR * abs(v):
            rel = abs(se / v) * 100.0 if v else float("inf")
            out.append(Estimate(name, unit, refused=f"not excited by this log: relative standard error "
                                                  f"{rel:.3g} % > {MAX_REL_STDERR * 100:g} %"))
            continue
        out.append(Estimate(name, unit, v, se, (v - q * se, v + q * se)))
    return out


def _neighbours(i: np.ndarray) -> np.ndarray:
    """Mean of the NEIGHBOURS samples either side of each sample, the sample itself left out.

    Used as the instrument for Δi: it follows the current (exactly where it is linear) but not
    the noise of the sample itself, which sits in the regressor Δi and would bias L to zero.
    """
    m = NEIGHBOURS
    if i.size <= 2 * m:
        return i
    kernel = np.ones(2 * m + 1) / (2 * m)
    kernel[m] = 0.0
    out = np.convolve(i, kernel, mode="same")
    out[:m], out[-m:] = i[:m], i[-m:]
    return out


def _electrical_rows(t: np.ndarray, th: np.ndarray, i_d: np.ndarray, i_q: np.ndarray, u_d: np.ndarray,
                     u_q: np.ndarray, p: int, delay: int, w: int
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Window-integrated rows of eqs. (1)–(2) in [1]; columns R_s, L_d, L_q, Ψ_PM."""
    n = t.size - delay
    t, th, i_d, i_q = t[delay:], th[delay:], i_d[delay:], i_q[delay:]
    u_d, u_q = u_d[:n], u_q[:n]
    dt, dth = np.diff(t), np.diff(th)
    md, mq = 0.5 * (i_d[1:] + i_d[:-1]), 0.5 * (i_q[1:] + i_q[:-1])
    a, b = _windows(n, w)

    def S(v: FloatArray) -> FloatArray:
        return _window_sums(v, a, b)

    def D(x: FloatArray) -> FloatArray:
        change: FloatArray = x[b] - x[a]
        return change

    zero = np.zeros(a.size)
    A_d = np.column_stack([S(md * dt), D(i_d), -p * S(mq * dth), zero])
    A_q = np.column_stack([S(mq * dt), p * S(md * dth), D(i_q), p * S(dth)])
    Z_d, Z_q = A_d.copy(), A_q.copy()
    Z_d[:, 1], Z_q[:, 2] = D(_neighbours(i_d)), D(_neighbours(i_q))
    y_d, y_q = S(u_d[:-1] * dt), S(u_q[:-1] * dt)
    return np.vstack([A_d, A_q]), np.concatenate([y_d, y_q]), np.vstack([Z_d, Z_q]), float(np.mean(t[b] - t[a]))


def _electrical_refusals(th: np.ndarray, i_d: np.ndarray, i_q: np.ndarray, p: int) -> dict[str, str]:
    refused: dict[str, str] = {}
    i_scale = max(float(np.max(np.abs(i_q))), float(np.max(np.abs(i_d))), 1e-12)
    if np.ptp(i_d) < 0.05 * i_scale:
        refused["L_d"] = (f"i_d is nearly constant (peak-to-peak {np.ptp(i_d):.3g} A): L_d needs a d-axis "
                          "current step (a motor-ID injection)")
    if np.ptp(i_q) < 0.05 * i_scale:
        refused["L_q"] = f"i_q is nearly constant (peak-to-peak {np.ptp(i_q):.3g} A): L_q is not excited"
    if np.ptp(th) < 2.0 * np.pi / p:
        refused["psi_pm"] = (f"the rotor turns {np.ptp(th):.3g} rad, less than one electrical revolution "
                             f"(2π/p = {2 * np.pi / p:.3g} rad): no back-EMF to identify Ψ_PM")
    return refused


def identify_electrical(t: np.ndarray, theta_r: np.ndarray, i_d: np.ndarray, i_q: np.ndarray, u_d: np.ndarray,
                        u_q: np.ndarray, p: int, window_s: float = 2e-3
                        ) -> tuple[list[Estimate], int | None, float | None, int]:
    """R_s, L_d, L_q, Ψ_PM from eqs. (1)–(2) in [1] integrated over windows of ``window_s`` [s].

    Returns
    -------
    estimates, voltage delay [samples], RMS window-mean residual [V], number of rows.
    """
    refused = _electrical_refusals(theta_r, i_d, i_q, p)
    active = [name for name, _ in ELECTRICAL if name not in refused]
    cols = [i for i, (name, _) in enumerate(ELECTRICAL) if name in active]
    w = max(2, int(round(window_s / float(np.median(np.diff(t))))))
    best: tuple[float, int, _Fit, float] | None = None
    for delay in DELAYS:
        if t.size - delay < 4 * w:
            break
        A, y, Z, T_w = _electrical_rows(t, theta_r, i_d, i_q, u_d, u_q, p, delay, w)
        fit = _ols(A[:, cols], y, Z[:, cols])
        if best is None or fit.rss / fit.rows < best[0]:
            best = (fit.rss / fit.rows, delay, fit, T_w)
    if best is None:
        reason = f"the log is too short: fewer than {4 * w} samples for windows of {window_s:g} s"
        return [Estimate(n, u, refused=reason) for n, u in ELECTRICAL], None, None, 0
    ms, delay, fit, T_w = best
    return _estimates(fit, ELECTRICAL, refused, active), delay, float(np.sqrt(ms)) / T_w, fit.rows


def speed_from_angle(t: np.ndarray, theta_r: np.ndarray, span_s: float = 1e-2) -> np.ndarray:
    """ω_r [rad/s] from θ_r [rad]: Savitzky–Golay derivative (cubic) over ≈ ``span_s`` [s]."""
    T_s = float(np.median(np.diff(t)))
    n = max(7, int(round(span_s / T_s)) | 1)
    n = min(n, theta_r.size - (1 - theta_r.size % 2))
    omega_r: FloatArray = np.gradient(theta_r, t) if n < 5 else savgol_filter(theta_r, n, 3, deriv=1, delta=T_s)
    return omega_r


def identify_mechanical(t: np.ndarray, theta_r: np.ndarray, omega_r: np.ndarray, Gamma_em: np.ndarray,
                        window_s: float = 1e-2) -> tuple[list[Estimate], float | None, int]:
    """J_total, F_v, Γ_Le from eqs. (4a), (6) in [1] integrated over windows of ``window_s`` [s].

    Returns
    -------
    estimates, RMS window-mean torque residual [N·m], number of rows.
    """
    refused: dict[str, str] = {}
    if np.ptp(omega_r) < 1e-3 * max(1.0, float(np.max(np.abs(omega_r)))) or np.ptp(omega_r) < 0.1:
        why = (f"not excited by this log: the speed hardly changes (peak-to-peak {np.ptp(omega_r):.3g} rad/s), "
               "no acceleration")
        refused = {"J_total": why, "F_v": why}
    w = max(2, int(round(window_s / float(np.median(np.diff(t))))))
    a, b = _windows(t.size, w)
    if a.size < 4:
        reason = f"the log is too short: fewer than 4 windows of {window_s:g} s"
        return [Estimate(n, u, refused=reason) for n, u in MECHANICAL], None, 0
    dt = np.diff(t)
    A = np.column_stack([omega_r[b] - omega_r[a], theta_r[b] - theta_r[a], t[b] - t[a]])
    y = _window_sums(0.5 * (Gamma_em[1:] + Gamma_em[:-1]) * dt, a, b)
    active = [name for name, _ in MECHANICAL if name not in refused]
    cols = [i for i, (name, _) in enumerate(MECHANICAL) if name in active]
    fit = _ols(A[:, cols], y)
    T_w = float(np.mean(t[b] - t[a]))
    return _estimates(fit, MECHANICAL, refused, active), float(np.sqrt(fit.rss / fit.rows)) / T_w, fit.rows


def _value(estimates: list[Estimate], name: str, prior: float | None) -> float | None:
    e = next(x for x in estimates if x.name == name)
    return e.value if e.value is not None else prior


def identify(
    signals: dict[str, np.ndarray], p: int, *, psi_pm_prior: float | None = None,
    L_d_prior: float | None = None, L_q_prior: float | None = None,
    window_electrical_s: float = 2e-3, window_mechanical_s: float = 2e-2,
) -> Identification:
    """Identify R_s, L_d, L_q, Ψ_PM, J_total, F_v and Γ_Le from a log (see the module docstring).

    Parameters
    ----------
    signals : dict of str to numpy.ndarray
        ``t`` [s] (increasing, near-uniform) and any of ``theta_r`` [rad], ``omega_r`` [rad/s],
        ``i_d``, ``i_q`` [A], ``u_d``, ``u_q`` [V] (logged, i.e. commanded, voltages), SI units.
    p : int
        Pole pairs [-].
    psi_pm_prior, L_d_prior, L_q_prior : float or None
        Values [Wb, H] used in Γ_em of eq. (5) when the log cannot identify them (no voltages).
    window_electrical_s, window_mechanical_s : float
        Integration windows [s].

    Returns
    -------
    Identification
        Every parameter either estimated (value, standard error, 95 % interval) or refused.
    """
    t = np.asarray(signals["t"], dtype=float)
    th, w = signals.get("theta_r"), signals.get("omega_r")
    if th is None and w is not None:
        th = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t))])
    if th is not None:
        w = speed_from_angle(t, th, 0.5 * window_mechanical_s)
    have = {k for k in ("i_d", "i_q", "u_d", "u_q") if signals.get(k) is not None}
    if th is None or have < {"i_d", "i_q", "u_d", "u_q"}:
        missing = sorted({"i_d", "i_q", "u_d", "u_q"} - have) + ([] if th is not None else ["theta_r or omega_r"])
        why = f"the electrical equations need {', '.join(missing)}, which the log does not hold"
        el, delay, res_el, n_el = [Estimate(n, u, refused=why) for n, u in ELECTRICAL], None, None, 0
    else:
        el, delay, res_el, n_el = identify_electrical(
            t, th, signals["i_d"], signals["i_q"], signals["u_d"], signals["u_q"], p, window_electrical_s)
    psi = _value(el, "psi_pm", psi_pm_prior)
    L_d, L_q = _value(el, "L_d", L_d_prior), _value(el, "L_q", L_q_prior)
    if th is None or w is None or signals.get("i_q") is None or psi is None:
        why = "the mechanical equation needs θ_r or ω_r, i_q and Ψ_PM (identified or given)"
        mech, res_m, n_m = [Estimate(n, u, refused=why) for n, u in MECHANICAL], None, 0
    else:
        i_q = signals["i_q"]
        i_d = signals.get("i_d")
        if i_d is not None and L_d is not None and L_q is not None:
            Gamma_em = electromagnetic_torque(p, psi, L_d, L_q, i_d, i_q)
        else:  # the reluctance term is 0
            Gamma_em = electromagnetic_torque(p, psi, 0.0, 0.0, np.zeros_like(i_q), i_q)
        mech, res_m, n_m = identify_mechanical(t, th, w, Gamma_em, window_mechanical_s)
    return Identification(tuple(el + mech), delay, res_el, res_m, n_el, n_m)
