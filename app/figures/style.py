"""One style for every figure and number of the page: palette, line dashes, font sizes, rounding.

Colours are the Okabe–Ito palette (Okabe & Ito, *Color Universal Design*, 2008), chosen so that
every pair of colours drawn together in one figure stays apart for deutan and protan viewers
(CIEDE2000 ΔE ≥ 10 after the Machado et al. 2009 simulation, checked by ``tests/test_palette.py``);
each controller and phase also has its own dash pattern, a second cue that survives greyscale
printing. Font sizes are for a 1280×720 projector read from the back row: ≥ 14 px on plots (ticks,
legends, annotations), ≥ 16 px for titles, verdicts and key numbers.
"""

from __future__ import annotations

import math

#: The Okabe–Ito palette (hex sRGB).
OKABE_ITO: dict[str, str] = {
    "black": "#000000", "orange": "#E69F00", "sky_blue": "#56B4E9", "bluish_green": "#009E73",
    "yellow": "#F0E442", "blue": "#0072B2", "vermillion": "#D55E00", "reddish_purple": "#CC79A7",
}
_O = OKABE_ITO

#: Position drive: colour and dash per controller (FDSMC, conventional, minimum-energy optimum,
#: a drive's stock controller).
POSITION_COLOURS: dict[str, str] = {"fdsmc": _O["blue"], "conventional": _O["orange"],
                                    "optimum": _O["bluish_green"], "stock": _O["black"]}
POSITION_DASHES: dict[str, str] = {"fdsmc": "solid", "conventional": "dash", "optimum": "dashdot", "stock": "dot"}

#: BLDC speed drives: colour and dash per controller key of ``sim.bldc.engine.CONTROLLERS``.
BLDC_COLOURS: dict[str, str] = {"smc_integral": _O["blue"], "smc_plain": _O["orange"],
                                "pi_sinusoidal": _O["bluish_green"], "six_step": _O["reddish_purple"]}
BLDC_DASHES: dict[str, str] = {"smc_integral": "solid", "smc_plain": "dash", "pi_sinusoidal": "dot",
                               "six_step": "dashdot"}

#: Phase currents a, b, c: colour and dash.
PHASE_COLOURS: tuple[str, str, str] = (_O["vermillion"], _O["sky_blue"], _O["black"])
PHASE_DASHES: tuple[str, str, str] = ("solid", "dash", "dot")

#: The FDSMC's phases in the replay's trail (reaching, sliding, linear): colour and dash.
TRAIL_PHASE_COLOURS: tuple[str, str, str] = (_O["sky_blue"], _O["blue"], _O["reddish_purple"])
TRAIL_PHASE_DASHES: tuple[str, str, str] = ("dot", "solid", "longdash")

#: Reference lines (ω*, T*, boundaries) and warnings (limits exceeded, load steps).
REFERENCE_COLOUR = "#333333"
WARNING_COLOUR = _O["vermillion"]
#: A verdict's two colours: bad (chatter, over a limit, a load step) and good. On white, the dark red
#: has a contrast of 5.5:1 and the green 4.4:1 (for large or bold text, where they carry words).
BAD_COLOUR, GOOD_COLOUR = "#c92a2a", "#2b8a3e"

#: Colour groups drawn together in one figure: each pair must stay distinguishable.
FIGURE_GROUPS: dict[str, tuple[str, ...]] = {
    "position controllers": tuple(POSITION_COLOURS.values()),
    "bldc controllers": tuple(BLDC_COLOURS.values()),
    "phase currents": PHASE_COLOURS,
    "fdsmc trail phases and the other controllers": (*TRAIL_PHASE_COLOURS, POSITION_COLOURS["conventional"],
                                                      POSITION_COLOURS["optimum"]),
}

#: Font sizes [px]: plot text (ticks, legends, annotations), titles, verdicts and key numbers.
FONT_PX = 14
TITLE_PX = 16
KEY_PX = 16


def round_to_meaning(value: float, digits: int = 4) -> float:
    """Return ``value`` rounded to ``digits`` significant digits (never fewer than the integer part).

    1432.39448783 → 1432.0, 4.822855 → 4.823, 0.000123456 → 0.0001235. Non-finite values pass.
    """
    if not math.isfinite(value) or value == 0:
        return value
    exponent = math.floor(math.log10(abs(value)))
    return round(value, max(digits - 1 - exponent, 0))


def fmt(value: float | int | None, unit: str = "", digits: int = 4) -> str:
    """Text of a number rounded to its meaning, with its unit: the page's one number formatter.

    ``digits`` significant digits, but an integer part is never cut (12345.6 → "12346"); no
    exponent between 1e-4 and 1e6; "—" for None, NaN or ±inf. E.g. ``fmt(1432.39448783, "rpm")``
    → "1432 rpm", ``fmt(4.822855)`` → "4.823", ``fmt(2.5e-7, "s")`` → "2.5e-07 s".
    """
    if value is None or not math.isfinite(value):
        return "—"
    if isinstance(value, (bool, int)):
        text = str(value)
    else:
        x = round_to_meaning(float(value), digits)
        text = f"{x:.0f}" if 10 ** (digits - 1) <= abs(x) < 1e6 else f"{x:.{digits}g}"
        text = "0" if text in ("-0", "-0.0") else text
    return f"{text} {unit}" if unit else text


def line(key: str, width: float = 2.0) -> dict[str, object]:
    """Return the Plotly ``line`` of a position-drive controller or BLDC controller ``key``: colour and dash."""
    colours = POSITION_COLOURS if key in POSITION_COLOURS else BLDC_COLOURS
    dashes = POSITION_DASHES if key in POSITION_DASHES else BLDC_DASHES
    return {"color": colours[key], "dash": dashes[key], "width": width}


#: Plot layout defaults every figure's template carries (fonts ≥ 14 px; titles 16 px).
TEMPLATE_LAYOUT: dict[str, object] = {
    "font": {"size": FONT_PX},
    "title": {"font": {"size": TITLE_PX}},
    "legend": {"font": {"size": FONT_PX}},
    "hoverlabel": {"font": {"size": FONT_PX}},
    "annotationdefaults": {"font": {"size": FONT_PX}},
}

#: Client-side export: the figure is laid out at a 720p slide's size [px] (so its 14 px text is 14 px
#: on the slide), the SVG at that size, the PNG drawn at :data:`EXPORT_SCALE` (1920×1080 pixels: text
#: 21 px in the image, 14 px again once the slide shows it at 1280×720).
EXPORT_SIZE: tuple[int, int] = (1280, 720)
EXPORT_SCALE = 1.5

__all__ = ["BLDC_COLOURS", "BLDC_DASHES", "EXPORT_SCALE", "EXPORT_SIZE", "FIGURE_GROUPS", "FONT_PX", "KEY_PX",
           "OKABE_ITO",
           "PHASE_COLOURS", "PHASE_DASHES", "POSITION_COLOURS", "POSITION_DASHES", "REFERENCE_COLOUR",
           "TEMPLATE_LAYOUT", "TITLE_PX", "WARNING_COLOUR", "fmt", "line", "round_to_meaning"]
