"""``pmsm-commission export --format c`` of a design that is not clean, and the files' text.

Refused: every failed check is named (a list of their names, then one line per check), exit 2, no file.
Forced: the files are written, and a warning on stderr names every failed check. Each of the four
files is printable ASCII, the forced banner included (a C compiler or an old editor may read no UTF-8).
"""

from __future__ import annotations

import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.exports.firmware.module import HEADER_NAME, SOURCE_NAME
from pmsm_commissioning.app.exports.firmware.vectors import TEST_NAME, VECTORS_NAME
from pmsm_commissioning.app.exports.provenance import failed_checks
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.fdsmc.engine import compare

PRESET = "paper_12kw_pmsm"  # K = 1000 on its drive: several checks fail
C_FILES = (HEADER_NAME, SOURCE_NAME, VECTORS_NAME, TEST_NAME)


@pytest.fixture(scope="module")
def failed() -> list:
    """The failed checks of the preset's simulated FDSMC run (the same the CLI computes)."""
    checks = failed_checks(compare(load_preset(PRESET)))
    assert len(checks) >= 3
    return checks


def test_refusal_names_every_failed_check(tmp_path, capsys, failed):
    out = tmp_path / "c"
    assert main(["export", PRESET, "--format", "c", "-o", str(out)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("error: export --format c refused") and "--force" in err[0]
    assert ", ".join(c.name for c in failed) in err[0]  # all names, whatever the texts' lengths
    assert [line.split(":")[0].strip() for line in err[1:]] == [c.name for c in failed]  # one line each
    assert all(len(line) <= 300 for line in err)
    assert not out.exists()


def test_forced_export_warns_naming_every_failed_check_and_writes_ascii(tmp_path, capsys, failed):
    out = tmp_path / "c"
    assert main(["export", PRESET, "--format", "c", "-o", str(out), "--force"]) == 0
    captured = capsys.readouterr()
    err = captured.err.splitlines()
    assert err[0].startswith("warning: written with --force: the design is NOT CLEAN")
    assert ", ".join(c.name for c in failed) in err[0]
    assert [line.split(":")[0].strip() for line in err[1:]] == [c.name for c in failed]
    assert "warning" not in captured.out
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(C_FILES)
    for name in names:
        data = (out / name).read_bytes()
        assert data.isascii(), (name, sorted({b for b in data if b > 127}))
        text = data.decode("ascii")
        assert text.startswith("/* verdict: NOT CLEAN -- written with --force; failed checks:\n")
        banner = text[: text.index("*/")]
        assert all(f" *   {c.name}: " in banner for c in failed)
        assert all(ch == "\n" or " " <= ch <= "~" for ch in banner)


def test_clean_export_prints_no_warning(tmp_path, capsys):
    assert main(["export", "yaskawa_sgm7j_04a", "--format", "c", "-o", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert captured.err == "" and captured.out.count("wrote ") == 4
    for path in tmp_path.iterdir():
        assert path.read_bytes().isascii() and not path.read_text().startswith("/* verdict")

