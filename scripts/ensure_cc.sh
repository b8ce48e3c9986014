#!/usr/bin/env bash
# Installs the compilers the generated-firmware tests need, when missing (Debian packages):
#   gcc, g++          host build of the C module, its host test program and the C++ build test;
#   clang             the same host builds with the other compiler firmware is built with (fast-math
#                     guard, golden test program, C++);
#   gcc-arm-none-eabi, libnewlib-arm-none-eabi
#                     the Cortex-M4F cross-compile (no double operation in the float build);
#   qemu-user         qemu-arm, to count the instructions of one controller step
#                     (scripts/c_bench.py; the count falls back to a static one without it).
# Exit 1 when gcc, g++, clang, clang++ or arm-none-eabi-gcc cannot be installed (CI treats that as a failure).
set -uo pipefail
have_all() {
  command -v cc >/dev/null 2>&1 && command -v g++ >/dev/null 2>&1 && command -v clang >/dev/null 2>&1 \
    && command -v clang++ >/dev/null 2>&1 \
    && command -v arm-none-eabi-gcc >/dev/null 2>&1 && command -v qemu-arm >/dev/null 2>&1
}
if have_all; then exit 0; fi
SUDO=""
if [ "$(id -u)" != "0" ]; then SUDO="sudo -n"; fi
PKGS="gcc g++ libc6-dev clang gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-user"
echo "Installing Debian's $PKGS for the C controller tests…" >&2
export DEBIAN_FRONTEND=noninteractive
# shellcheck disable=SC2086
$SUDO apt-get install -y -q --no-install-recommends $PKGS >/dev/null 2>&1 || {
  $SUDO apt-get update -q >/dev/null 2>&1
  # shellcheck disable=SC2086
  $SUDO apt-get install -y -q --no-install-recommends $PKGS >/dev/null 2>&1
}
missing=""
for tool in cc g++ clang clang++ arm-none-eabi-gcc; do
  command -v "$tool" >/dev/null 2>&1 || missing="$missing $tool"
done
if [ -n "$missing" ]; then echo "could not install:$missing (apt-get install $PKGS)" >&2; exit 1; fi
command -v qemu-arm >/dev/null 2>&1 || echo "qemu-arm missing: the instruction count is static" >&2
exit 0
