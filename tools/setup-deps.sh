#!/usr/bin/env bash
# Installs the Debian 12 packages crater needs to build, test and plot.
# Idempotent: installs only what is missing and runs `apt-get update` only then.
# Never removes a package (apt-get install --no-remove): when what is missing cannot be
# installed without removing something, it stops and says so.
set -euo pipefail

packages=(
  g++ cmake ninja-build make pkg-config
  libeigen3-dev libtomlplusplus-dev libcli11-dev libfmt-dev libspdlog-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenmpi-dev openmpi-bin
  python3 python3-numpy python3-matplotlib
  clang-format universal-ctags
)

installed() {
  dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"
}

# VTK for the Python crater uses (/usr/bin/python3 unless CRATER_PYTHON names another; the tests
# and `crater report` read the VTU files with it). Debian's python3-vtk9 and ParaView's
# python3-paraview conflict: installing one removes the other. python3-paraview (5.11) ships
# VTK's own `vtkmodules` package (and `vtk`) into /usr/lib/python3/dist-packages, which crater's
# scripts import from, so with it installed python3-vtk9 is not needed.
vtk_import='from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
from vtkmodules.vtkIOXMLParser import vtkXMLUtilities
from vtkmodules.vtkCommonDataModel import vtkPlane
from vtkmodules.vtkFiltersCore import vtkCutter'
python="${CRATER_PYTHON:-/usr/bin/python3}"
if installed python3-paraview; then
  if ! "$python" -c "$vtk_import" >/dev/null 2>&1; then
    cat >&2 <<'EOF'
crater setup: python3-paraview is installed, but Python cannot import VTK's XML reader from it
(from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader fails).
Debian's python3-vtk9 would do, but installing it removes python3-paraview (they conflict),
so this script leaves both alone. Either repair ParaView's Python modules:
  sudo apt-get install --reinstall python3-paraview
or, if you do not need ParaView's Python (pvpython), replace it yourself:
  sudo apt-get install python3-vtk9     # removes python3-paraview
then run tools/setup-deps.sh again.
EOF
    exit 1
  fi
  echo "crater setup: using the VTK of python3-paraview (not installing python3-vtk9, which" \
    "would remove it)"
else
  packages+=(python3-vtk9)
fi

missing=()
for p in "${packages[@]}"; do
  if ! installed "$p"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "crater setup: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "crater setup: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
if ! "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends --no-remove "${missing[@]}"; then
  echo "crater setup: apt-get could not install ${missing[*]} without removing packages" \
    "(this script never removes any); see apt-get's message above, install them yourself," \
    "then run tools/setup-deps.sh again" >&2
  exit 1
fi
