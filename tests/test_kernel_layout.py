"""The FDSMC kernel's flat arrays are declared once, by name: indices generated, every slot packed."""

from __future__ import annotations

import dataclasses
from types import ModuleType

import numpy as np
import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.bldc.design import bldc_design
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.bldc import kernel as bldc_kernel
from pmsm_commissioning.sim.bldc.engine import CONTROLLERS as BLDC_CONTROLLERS
from pmsm_commissioning.sim.bldc.engine import pack_parameters as bldc_pack
from pmsm_commissioning.sim.common.layout import Layout
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.run import KERNEL_LAW, TRACKING_TO_THE_END, pack_parameters
from pmsm_commissioning.sim.fdsmc.trace import CHANNELS
from pmsm_commissioning.sim.stock.route import StockLoop, pack_loop

LAYOUTS = ((lay, lay.PRM), (lay, lay.STATE), (lay, lay.INFO), (bldc_kernel, bldc_kernel.PRM))


@pytest.mark.parametrize(("module", "layout"), LAYOUTS, ids=lambda x: getattr(x, "what", ""))
def test_each_constant_is_its_declared_slot(module: ModuleType, layout: Layout) -> None:
    """Every slot's name is a module constant holding its index; the slots tile the array without a gap."""
    at = 0
    for s in layout.slots:
        assert getattr(module, s.name) == s.index == at, s.name
        assert s.doc and (s.size == 1 or s.name.startswith("I_")), s.name
        at += s.size
    assert at == layout.size


def test_bldc_packing_fills_every_slot() -> None:
    """The BLDC packer writes every slot for each controller (none NaN) and the controller's code."""
    case = load_preset("bldc_smc_paper")
    assert bldc_kernel.PRM.size == bldc_kernel.N_PRM
    design = bldc_design(case)
    for code, controller in enumerate(BLDC_CONTROLLERS):
        prm = bldc_pack(case, design, controller)
        assert np.all(np.isfinite(prm)) and prm[bldc_kernel.P_CTRL] == code


def test_sizes_and_channels() -> None:
    """The array sizes follow from the declarations; the state's plant part ends where the observer's starts."""
    assert (lay.PRM.size, lay.STATE.size, lay.INFO.size) == (lay.N_PRM, lay.N_X, lay.N_INFO)
    assert lay.X_THH == 9 and lay.N_X - lay.X_THH == 4  # RK4's 9-tuple of the plant, the observer's 4-tuple
    assert lay.I_END == lay.I_SNAP + lay.N_X
    assert [getattr(lay, "C_" + n.upper()) for n in CHANNELS] == list(range(lay.N_CH))


def test_law_is_an_integer_enum_stored_exactly() -> None:
    """The controller codes are distinct small integers, exact as floats in the parameter vector."""
    codes = [int(v) for v in lay.Law]
    assert len(set(codes)) == len(codes) and all(float(c) == c for c in codes)
    assert set(KERNEL_LAW.values()) | {TRACKING_TO_THE_END, lay.Law.DRIVE} == set(lay.Law)


@pytest.mark.parametrize("controller", sorted(KERNEL_LAW))
def test_every_required_slot_is_packed(controller: str, paper_params: DriveParams) -> None:
    """pack_parameters writes every slot without a default: none is left NaN, and the law is the controller's."""
    p = paper_params
    prm = pack_parameters(p, derive(p), controller)
    assert prm.shape == (lay.N_PRM,) and np.all(np.isfinite(prm))
    assert prm[lay.P_CTRL] == KERNEL_LAW[controller]
    assert prm[lay.P_RS] == p.motor.R_s and prm[lay.P_THDEM] == p.manoeuvre.theta_dem


def test_stock_loop_fills_the_drive_slots(paper_params: DriveParams) -> None:
    """A stock drive's loop writes the law and its cycle; the FDSMC's packing leaves those slots at 0."""
    prm = pack_parameters(paper_params, derive(paper_params), "fdsmc")
    assert np.all(prm[lay.P_DLAW: lay.P_DREFDT + 1] == 0.0)
    loop = StockLoop("odrive", 8000.0, "cascade", 20.0, 0.5, 2.0, np.inf, 300.0, 0.0, 1.2, 40.0, 2000.0, True,
                     5.0, 5000.0, np.zeros((3, 2)), 1e-3)
    pack_loop(prm, loop, 100.0, 1e-4)
    assert prm[lay.P_CTRL] == lay.Law.DRIVE and prm[lay.P_DT] == 1.0 / 8000.0
    assert prm[lay.P_DKT] == 1.2 and prm[lay.P_DREFDT] == 1e-3 and prm[lay.P_DUMAX] == 100.0


def test_a_forgotten_slot_is_named() -> None:
    """A required slot left unwritten is an error that names it, never a silent 0."""
    layout = Layout("a test array")
    a = layout.slot("P_X", "x [m]")
    layout.slot("P_Y", "y [m]", 0.0)
    layout.block("I_Z", 3, "z [-]")
    v = layout.empty()
    v[a] = 1.0
    with pytest.raises(ValueError, match=r"a test array: not packed \(NaN\): I_Z$"):
        layout.check_filled(v)
    v[2:5] = 0.0
    layout.check_filled(v)
    with pytest.raises(ValueError, match="declared twice"):
        layout.slot("P_Y", "again")


def test_packing_rejects_a_nan_that_reaches_a_required_slot(paper_params: DriveParams) -> None:
    """A NaN reaching the packer (a derivation's bug) stops the run with the slot's name."""
    p = paper_params
    d = derive(p)
    bad = dataclasses.replace(d, observer=dataclasses.replace(d.observer, K2=float("nan")))
    with pytest.raises(ValueError, match="P_K2"):
        pack_parameters(p, bad, "fdsmc")
