#!/usr/bin/env bash
# Installs what godrays needs from Debian bookworm packages, and only what is missing.
# Idempotent: a machine that has everything is left alone (no apt-get update, no install).
# Needs root only when something is missing (exit 2 otherwise). docs/dependencies.md says
# why each package is here.
set -euo pipefail

# ---- the package list: the one place to add a dependency -------------------------------
# Installed with --no-install-recommends. The run-time pieces that this would otherwise drop
# are named explicitly: libegl-mesa0 + libgl1-mesa-dri (Mesa EGL vendor + llvmpipe, what a
# headless context runs on without a GPU) and plplot-driver-qt (PLplot's pngqt device; it is
# only a Recommends of libplplotqt2). PLplot's svg/pdf/ps devices are in libplplot17 itself.
GODRAYS_PACKAGES=(
  # toolchain
  gcc g++ cmake ninja-build pkg-config git
  # ray tracing, images, JSON
  libembree-dev libopenexr-dev libopenimageio-dev openimageio-tools libcjson-dev libpng-dev
  # headless OpenGL through EGL (GLVND) with Mesa's software rasterizer
  libegl-dev libgl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri
  # the local HTTP server of `godrays watch`
  libmicrohttpd-dev
  # plots (PNG: PLplot; the interactive charts of the pareto pages: Chart.js, inlined)
  libplplot-dev plplot-driver-qt libjs-chart.js
  # headless browser for the report's test (tests/cli/test_report_browser.sh)
  chromium
  # Node.js for the test tools installed from npm below (npm_tools)
  nodejs
  # Blender round trip of the glTF export (tests/cli/test_export_blender.sh); its glTF
  # importer needs NumPy, only a Recommends of blender
  blender python3-numpy
  # an X server for Blender's Eevee (the eevee technique, docs/engines.md section 5): xvfb-run
  # needs xauth, only a Recommends of xvfb
  xvfb xauth
  # a single-node Slurm cluster for the farm test (tests/farm/test_slurm.sh, docs/farm.md)
  slurm-wlm munge
  # libFuzzer targets (tests/fuzz, scripts/fuzz.sh): clang and its fuzzer runtime
  clang libclang-rt-14-dev
)

installed() {
  # "install ok installed" is the only state in which a package's files are all present
  [ "$(dpkg-query -W -f '${Status}' "$1" 2>/dev/null)" = "install ok installed" ]
}

# ---- test tools from npm (tests only; into build-tools/, ignored by git) -----------------
# Khronos' glTF-Validator for tests/cli/test_export_gltf.sh, pinned, installed only when missing.
GLTF_VALIDATOR_VERSION=2.0.0-dev.3.10
npm_tools() {
  local dir
  dir="$(cd "$(dirname "$0")/.." && pwd)/build-tools"
  local pj="$dir/node_modules/gltf-validator/package.json"
  if [ -f "$pj" ] && [ "$(node -p "require('$pj').version" 2>/dev/null)" = "$GLTF_VALIDATOR_VERSION" ]; then
    echo "setup: gltf-validator $GLTF_VALIDATOR_VERSION is in build-tools/"
    return 0
  fi
  if ! command -v npm >/dev/null 2>&1; then
    # Debian's nodejs has no npm; NodeSource's has it built in
    [ "$(id -u)" -eq 0 ] || { echo "setup: npm missing: run as root (or: sudo apt-get install npm)" >&2; exit 2; }
    apt-get install -y -q --no-install-recommends npm
  fi
  echo "setup: npm install gltf-validator@$GLTF_VALIDATOR_VERSION into build-tools/"
  mkdir -p "$dir"
  npm install --no-audit --no-fund --silent --prefix "$dir" "gltf-validator@$GLTF_VALIDATOR_VERSION"
}

missing=()
for p in "${GODRAYS_PACKAGES[@]}"; do
  installed "$p" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#GODRAYS_PACKAGES[@]} packages are installed"
  npm_tools
  exit 0
fi

echo "setup: missing packages: ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "setup: not root: run as root (or: sudo apt-get install --no-install-recommends ${missing[*]})" >&2
  exit 2
fi

export DEBIAN_FRONTEND=noninteractive
echo "setup: apt-get update"
apt-get update -q
echo "setup: apt-get install -y --no-install-recommends ${missing[*]}"
apt-get install -y -q --no-install-recommends "${missing[@]}"

still=()
for p in "${missing[@]}"; do
  installed "$p" || still+=("$p")
done
if [ ${#still[@]} -ne 0 ]; then
  echo "setup: still missing after install: ${still[*]}" >&2
  exit 1
fi
echo "setup: installed ${#missing[@]} package(s)"
npm_tools
