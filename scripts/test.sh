#!/usr/bin/env bash
# Sets up (idempotent), installs chromium and a C compiler if missing, and runs the whole test suite.
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
exec .venv/bin/python -m pytest "$@"
