#!/usr/bin/env bash
# Build the offline kit that carries lagice's dependencies to a GPU machine with no network
# (the workplace's device machines: Python 3.12, numba + numba-cuda, numpy, scipy, xarray and
# matplotlib already there; docs/gpu.md, "Installing on a GPU machine").
#
#   bash scripts/gpu_kit.sh [KIT_DIR]            # default .devpkg (add it to .git/info/exclude)
#
# Writes KIT_DIR/site.tar.xz: the Python 3.12 manylinux wheels of the dependencies that machine
# lacks, unpacked into one folder `site/`, with gmsh's library stripped and placed beside
# gmsh.py (its examples and executable left out) and the X11/OpenGL client libraries that
# libgmsh loads in `site/xlibs/` (copied from this Debian machine, where scripts/bootstrap.sh
# installed them). About 45 MB. On the GPU machine:
#
#   mkdir -p /tmp/s && tar -xJf KIT_DIR/site.tar.xz -C /tmp/s
#   export PYTHONPATH=/tmp/s/site:$PWD LD_LIBRARY_PATH=/tmp/s/site/xlibs:$LD_LIBRARY_PATH
#
# and, where that machine's numpy is newer than its numba-cuda supports (numpy 2.5 removed
# numpy.row_stack), a sitecustomize.py in /tmp/s/site with `numpy.row_stack = numpy.vstack`
# (KIT_DIR/sitecustomize.py, written here).
set -euo pipefail
cd "$(dirname "$0")/.."
KIT=${1:-.devpkg}
PY=.venv/bin/python
[ -x "$PY" ] || { echo "gpu_kit: run scripts/bootstrap.sh first (the versions are taken from .venv)"; exit 1; }
PKGS="gmsh meshio netCDF4 cftime shapely pyproj pyamg numba_celltree xugrid pyshp pooch"
SPECS=""
for p in $PKGS; do
    v=$($PY -c "import importlib.metadata as m; print(m.version('$p'))")
    SPECS="$SPECS $p==$v"
done
rm -rf "$KIT/whl" "$KIT/site" && mkdir -p "$KIT/whl" "$KIT/site"
PLAT=""
for n in 17 24 27 28 31 34; do PLAT="$PLAT --platform manylinux_2_${n}_x86_64"; done
# shellcheck disable=SC2086
python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
    $PLAT --platform manylinux2014_x86_64 --platform manylinux1_x86_64 --platform any -d "$KIT/whl" $SPECS
for w in "$KIT"/whl/*.whl; do (cd "$KIT/site" && python3 -m zipfile -e "../whl/$(basename "$w")" .); done
lib=$(ls "$KIT"/site/gmsh-*.data/data/lib/libgmsh.so.* | head -1)
mv "$lib" "$KIT/site/" && rm -rf "$KIT"/site/gmsh-*.data
strip --strip-unneeded "$KIT"/site/libgmsh.so.*
mkdir -p "$KIT/site/xlibs"
for l in $(ldd "$KIT"/site/libgmsh.so.* | awk '{print $3}' \
           | grep -v -E 'libc\.so|libm\.so|libstdc|libgcc_s|libpthread|libdl\.so|librt\.so|libgomp|libz\.so'); do
    cp -L "$l" "$KIT/site/xlibs/"
done
find "$KIT/site" -name tests -type d -prune -exec rm -rf {} +
printf 'try:\n    import numpy\n    if not hasattr(numpy, "row_stack"):\n        numpy.row_stack = numpy.vstack\nexcept Exception:\n    pass\n' \
    > "$KIT/sitecustomize.py"
tar -C "$KIT" -cJf "$KIT/site.tar.xz" site
rm -rf "$KIT/whl" "$KIT/site"
ls -l "$KIT/site.tar.xz"
