"""Run the hostile suite as an attacker would and print the totals by category and the memory figures.

Run: ``.venv/bin/python scripts/bench_hostile.py [--pure] [--quick]``. Categories:

* **parsers** — the nesting/quote/comment attacks of ``tests/hostile_inputs.py`` and wide files
  (CPU time each, best of 3; the promise: every attack ≤ 0.5 s);
* **vendor files** — ODrive/VESC/moteus texts: deep nesting, 28 000 keys, duplicates, other digits;
* **CLI** — hostile options, keys, numbers, names and ``-o`` targets: exit 2 and one line each;
* **written files** — the generated corpus of hostile names/sources in every drive file, read back
  by our strict parsers: an added line, key, row or unknown entry is an injection;
* **websocket** — frames that are no message of the protocol: closed with 1007, no traceback logged;
* **memory** — row bombs and a 10 GB sparse file through every reader (peak RSS rise per input byte,
  promise ≤ 25×, in a child process: ``tests/peak_rss.py``);
* **processes** — ``kill -9`` and SIGHUP of a robustness run with its pool: processes left behind.

``--quick`` leaves out the websocket and process categories (they start a server and pools).
``--pure`` measures the pure-Python YAML path (used when PyYAML lacks libyaml).
"""

from __future__ import annotations

import contextlib
import io
import json
import signal
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pmsm_commissioning.app.cli.main import main  # noqa: E402
from pmsm_commissioning.app.io import yaml_text  # noqa: E402
from pmsm_commissioning.app.io.presets import PresetError, load_preset, loads_preset  # noqa: E402
from tests.hostile_inputs import attacks  # noqa: E402

PAPER = "paper_12kw_pmsm"
MAX_PER_BYTE = 25.0


@dataclass
class Tally:
    """One category's totals."""

    cases: int = 0
    refused: int = 0
    tracebacks: int = 0
    injections: int = 0
    orphans: int = 0

    def line(self, name: str) -> str:
        """Return the category's line of totals."""
        return (f"{name:14s} {self.cases:5d} cases, {self.refused:5d} refused with a message, "
                f"tracebacks = {self.tracebacks}, injections = {self.injections}, orphans = {self.orphans}")


def _answer(call: Callable[[], object]) -> tuple[str, bool]:
    """(one-line answer, True when it was a traceback: an exception other than the refusal kinds)."""
    try:
        call()
    except ValueError as exc:  # PresetError, ParameterError, LogError, NumberFormatError: refusals
        return str(exc), False
    except Exception as exc:  # noqa: BLE001 - that is what is counted
        return f"TRACEBACK {type(exc).__name__}: {exc}", True
    return "accepted", False


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


def _feed(kind: str, text: str) -> None:
    if kind == "set":
        load_preset(PAPER, [text])
    else:
        loads_preset(text, f"attack.{kind}")


def parsers() -> Tally:
    """The parser attacks: one line each with its CPU time (best of 3)."""
    tally, worst = Tally(), 0.0
    for name, (kind, text, _) in {**attacks(), **_wide()}.items():
        best, message, broke = float("inf"), "", False
        for _ in range(3):
            t0 = time.process_time()
            message, broke = _answer(lambda kind=kind, text=text: _feed(kind, text))
            best = min(best, time.process_time() - t0)
        worst = max(worst, best)
        tally.cases += 1
        tally.refused += message != "accepted" and not broke
        tally.tracebacks += broke
        print(f"  {best * 1e3:8.1f} ms  {len(text.encode()) / 1024:7.1f} KiB  {name}: {message[:90]}")
    print(f"  worst {worst * 1e3:.1f} ms (promise ≤ 500 ms)")
    return tally


def _vendor_cases() -> dict[str, tuple[str, str]]:
    keys = {f"k{i}": 1 for i in range(28_000)}
    vesc_r = "<MCConfiguration><ConfigVersion>2</ConfigVersion><foc_motor_r>{}</foc_motor_r></MCConfiguration>"
    cases = {"ODrive nested 5000 deep": ("odrive", '{"axis0": ' * 5000 + "1" + "}" * 5000),
             "ODrive 28 000 keys": ("odrive", json.dumps({"axis0": {"motor": {"config": keys}}})),
             "ODrive duplicated key": ("odrive", '{"axis0": {"a": 1, "a": 2}}'),
             "ODrive key with a newline": ("odrive", '{"axis0": {"motor": {"config": {"x\\nplant:": 1}}}}'),
             "moteus 28 000 lines": ("moteus", "".join(f"motor.k{i} 1\n" for i in range(28_000)))}
    for text in ("1_0", "١", "１", "१", "١٫٥", "0x10", "1e-400"):
        cases[f"VESC number {text!r}"] = ("vesc", vesc_r.format(text))
        cases[f"moteus number {text!r}"] = ("moteus", f"motor.resistance_ohm {text}\n")
    return cases


