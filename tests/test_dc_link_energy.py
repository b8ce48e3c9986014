"""Energy at the DC link (drawn, returned, net, the supply's under the DC-link choice) and every run's trace."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pmsm_commissioning.app.cli.main import main

PRESET = "yaskawa_sgm7j_02a"  # a clean shipped design; the tracked optimum is recommended


def _csv(path):
    head = path.read_text().splitlines()[0].split(",")
    names = np.genfromtxt(path, delimiter=",", skip_header=1, usecols=0, dtype=str)
    data = np.genfromtxt(path, delimiter=",", skip_header=1)[:, 1:]
    return names, {k: data[:, i] for i, k in enumerate(head[1:])}


def test_every_run_in_the_csv_and_its_dc_link_energies(tmp_path, capsys):
    """simulate --csv holds the four controllers; per run drawn = ∫max(p, 0) dt, returned = drawn − net, the
    supply's energy under the default DC link (a braking resistor) = drawn; the CSV's cumulative energies end
    at the JSON's figures; the recommendation is the clean run drawing least.
    """
    path = tmp_path / "all.csv"
    assert main(["simulate", PRESET, "--json", "--csv", str(path)]) == 0
    out = json.loads(capsys.readouterr().out)
    names, cols = _csv(path)
    assert set(names) == {"fdsmc", "conventional", "optimum", "stock"}
    assert out["dc_link"]["choice"] == "braking_resistor" and "dc_link_J" in out["energy_basis"]
    clean = [c for c in ("fdsmc", "conventional", "optimum", "stock") if not out[c]["checks_failed"]]
    assert out["recommended"]["controller"] == min(clean, key=lambda c: out[c]["dc_link_J"])
    assert out["recommended"]["dc_link"] == "braking_resistor" and "braking_resistor" in out["recommended"]["why"]
    for ctrl in ("fdsmc", "conventional", "optimum", "stock"):
        run, link = out[ctrl], out[ctrl]["dc_link"]
        rows = names == ctrl
        assert cols["E_electrical [J]"][rows][-1] == pytest.approx(run["electrical_in_total_J"], rel=1e-5)
        assert cols["E_motoring [J]"][rows][-1] == pytest.approx(link["drawn_J"], rel=1e-5)
        assert link["drawn_J"] == run["motoring_total_J"] == link["braking_resistor_supply_J"] == run["dc_link_J"]
        assert link["returned_J"] == pytest.approx(link["drawn_J"] - link["net_J"], abs=1e-12)
        assert link["returned_J"] == pytest.approx(run["regenerated_total_J"], rel=1e-12)
        assert link["drawn_J"] > link["net_J"] > 0.0  # the servo brakes electrically: energy goes back
    w_net, w_drawn = (out["fdsmc"]["electrical_in_total_J"], out["optimum"]["electrical_in_total_J"]), (
        out["fdsmc"]["dc_link"]["drawn_J"], out["optimum"]["dc_link"]["drawn_J"])
    assert out["fdsmc"]["saving_vs_optimum_pct"] == pytest.approx(100 * (1 - w_net[1] / w_net[0]), rel=1e-9)
    assert out["fdsmc"]["saving_vs_optimum_drawn_pct"] == pytest.approx(100 * (1 - w_drawn[1] / w_drawn[0]), rel=1e-9)
    assert out["fdsmc"]["saving_vs_optimum_dc_link_pct"] == out["fdsmc"]["saving_vs_optimum_drawn_pct"]


def test_the_recommended_optimum_alone_is_exported_and_its_energy_recomputes(tmp_path, capsys):
    """--controller optimum --csv on a clean design (was refused as "T_m is infeasible"): the CSV's
    p = 3/2·(u_d·i_d + u_q·i_q) integrated over its samples gives the JSON's net and drawn energy (1 %).
    """
    path = tmp_path / "optimum.csv"
    assert main(["simulate", PRESET, "--controller", "optimum", "--json", "--csv", str(path)]) == 0
    out = json.loads(capsys.readouterr().out)
    names, c = _csv(path)
    assert set(names) == {"optimum"}
    p = 1.5 * (c["u_d [V]"] * c["i_d [A]"] + c["u_q [V]"] * c["i_q [A]"])
    assert np.trapezoid(p, c["t [s]"]) == pytest.approx(out["optimum"]["electrical_in_total_J"], rel=0.01)
    assert np.trapezoid(np.maximum(p, 0.0), c["t [s]"]) == pytest.approx(out["optimum"]["dc_link"]["drawn_J"],
                                                                          rel=0.01)


def test_supply_energy_closed_form():
    """Braking resistor: W_drawn; regenerative: W_drawn − W_ret; battery: W_drawn − η_ch·W_ret."""
    from pmsm_commissioning.control.common.dc_link import DC_LINKS, supply_energy

    W_drawn, W_ret = 3.89, 2.57  # a servo's FDSMC move: 1.32 J net
    assert DC_LINKS[0] == "braking_resistor"  # the default: what a stock servo drive has
    assert supply_energy(W_drawn, W_ret, "braking_resistor", 0.5) == W_drawn
    assert supply_energy(W_drawn, W_ret, "regenerative") == pytest.approx(1.32, abs=1e-12)
    assert supply_energy(W_drawn, W_ret, "battery", 0.9) == pytest.approx(3.89 - 0.9 * 2.57, abs=1e-12)
    assert supply_energy(W_drawn, W_ret, "battery", 1.0) == supply_energy(W_drawn, W_ret, "regenerative")
    assert supply_energy(W_drawn, W_ret, "battery", 0.0) == W_drawn
    with pytest.raises(ValueError, match="one of braking_resistor, regenerative, battery"):
        supply_energy(W_drawn, W_ret, "capacitor")


def test_the_dc_link_choice_changes_the_recommendation_and_the_headline(capsys):
    """On the SGM7J-02A the tracked optimum returns the most energy: netted it is least (recommended with a
    regenerative link), drawn the stock drive's trapezoid is least (recommended with a braking resistor).
    """
    assert main(["simulate", PRESET, "--set", "controller.dc_link=regenerative", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["dc_link"]["choice"] == "regenerative"
    runs = {c: out[c] for c in ("fdsmc", "conventional", "optimum", "stock")}
    for run in runs.values():
        assert run["dc_link_J"] == pytest.approx(run["net_electrical_J"], rel=1e-12)
    assert out["recommended"]["controller"] == "optimum"
    # the default (braking resistor) ranks the same runs by the energy drawn: another controller
    drawn = {c: r["dc_link"]["drawn_J"] for c, r in runs.items() if not r["checks_failed"]}
    assert min(drawn, key=drawn.get) == "stock" != out["recommended"]["controller"]
    # the headline of the text output names the choice and gives its figures
    assert main(["simulate", PRESET, "--set", "controller.dc_link=battery",
                 "--set", "controller.charge_efficiency=0.5"]) == 0
    head = capsys.readouterr().out.splitlines()[2]
    assert head.startswith("Energy from the supply, whole run (DC link battery, η_ch = 0.5")
    battery = runs["fdsmc"]["dc_link"]["drawn_J"] - 0.5 * runs["fdsmc"]["dc_link"]["returned_J"]
    assert f"FDSMC {battery:.4g} J" in head


def test_recommend_ranks_by_the_supply_energy_of_each_choice():
    """The same runs ranked under each choice: the clean one whose supply energy is least is recommended."""
    import dataclasses

    from pmsm_commissioning.control.common.dc_link import supply_energy
    from pmsm_commissioning.control.fdsmc.params import Controller
    from pmsm_commissioning.sim.fdsmc.recommend import ControllerEnergy, rank

    runs = (ControllerEnergy("optimum", 3.99, 3.0, 0.9, (), 35.1, 31.11),
            ControllerEnergy("stock", 7.76, 6.0, 1.7, (), 23.9, 16.14),
            ControllerEnergy("conventional", 13.0, 12.0, 1.0, ("in_position",), 20.0, 7.0))

    def ranked(link, eta=0.9):
        c = Controller(T_si=1e-3, T_salpha=1e-2, T_so=1e-2, K=1.0, dc_link=link, charge_efficiency=eta)
        return rank(tuple(dataclasses.replace(e, dc_link_J=supply_energy(e.drawn_J, e.returned_J, link, eta))
                          for e in runs), c)

    assert ranked("regenerative").controller == "optimum"  # 3.99 < 7.76 J net
    assert ranked("braking_resistor").controller == "stock"  # 23.9 < 35.1 J drawn; the conventional fails a check
    assert ranked("battery", 0.9).controller == "optimum"  # 35.1 − 0.9·31.11 = 7.10 < 23.9 − 0.9·16.14 = 9.37 J
    assert ranked("battery", 0.3).controller == "stock"  # 25.8 > 19.1 J
    assert "DC link braking_resistor" in ranked("braking_resistor").why
    assert ranked("battery").dc_link.startswith("DC link battery, η_ch = 0.9")


def test_a_bad_dc_link_is_refused_naming_field_value_and_choices(tmp_path, capsys):
    """The YAML loader and --set refuse an unknown choice or an efficiency outside [0, 1], in one line."""
    from pmsm_commissioning.app.io.presets import resolve

    text = resolve(PRESET).read_text(encoding="utf-8")
    assert text.count("\ncontroller:\n") == 1
    path = tmp_path / "bad.yaml"
    path.write_text(text.replace("\ncontroller:\n", "\ncontroller:\n  dc_link: supercap\n"), encoding="utf-8")
    assert main(["derive", str(path)]) == 2
    err = capsys.readouterr().err
    assert "controller.dc_link = 'supercap' is not allowed: one of braking_resistor, regenerative, battery" in err
    assert "Traceback" not in err
    assert main(["derive", PRESET, "--set", "controller.charge_efficiency=1.2"]) == 2
    assert "controller.charge_efficiency = 1.2 is out of range: allowed 0 ≤ value ≤ 1" in capsys.readouterr().err
