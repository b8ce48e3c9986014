#!/usr/bin/env bash
# Sets up (idempotent), installs chromium and a C compiler if missing, and runs the whole test suite
# (with arguments: pytest with those arguments).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
if ! bash scripts/ensure_chromium.sh; then
  if [ "${CI:-}" = "true" ]; then echo "CI: chromium is required for the browser tests" >&2; exit 1; fi
fi
if ! bash scripts/ensure_cc.sh; then
  if [ "${CI:-}" = "true" ]; then echo "CI: a C compiler is required for the C controller tests" >&2; exit 1; fi
fi
export NUMBA_CACHE_DIR="${NUMBA_CACHE_DIR:-$PWD/.numba_cache}"
if [ "$#" -gt 0 ]; then  # a selection: as given, in one process
  exec .venv/bin/python -m pytest "$@"
fi
# The whole suite: the unit, engine and CLI tests on every core (pytest-xdist), then the browser tests one
# at a time (their layout-steadiness and frame checks want the page's machine to themselves).
rc=0
.venv/bin/python -m pytest -n auto --durations=25 --ignore=tests/browser || rc=$?
.venv/bin/python -m pytest --durations=25 tests/browser || rc=$?
exit "$rc"
