"""The controller's model vs the plant's true values: ``--set plant.FIELD=VALUE`` overrides.

A ``plant.`` override changes the simulated drive only; the controller keeps designing with the
preset's (and the other overrides') values. FIELD is a motor or load field of the preset, with the
same unit suffixes as ``motor.`` / ``load.`` overrides (``plant.L_d_mH=6``, ``plant.J_L=0.3``).
The overrides go on top of the preset's own ``plant`` section (:func:`app.io.preset_schema.parse_plant`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

from pmsm_commissioning.app.io.presets import load_with_plant, require_mode
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams, Load, Motor

PREFIX = "plant."
MOTOR_FIELDS = tuple(f.name for f in dataclasses.fields(Motor))
LOAD_FIELDS = tuple(f.name for f in dataclasses.fields(Load) if f.name != "steps")


def with_plant_J_L(params: DriveParams, J_L: float) -> DriveParams:
    """``params`` with the load inertia ``J_L`` [kg·m²]: the plant of a model-mismatch run."""
    return dataclasses.replace(params, load=dataclasses.replace(params.load, J_L=J_L))


def plant_section(field: str) -> str:
    """``motor`` or ``load`` for a plant field (a unit suffix such as ``_mH`` is allowed)."""
    for name in (field, field.rsplit("_", 1)[0]):
        if name in MOTOR_FIELDS:
            return "motor"
        if name in LOAD_FIELDS:
            return "load"
    raise ParameterError(
        f"plant.{field} is not a plant value: allowed plant.FIELD with FIELD one of "
        f"{', '.join(MOTOR_FIELDS + LOAD_FIELDS)} (optionally with a unit suffix)")


def split_overrides(overrides: Iterable[str]) -> tuple[list[str], list[str]]:
    """Split into (the model's overrides, the plant's overrides mapped to ``motor.``/``load.`` fields)."""
    model, plant = [], []
    for item in overrides:
        if not item.startswith(PREFIX):
            model.append(item)
            continue
        key, sep, value = item[len(PREFIX):].partition("=")
        if not sep:
            raise ParameterError(f"--set {item!r} is not allowed: the form is plant.FIELD=VALUE")
        plant.append(f"{plant_section(key.strip())}.{key.strip()}={value}")
    return model, plant


def load_model_and_plant(preset: str, overrides: Iterable[str]) -> tuple[DriveParams, DriveParams | None]:
    """Return the controller's model and the plant.

    The plant is the preset's ``plant`` section with the ``plant.`` overrides on top (None when
    neither gives a value that differs from the model).
    """
    overrides = list(overrides)
    split_overrides(overrides)  # names a bad plant field before anything is loaded
    params, plant = load_with_plant(preset, overrides)
    return require_mode(params, "position", preset), plant
