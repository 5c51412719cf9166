# Sourced by the quick-start scripts: installs the Debian 12 packages cps needs that are missing.
# apt-get update runs once, and only when something is missing.
cps_packages=(
  # Ninja schedules a fresh build's compiles across the cores better than make does.
  cmake g++ make ninja-build pkg-config
  libeigen3-dev libglm-dev libstb-dev libpng-dev catch2 libcli11-dev nlohmann-json3-dev
  # The state hash of `cps simulate --json`: xxHash.
  libxxhash-dev
  # Scene files: validated against assets/schemas/scene.schema.json by valijson.
  libvalijson-dev
  # PNG frames: written by stb_image_write (libstb-dev), deflate by Intel ISA-L, CRCs by zlib.
  libisal-dev zlib1g-dev
  # The two GL backends (both loaded at run time): OSMesa, and EGL with Mesa's driver.
  libosmesa6-dev libegl-dev libegl1 libegl-mesa0 libgl1-mesa-dri
  # Plots of `cps report`, videos of `cps render --video`.
  gnuplot-nox ffmpeg
  # Figures of `cps figure` (PNG, PDF, SVG with the labels as text): cairo, and the font it
  # typesets the labels in, DejaVu Sans.
  libcairo2-dev fonts-dejavu-core
  # Tests only: pdftotext reads the text of the figures' and the report's PDFs; GNU parallel
  # runs a spread sweep as docs/commands.md shows it.
  poppler-utils parallel
  # glTF 2.0 binaries of `cps export` (header only; built and read back by the tests).
  libtinygltf-dev
  # The exact reference of a step (`cps simulate --solver-error`, demos/analysis): Siconos
  # numerics' Lemke solver.
  libsiconos-numerics-dev
  # FCLIB files of `cps export --fclib` (optional: without it the option says it was left out).
  # fclib.h at build time; cps opens libfclib.so.0 (libfclib0, a dependency) only for --fclib.
  libfclib-dev
  # The Python module cps (demos/python, docs/python.md) and its tests: pybind11 and Debian's
  # python3 with numpy and pytest; matplotlib draws the worked example's plot (docs/python.md).
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib
)

cps_install_missing() {
  local missing=()
  local pkg
  for pkg in "${cps_packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q '^install ok installed$'; then
      missing+=("$pkg")
    fi
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  echo "cps: installing missing packages: ${missing[*]}"
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    sudo=(sudo)
  fi
  "${sudo[@]}" apt-get update
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
}

# Configures FOLDER with Ninja, or with the generator it already has (a folder configured by an
# earlier make build keeps make). Usage: cps_configure FOLDER [CMAKE ARGS...]
cps_configure() {
  local dir=$1
  shift
  local generator=(-G Ninja)
  if [ -f "$dir/CMakeCache.txt" ]; then
    generator=()
  fi
  cmake -S . -B "$dir" "${generator[@]}" "$@"
}

# Configures and builds into build/ (Release).
cps_build() {
  cps_configure build -DCMAKE_BUILD_TYPE=Release "$@"
  cmake --build build --parallel "$(nproc)"
  cps_link_python
}

# Where the build folder (default build) has the Python module, points its interpreter's user
# site at FOLDER/python with the file cps-build.pth (what an editable install writes), so that
# `import cps` finds this build from any folder. The file names one folder; a build in another
# clone replaces it. Skipped where the interpreter has no user site; `cmake --install` or
# PYTHONPATH then. Usage: cps_link_python [FOLDER]
cps_link_python() {
  local build=${1:-build}
  [ -f "$build/python/interpreter.txt" ] || return 0
  compgen -G "$build/python/cps.*.so" > /dev/null || return 0
  local python site
  python=$(head -n 1 "$build/python/interpreter.txt")
  site=$("$python" -c 'import site; print(site.getusersitepackages() if site.ENABLE_USER_SITE else "")' 2> /dev/null) || return 0
  [ -n "$site" ] || return 0
  local pth="$site/cps-build.pth" folder
  folder=$(cd "$build/python" && pwd)
  if [ "$(cat "$pth" 2> /dev/null)" != "$folder" ]; then
    if ! { mkdir -p "$site" && printf '%s\n' "$folder" > "$pth.tmp.$$" && mv "$pth.tmp.$$" "$pth"; } 2> /dev/null; then
      rm -f "$pth.tmp.$$" 2> /dev/null || true
      echo "cps: could not write $pth; to import cps, set PYTHONPATH=$folder"
      return 0
    fi
  fi
  echo "cps: $python imports cps from $folder ($pth)"
}
