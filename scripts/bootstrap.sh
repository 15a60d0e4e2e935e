#!/usr/bin/env bash
# Install lagice into ./.venv, with the system libraries gmsh needs.
#   bash scripts/bootstrap.sh          # the model
#   bash scripts/bootstrap.sh --test   # the model + test extras
# Works on a fresh Debian 12 with Python 3.11 (installs python3-venv and the
# gmsh runtime libraries with apt-get when they are missing; needs root or sudo
# only in that case).
set -euo pipefail
cd "$(dirname "$0")/.."

extras=""
case "${1:-}" in
  --test) extras="[test]" ;;
  "") ;;
  *) echo "usage: $0 [--test]" >&2; exit 2 ;;
esac

PY=${PYTHON:-python3}
if ! command -v "$PY" >/dev/null 2>&1; then
  echo "bootstrap: $PY not found; install Python >= 3.11 first" >&2
  exit 1
fi
if ! "$PY" -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then
  echo "bootstrap: $PY is $("$PY" -V 2>&1); lagice needs Python >= 3.11" >&2
  exit 1
fi

missing=()
if command -v dpkg >/dev/null 2>&1; then
  for pkg in libglu1-mesa libxcursor1 libxft2 libxinerama1; do
    dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
  done
fi
if [ ! -x .venv/bin/python ] && ! "$PY" -c 'import ensurepip, venv' >/dev/null 2>&1; then
  missing+=("python3-venv")
fi
if [ ${#missing[@]} -gt 0 ]; then
  if command -v apt-get >/dev/null 2>&1; then
    SUDO=""
    [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    echo "bootstrap: installing system packages: ${missing[*]}"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
  else
    echo "bootstrap: please install ${missing[*]} (needed by gmsh / venv)" >&2
  fi
fi

if [ ! -x .venv/bin/python ]; then
  echo "bootstrap: creating .venv"
  "$PY" -m venv .venv
fi
echo "bootstrap: installing lagice${extras} into .venv (first time: a few minutes)"
.venv/bin/python -m pip install -q --disable-pip-version-check -e ".${extras}"
echo "bootstrap: ready (.venv/bin/lagice)"
