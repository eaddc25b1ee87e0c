#!/usr/bin/env bash
# The installed program, run as a user runs it: cmake --install into a temporary prefix, then, from another
# folder and with no CLOTHSIM_* variable set, --version, the bundled scenes, a headless run, and a windowed
# --frames run with a screenshot (a real window: under xvfb-run when there is no display). The desktop entry
# validates, the icon is a 256 x 256 PNG, and nothing in the program names the source or build tree.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$(cd "$1" && pwd)"
source="$(cd "$2" && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "install test: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
exe="$tmp/prefix/bin/clothsim"
share="$tmp/prefix/share"
[ -x "$exe" ] || fail "no bin/clothsim in the installed tree"
unset CLOTHSIM_SCENES CLOTHSIM_SHADERS CLOTHSIM_TEXTURES
mkdir "$tmp/elsewhere"
cd "$tmp/elsewhere"

# Its data folders must not be compiled in (debug builds keep source file names for their own reasons).
for dir in "$source/assets" "$source/shaders" "$build/share"; do
  if grep -qaF "$dir" "$exe"; then fail "bin/clothsim names $dir: it must find its data relative to itself"; fi
done

version="$("$exe" --version)"
[[ "$version" =~ ^clothsim\ [0-9]+\.[0-9]+\.[0-9]+\ \(fast\ solver\ kernel:\ (avx512|avx2\+fma|generic)\)$ ]] ||
  fail "--version printed '$version'"

expected="$(cd "$source/assets/scenes" && ls -- *.toml | sed 's/\.toml$//' | sort)"
listed="$("$exe" --list-scenes)"
[ "$listed" = "$expected" ] || fail "--list-scenes printed '$listed', expected the bundled scenes '$expected'"
for s in $expected; do
  [ -f "$share/clothsim/scenes/$s.toml" ] || fail "scene $s not installed"
done

"$exe" --headless --scene drape-sphere --steps 5 --json > run.json
python3 - run.json <<'PY' || fail "the headless run's JSON is wrong"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["finite"] is True and d["steps"] == 5 and d["particles"] > 0, d
PY

run_window() {
  if [ -n "${DISPLAY:-}" ]; then "$@"; else xvfb-run -a -s "-screen 0 1280x720x24" "$@"; fi
}
run_window "$exe" flag --frames 5 --size 640x360 --screenshot shot.png > window.log ||
  fail "the windowed run failed: $(cat window.log)"
python3 - shot.png 640 360 "$share/icons/hicolor/256x256/apps/clothsim.png" 256 256 <<'PY' || fail "a PNG is wrong"
import struct, sys
args = sys.argv[1:]
for path, w, h in zip(args[0::3], args[1::3], args[2::3]):
    head = open(path, "rb").read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n", path + ": not a PNG"
    size = struct.unpack(">II", head[16:24])
    assert size == (int(w), int(h)), f"{path}: {size}, expected {w} x {h}"
PY

desktop-file-validate "$share/applications/clothsim.desktop" || fail "the desktop entry does not validate"
grep -qx 'Exec=clothsim %f' "$share/applications/clothsim.desktop" || fail "the desktop entry does not run clothsim FILE"
echo "install test: $exe ($version) runs from $PWD"
