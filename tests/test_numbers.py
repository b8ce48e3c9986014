"""The engineers' number parser: what is typed is what reaches the physics, or a message."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from pmsm_commissioning.app.io.numbers import NumberFormatError, format_number, parse_integer, parse_number


@pytest.mark.parametrize(("text", "value"), [
    ("1e3", 1000.0), ("2.5e-3", 2.5e-3), ("4.86E-5", 4.86e-5), ("-0.5", -0.5), ("1 000", 1000.0),
    ("0.0000486", 4.86e-5), ("017", 17.0), (" +12.5 ", 12.5), (".5", 0.5), ("1\u2009000.25", 1000.25),
])
def test_accepted_forms_mean_what_they_look_like(text: str, value: float) -> None:
    assert parse_number(text, "motor.J_r") == value


@pytest.mark.parametrize("text", ["1,5", "1.2.3", "abc", "", "  ", "nan", "NaN", "inf", "-Infinity", "0x10",
                                  "1_000", "1:30", "12 34", "1 0000", "e5", "1e", "--1", "1e400"])
def test_rejected_forms_name_field_and_allowed_form(text: str) -> None:
    with pytest.raises(NumberFormatError) as exc:
        parse_number(text, "motor.J_r")
    msg = str(exc.value)
    assert msg.startswith("motor.J_r = ")
    assert "allowed" in msg


def test_integer_fields_refuse_fractions() -> None:
    assert parse_integer("4", "motor.p") == 4
    assert parse_integer("1e1", "motor.p") == 10
    with pytest.raises(NumberFormatError, match="whole number"):
        parse_integer("4.5", "motor.p")


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_format_then_parse_is_exact(x: float) -> None:
    # Round trip at full double precision: a field shown with format_number reads back unchanged.
    y = parse_number(format_number(x), "x")
    assert y == x and math.copysign(1.0, y) == math.copysign(1.0, x) or x == 0.0
