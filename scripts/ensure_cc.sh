#!/usr/bin/env bash
# Installs Debian's C compiler (gcc, as `cc`) for the generated-firmware tests when it is missing.
set -uo pipefail
if command -v cc >/dev/null 2>&1; then exit 0; fi
SUDO=""
if [ "$(id -u)" != "0" ]; then SUDO="sudo -n"; fi
echo "Installing Debian's gcc for the C controller tests…" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get install -y -q gcc libc6-dev >/dev/null 2>&1 || {
  $SUDO apt-get update -q >/dev/null 2>&1
  $SUDO apt-get install -y -q gcc libc6-dev >/dev/null 2>&1
}
command -v cc >/dev/null 2>&1 || { echo "a C compiler (cc) could not be installed" >&2; exit 1; }
