"""The energy the supply delivers to the DC link over a move, for each way the link handles regeneration.

The inverter's DC-link power is p_el = (3/2)·(u_d·i_d + u_q·i_q) (amplitude-invariant dq, eq. (5)
in [1]). Over a run it splits into the energy drawn from the link, W_drawn = ∫max(p_el, 0) dt, and
the energy returned to it while the motor brakes electrically, W_ret = ∫max(−p_el, 0) dt. What
the **supply** delivers depends on what the DC link does with the returned energy:

* ``braking_resistor`` — a stock servo drive: the returned energy lifts the bus voltage until the
  brake chopper burns it in the resistor; the supply delivers W_drawn.
* ``regenerative`` — an active front end (or a bus shared with motoring axes) takes it back in full:
  W_drawn − W_ret, the net electrical input.
* ``battery`` — a battery takes it back at its charge efficiency η_ch: W_drawn − η_ch·W_ret.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math

#: The DC link's choices, the default first (what a stock servo drive has).
DC_LINKS = ("braking_resistor", "regenerative", "battery")

#: What each choice means, as every output says it.
DC_LINK_MEANING = {
    "braking_resistor": "the supply delivers the energy drawn; the regenerated energy is burnt",
    "regenerative": "the regenerated energy goes back to the supply: the net electrical input",
    "battery": "the supply delivers the energy drawn less η_ch × the regenerated energy",
}


def supply_energy(W_drawn: float, W_ret: float, dc_link: str, eta_ch: float = 1.0) -> float:
    """Return the energy the supply delivers to the DC link [J].

    Parameters
    ----------
    W_drawn : float    Energy drawn from the DC link, ∫max(p_el, 0) dt [J].
    W_ret : float      Energy returned to the DC link (regenerated), ∫max(−p_el, 0) dt ≥ 0 [J].
    dc_link : str      One of :data:`DC_LINKS`.
    eta_ch : float     Battery charge efficiency η_ch ∈ [0, 1] [-]; used only for ``battery``.

    Returns
    -------
    float
        ``braking_resistor``: W_drawn; ``regenerative``: W_drawn − W_ret; ``battery``:
        W_drawn − η_ch·W_ret [J]. NaN in, NaN out.

    Raises
    ------
    ValueError
        For a ``dc_link`` not in :data:`DC_LINKS`.
    """
    if dc_link == "braking_resistor":
        return W_drawn
    if dc_link == "regenerative":
        return W_drawn - W_ret
    if dc_link == "battery":
        return W_drawn - eta_ch * W_ret
    raise ValueError(f"dc_link = {dc_link!r} is not allowed: one of {', '.join(DC_LINKS)}")


def dc_link_text(dc_link: str, eta_ch: float) -> str:
    """Return the choice as the outputs say it, e.g. ``"DC link braking_resistor (the supply delivers …)"``."""
    eta = f", η_ch = {eta_ch:g}" if dc_link == "battery" and math.isfinite(eta_ch) else ""
    return f"DC link {dc_link}{eta} ({DC_LINK_MEANING[dc_link]})"


__all__ = ["DC_LINKS", "DC_LINK_MEANING", "dc_link_text", "supply_energy"]