def vendor_files() -> Tally:
    """Vendor texts through import-drive's parser and mapping onto a base preset."""
    from pmsm_commissioning.app.exports.drives.import_drive import import_drive
    from pmsm_commissioning.app.io.presets import load

    base, tally = load("odrive_d5065_belt", (), mode="position"), Tally()
    for name, (fmt, text) in _vendor_cases().items():
        t0 = time.process_time()
        message, broke = _answer(lambda fmt=fmt, text=text: import_drive(text, fmt, base, "attack"))
        tally.cases += 1
        tally.refused += message != "accepted" and not broke
        tally.tracebacks += broke
        print(f"  {(time.process_time() - t0) * 1e3:8.1f} ms  {name}: {message[:90]}")
    return tally


def _cli_cases(tmp: Path) -> list[list[str]]:
    (tmp / "loop").symlink_to(tmp / "loop")
    ro = tmp / "ro.yaml"
    ro.write_text("x\n")
    ro.chmod(0o444)
    moves = tmp / "moves.yaml"
    moves.write_text("- {theta_dem: 1.0, T_m: 0.5, dwell: 1e300}\n")
    cases = [["robustness", PAPER, opt, text] for opt in ("--samples", "--seed", "--workers", "--cluster-timeout")
             for text in ("1_0", "١", "１")]
    cases += [["export", "yaskawa_sgm7j_04a", "--format", "moteus", opt, "m\nservo.max_voltage 1000", "-o",
               str(tmp / "m.cfg")] for opt in ("--name", "--source")]
    cases += [["derive", PAPER, "--set", s] for s in ("motor.Kv_rpm_per_V=0", "motor.Kv_rpm_per_V=-0",
                                                     "load.Gamma_Le=1e-400", "motor.R_s=[1, # 2]")]
    cases += [["export", PAPER, "--format", "csv", "-o", target]
              for target in ("/dev/null", "/dev/full", str(tmp / "loop"), str(ro))]
    cases += [["design", PAPER, "-o", "/dev/null"], ["bench", "--repeat", "1e9"],
              ["dutycycle", PAPER, str(moves)], ["dutycycle", PAPER, "/proc/self/mem"],
              ["log", "/dev/zero"], ["import-drive", "/proc/self/environ", "--format", "odrive", "--base",
                                     "odrive_d5065_belt", "-o", str(tmp / "x.yaml")]]
    return cases


def cli() -> Tally:
    """Hostile command lines run in this process: exit 2 and one line of message, never a traceback."""
    tally = Tally()
    with tempfile.TemporaryDirectory() as folder:
        for argv in _cli_cases(Path(folder)):
            err = io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                try:
                    rc = main(argv)
                except SystemExit as exc:  # argparse's refusals
                    rc = exc.code
                except Exception as exc:  # noqa: BLE001 - counted
                    rc, err = -1, io.StringIO(f"TRACEBACK {type(exc).__name__}: {exc}\n")
            text = err.getvalue()
            tally.cases += 1
            tally.tracebacks += rc == -1 or "Traceback" in text
            tally.refused += rc == 2 and text.strip().count("\n") == 0 and bool(text.strip())
            print(f"  rc {rc}  {' '.join(argv)[:70]!r}: {text.strip().splitlines()[-1][:90] if text.strip() else ''}")
    return tally


def written_files() -> Tally:
    """The corpus of hostile names/sources in every drive file, read back by our parsers."""
    import xml.etree.ElementTree as ET

    from pmsm_commissioning.app.cli.export import case
    from pmsm_commissioning.app.exports.drives import moteus, odrive, setpoints, vesc
    from pmsm_commissioning.app.exports.drives.stock import stock_settings
    from tests.test_hostile_round3 import _files, corpus

    cmp = case(load_preset("yaskawa_sgm7j_04a"), "odrive")
    cascade = stock_settings(cmp, "odrive")
    base = cmp, {"moteus": stock_settings(cmp, "moteus"), "odrive": cascade, "vesc": cascade, "setpoints": cascade}
    clean, tally = _files(base, "clean"), Tally()
    rows = setpoints.parse_setpoints(clean["setpoints"]).t.size
    for text in corpus():
        files = _files(base, text)
        tally.cases += len(files)
        tally.injections += sum(body.count("\n") != clean[f].count("\n") for f, body in files.items())
        tally.injections += moteus.parse_moteus(files["moteus"]).unknown != ()
        tally.injections += odrive.parse_odrive(files["odrive"]).unknown != ()
        tally.injections += vesc.parse_vesc(files["vesc"]).unknown != ()
        ET.fromstring(files["vesc"])
        tally.injections += setpoints.parse_setpoints(files["setpoints"]).t.size != rows
    print(f"  {len(corpus())} hostile names × {len(clean)} formats written and read back")
    return tally


