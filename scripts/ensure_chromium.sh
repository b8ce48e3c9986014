#!/usr/bin/env bash
# Installs Debian's chromium for the browser tests when it is missing (never `playwright install`).
set -uo pipefail
if command -v chromium >/dev/null 2>&1; then exit 0; fi
SUDO=""
if [ "$(id -u)" != "0" ]; then SUDO="sudo -n"; fi
echo "Installing Debian's chromium for the browser tests…" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get install -y -q chromium >/dev/null 2>&1 || {
  $SUDO apt-get update -q >/dev/null 2>&1
  $SUDO apt-get install -y -q chromium >/dev/null 2>&1
}
command -v chromium >/dev/null 2>&1 || { echo "chromium could not be installed" >&2; exit 1; }
