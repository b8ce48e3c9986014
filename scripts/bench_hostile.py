"""Print how long each hostile parser attack takes to be refused (CPU seconds, best of 3).

Run: ``.venv/bin/python scripts/bench_hostile.py [--pure]``. The promise: every attack ≤ 0.5 s (a text
can cost no more than its size allows). The attacks are those of ``tests/hostile_inputs.py``
plus wide (many-key) files.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pmsm_commissioning.app.io import yaml_text  # noqa: E402
from pmsm_commissioning.app.io.presets import PresetError, load_preset, loads_preset  # noqa: E402
from tests.hostile_inputs import attacks  # noqa: E402

PAPER = "paper_12kw_pmsm"


def _wide() -> dict[str, tuple[str, str, str]]:
    """Wide texts of ≈ 250 KiB: many keys, many items, long scalars, lines without content."""
    n, size = 20_000, 250_000
    return {"json: 20 000 keys in one object": ("json", "{" + ",".join(f'"k{i}":1' for i in range(n)) + "}", ""),
            "yaml: 20 000 keys in one mapping": ("yaml", "".join(f"k{i}: 1\n" for i in range(n)), ""),
            "yaml: 125 000 items in one flow list": ("yaml", "k: [" + "1," * (size // 2 - 4) + "1]\n", ""),
            "yaml: 62 000 block items": ("yaml", "k:\n" + "- 1\n" * (size // 4 - 1), ""),
            "yaml: 9 000 items of 6 lines each": ("yaml", "k:\n" + "- a\n  b\n  c\n  d\n  e\n  f\n" * 9_000, ""),
            "yaml: 250 000 blank lines": ("yaml", "\n" * size + "k: 1\n", ""),
            "yaml: one 250 000-character plain scalar": ("yaml", "k: " + "a" * size + "\n", "")}


def _feed(kind: str, text: str) -> str:
    try:
        if kind == "set":
            load_preset(PAPER, [text])
        else:
            loads_preset(text, f"attack.{kind}")
    except PresetError as exc:
        return str(exc)
    except ValueError as exc:
        return f"{type(exc).__name__}: {exc}"
    return "accepted"


def main() -> None:
    """Print one line per attack: CPU time, text size, the start of the refusal.

    ``--pure`` measures the pure-Python YAML path (used when PyYAML lacks libyaml).
    """
    if "--pure" in sys.argv:
        yaml_text._CLoader = None
    load_preset(PAPER)  # warm the preset cache
    worst = 0.0
    for name, (kind, text, _) in {**attacks(), **_wide()}.items():
        best = float("inf")
        for _ in range(3):
            t0 = time.process_time()
            message = _feed(kind, text)
            best = min(best, time.process_time() - t0)
        worst = max(worst, best)
        print(f"{best * 1e3:8.1f} ms  {len(text.encode()) / 1024:7.1f} KiB  {name}: {message[:90]}")
    print(f"worst {worst * 1e3:.1f} ms (promise ≤ 500 ms)")


if __name__ == "__main__":
    main()