def websocket() -> Tally:
    """Hostile frames to a served page: each closes its connection with 1007; log records with a traceback."""
    import logging

    from pmsm_commissioning.app.io.presets import DEFAULT_PRESET
    from pmsm_commissioning.app.ui.page import create_server
    from pmsm_commissioning.app.ui.web_guard import INVALID_FRAME
    from tests.net import free_port
    from tests.test_ui_hostile_frames import HOSTILE_FRAMES, _Records, _send

    server, _ = create_server(load_preset(DEFAULT_PRESET), DEFAULT_PRESET, port=free_port(), scene_3d=False)
    records, tally = _Records(), Tally()
    logging.getLogger().addHandler(records)
    try:
        for name, frame in HOSTILE_FRAMES.items():
            code = _send(f"127.0.0.1:{server.get_port()}", frame)
            tally.cases += 1
            tally.refused += code == INVALID_FRAME
            print(f"  close code {code}  {name}")
    finally:
        logging.getLogger().removeHandler(records)
        server.stop()
    tally.tracebacks = sum(bool(r.exc_info) or "Traceback" in r.getMessage() for r in records.records)
    return tally


def memory() -> Tally:
    """Peak RSS rise per input byte of row bombs and a 10 GB sparse file through every reader."""
    from tests.peak_rss import READERS, peak, row_bomb, sparse_file

    tally = Tally()
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        logs = [r for r in READERS if r.startswith("log")]
        files = [r for r in READERS if r != "log upload (page)"]  # an upload holds its bytes: not sparse
        inputs = [("row bomb, 8 M rows (16 MB)", row_bomb(tmp / "bomb8.csv", 8_000_000), logs),
                  ("row bomb, 1.9 M rows (3.8 MB)", row_bomb(tmp / "bomb2.csv", 1_900_000), logs),
                  ("sparse file, 10 GB", sparse_file(tmp / "sparse.yaml", 10 * 2**30), files)]
        for label, path, readers in inputs:
            for reader in readers:
                got = peak(reader, path)
                tally.cases += 1
                tally.refused += got.answer != "accepted" and not got.answer.startswith("TRACEBACK")
                flag = "" if got.per_byte <= MAX_PER_BYTE else "  OVER THE PROMISE"
                print(f"  {label:30s} {reader:27s} peak rise {got.rise_bytes / 2**20:7.1f} MB = "
                      f"{got.per_byte:8.4f} B/B{flag}: {got.answer[:70]}")
    print(f"  promise: ≤ {MAX_PER_BYTE:g} bytes of peak RSS per input byte")
    return tally


def processes() -> Tally:
    """kill -9 and SIGHUP of a robustness run with a pool of 2: processes left after 30 s."""
    import os

    from tests.test_faults_orphans import LONG_ROBUSTNESS, _children, _kill_group, _start, _workers_started
    from tests.test_faults_signals import _running

    tally = Tally()
    for sig in (signal.SIGKILL, signal.SIGHUP, signal.SIGTERM):
        proc = _start(LONG_ROBUSTNESS)
        try:
            started = _workers_started(proc) + _children(proc.pid, b"resource_tracker")
            (os.kill if sig == signal.SIGKILL else os.killpg)(proc.pid, sig)
            _, err = proc.communicate(timeout=60)
            deadline = time.monotonic() + 30.0
            while _running(started) and time.monotonic() < deadline:
                time.sleep(0.1)
            left = _running(started)
        finally:
            _kill_group(proc)
        tally.cases += 1
        tally.orphans += len(left)
        tally.tracebacks += "Traceback" in err
        tally.refused += sig == signal.SIGKILL or proc.returncode == 130
        print(f"  {signal.Signals(sig).name}: exit {proc.returncode}, {len(started)} children, {len(left)} left")
    return tally


def main_bench() -> None:
    """Print each category's cases and the totals."""
    if "--pure" in sys.argv:
        yaml_text._CLoader = None
    load_preset(PAPER)  # warm the preset cache
    categories: dict[str, Callable[[], Tally]] = {
        "parsers": parsers, "vendor files": vendor_files, "CLI": cli, "written files": written_files,
        "memory": memory}
    if "--quick" not in sys.argv:
        categories |= {"websocket": websocket, "processes": processes}
    totals = {}
    for name, run in categories.items():
        print(f"{name}:")
        totals[name] = run()
    print("\ntotals by category:")
    for name, tally in totals.items():
        print("  " + tally.line(name))
    whole = Tally(*(sum(getattr(t, f) for t in totals.values()) for f in Tally.__dataclass_fields__))
    print("  " + whole.line("all"))


if __name__ == "__main__":
    with contextlib.suppress(PresetError):
        main_bench()
