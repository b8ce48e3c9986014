#!/usr/bin/env bash
# Sets up (idempotent) and starts the commissioning tool with the default preset.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export NUMBA_CACHE_DIR="${NUMBA_CACHE_DIR:-$PWD/.numba_cache}"
exec .venv/bin/python -m pmsm_commissioning.app serve "$@"
