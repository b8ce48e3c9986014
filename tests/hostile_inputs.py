"""Parser attacks (nesting blow-ups, quote/comment tricks), shared by the regression
tests (``tests/test_faults_parsers.py``) and the timing script (``scripts/bench_hostile.py``).

Each entry: name → (how it is fed: ``yaml``, ``json`` or ``set``, the text, what the refusal says).
"""

from __future__ import annotations

KIB = 1024
N_BIG = 120_000  # brackets in a ≈ 250 KiB file (the 254 KiB case)


DEEP = "nested too deeply"


def attacks() -> dict[str, tuple[str, str, str]]:
    """The hostile texts, by name."""
    return {
        "set: '#' in a flow scalar hides 10 000 brackets": (
            "set", "motor.R_s=[a#, " + "[" * 10_000 + "]" * 10_000 + "]", DEEP),
        "yaml: '\"' in a flow scalar hides brackets (≈ 250 KiB)": (
            "yaml", 'name: x\nx: ["\\"", ' + "[" * N_BIG, DEEP),
        "yaml: '#' in a flow scalar hides brackets (≈ 250 KiB)": ("yaml", "x: [a#, " + "[" * N_BIG, DEEP),
        "yaml: 20 000 plain brackets": ("yaml", "x: " + "[" * 20_000 + "]" * 20_000, DEEP),
        "yaml: 20 000 flow mappings": ("yaml", "x: " + "{a: " * 20_000 + "}" * 20_000, DEEP),
        "yaml: brackets after a quoted backslash (a string: invalid)": ("yaml", "x: ['#', '\\'', " + "[" * N_BIG,
                                                                       "not valid YAML"),
        "yaml: block sequences on one line": ("yaml", "- " * 60_000 + "x", DEEP),
        "yaml: nested block mappings": ("yaml", "".join(f"{' ' * i}k:\n" for i in range(700)), DEEP),
        "yaml: complex keys": ("yaml", "? " * 60_000 + "x", DEEP),
        "json: escaped quote then 600 brackets": ("json", '{"name":"\\"","x":' + "[" * 600, DEEP),
        "json: escaped quote then 120 000 brackets": ("json", '{"name":"\\"","x":' + "[" * N_BIG, DEEP),
        "json: brackets inside strings only": ("json", '{"name":"' + "[" * N_BIG + '"}', "characters long"),
        "json: unterminated string of backslash-quotes": ("json", '{"x": "' + '\\"' * (N_BIG // 2), "not valid JSON"),
    }


__all__ = ["attacks"]
