#!/usr/bin/env bash
# Idempotent set-up: creates .venv and installs the project with its test extras.
# Re-installs only when pyproject.toml or constraints.txt changed since the last successful install;
# versions are pinned by constraints.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
stamp=.venv/.installed-$(cat pyproject.toml constraints.txt | sha256sum | cut -c1-16)
if [ ! -f "$stamp" ]; then
  .venv/bin/python -m pip install --quiet --upgrade pip
  .venv/bin/python -m pip install --quiet -c constraints.txt -e ".[test]"
  rm -f .venv/.installed-*
  touch "$stamp"
fi
# Compile the numba kernels now (into the cache the server and tests use), so that no user's
# first click (and no test) pays the ≈ 20 s of CPU of a JIT compile. With a warm cache this takes ≈ 6 s.
export NUMBA_CACHE_DIR="${NUMBA_CACHE_DIR:-$PWD/.numba_cache}"
.venv/bin/python -m pmsm_commissioning.app simulate paper_12kw_pmsm --json >/dev/null
.venv/bin/python -m pmsm_commissioning.app simulate paper_12kw_pmsm --set controller.f_s=continuous --json >/dev/null
.venv/bin/python -m pmsm_commissioning.app bldc bldc_smc_paper --json >/dev/null
# The duty-cycle kernel (sim/studies/cycle_kernel.py): one short move and dwell compiles it.
moves=$(mktemp --suffix=.yaml)
trap 'rm -f "$moves"' EXIT
printf -- '- {theta_dem: 1.0, T_m: 0.2, dwell: 0.05}\n' >"$moves"
.venv/bin/python -m pmsm_commissioning.app dutycycle siemens_1ft7044_ak7 "$moves" --json >/dev/null
