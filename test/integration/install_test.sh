#!/usr/bin/env bash
# The install a user gets, run with the source and build trees out of reach (ctest Install.*, label install).
#   install_test.sh prefix|deb BUILD_DIR SOURCE_DIR
# prefix: `cmake --install BUILD_DIR --prefix TMP/prefix`. deb: `cpack -G DEB` of BUILD_DIR, the package
# unpacked with `dpkg-deb -x` into TMP/root (its programs under TMP/root/usr). Then, in a private mount
# namespace where the source tree, the build tree and (when the install has its own plotly.min.js)
# /usr/share/python3-plotly are hidden under empty mounts, from a working directory outside them and with
# a bare environment: `selfcal simulate --points` (the shipped robot and trajectory, report.html) and
# `selfcal calibrate` of its observations (report.html; an OpenCV camera file, through the private library)
# and `selfcal-robot-sim` on a shipped robot.
# Exits 77 (skipped) when no mount namespace can be made (no unshare, or user namespaces disabled).
set -euo pipefail

fail() {
  echo "install test: FAIL: $*" >&2
  exit 1
}

mode=$1
build=$(cd "$2" && pwd -P)
source=$(cd "$3" && pwd -P)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/selfcal-install-test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
case "$tmp/" in "$source/"* | "$build/"*) fail "the temporary directory $tmp is inside the trees to hide" ;; esac

if unshare -m true 2>/dev/null; then
  namespace=(unshare -m)
elif unshare -rm true 2>/dev/null; then
  namespace=(unshare -rm)
else
  echo "install test: skipped: no mount namespace (unshare -m / -rm) to hide the source tree in"
  exit 77
fi

case $mode in
  prefix)
    cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log" ||
      { cat "$tmp/install.log"; fail "cmake --install failed"; }
    root=$tmp/prefix
    ;;
  deb)
    (cd "$tmp" && cpack -G DEB --config "$build/CPackConfig.cmake" -B "$tmp/pkg" >"$tmp/cpack.log" 2>&1) ||
      { cat "$tmp/cpack.log"; fail "cpack failed"; }
    debs=("$tmp"/pkg/*.deb)
    [[ -f ${debs[0]} && ${#debs[@]} == 1 ]] || fail "cpack made no single .deb: ${debs[*]}"
    deb=${debs[0]}
    echo "package: $(basename "$deb"), $(stat -c %s "$deb") bytes"
    dpkg-deb -f "$deb" Package Version Architecture Installed-Size Depends Recommends
    dpkg-deb -x "$deb" "$tmp/root"
    root=$tmp/root/usr
    # Depends names the package of every library the programs and the private library link directly
    # (their NEEDED entries, resolved by ldd, owned per dpkg -S; an alternatives link by the file it names).
    depends=$(dpkg-deb -f "$deb" Depends)
    for elf in "$root"/bin/* "$root"/lib*/selfcal/*.so; do
      resolved=$(ldd "$elf")
      for needed in $(readelf -d "$elf" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
        # "libx.so.1 => /path/libx.so.1 (0x...)", or the loader's "/lib64/ld-linux-x86-64.so.2 (0x...)"
        path=$(awk -v n="$needed" '$1 == n { print $3 } $1 ~ "/" n "$" { print $1 }' <<<"$resolved")
        [[ -n $path ]] || fail "$elf: $needed not found by ldd"
        owner=$(dpkg -S "$path" 2>/dev/null || dpkg -S "/usr$path" 2>/dev/null || dpkg -S "${path#/usr}" 2>/dev/null ||
          dpkg -S "$(realpath "$path")" 2>/dev/null) ||
          fail "$path ($needed of $elf) belongs to no Debian package"
        package=${owner%%:*}
        [[ ", $depends," == *", $package "* || ", $depends," == *", $package,"* || $depends == *"| $package"* ]] ||
          fail "Depends lacks $package ($needed of $(basename "$elf")): $depends"
      done
    done
    echo "Depends covers the package of every library linked directly"
    ;;
  *) fail "mode must be prefix or deb, not $mode" ;;
esac

echo "installed files (under $root):"
(cd "$root" && find . -type f -printf '%P\t%s\n' | sort | awk -F'\t' '
  /^share\/doc\/selfcal\/docs\// { docs++; next }
  { print "  " $1 " (" $2 " bytes)" }
  END { print "  share/doc/selfcal/docs/: " docs " files" }')
for file in bin/selfcal bin/selfcal-full bin/selfcal-robot-sim share/selfcal/config/robots/puma560.yaml \
  share/selfcal/config/trajectories/initial_puma560.yaml share/doc/selfcal/README.md \
  share/doc/selfcal/docs/troubleshooting.md share/doc/selfcal/examples/reference-robot-server; do
  [[ -f $root/$file ]] || fail "$file not installed"
done
[[ -n $(find "$root" -path '*/selfcal/libselfcal_camera_formats.so') ]] ||
  fail "libselfcal_camera_formats.so not installed"

# Hidden inside the namespace: the trees, and Debian's plotly.js when the install must use its own.
hide=("$source")
case "$build/" in "$source/"*) ;; *) hide+=("$build") ;; esac
if [[ -f $build/plotly.min.js ]]; then
  [[ -f $root/share/selfcal/plotly.min.js ]] ||
    fail "the build minified plotly.js but share/selfcal/plotly.min.js is not installed"
  [[ -d /usr/share/python3-plotly ]] && hide+=(/usr/share/python3-plotly)
fi
mkdir -p "$tmp/work" "$tmp/home"
cat >"$tmp/sealed.sh" <<'SEALED'
while [[ $1 != -- ]]; do mount -t tmpfs -o ro,size=4k selfcal-hidden "$1" || exit 99; shift; done
shift
cd "$SEALED_WORK" && exec env -i PATH=/usr/bin:/bin HOME="$SEALED_HOME" LANG=C.UTF-8 "$@"
SEALED
sealed() { SEALED_WORK=$tmp/work SEALED_HOME=$tmp/home "${namespace[@]}" bash "$tmp/sealed.sh" "${hide[@]}" -- "$@"; }

# The hiding works: the source tree's files are not there for the programs.
sealed test ! -e "$source/CMakeLists.txt" -a ! -e "$build/CMakeCache.txt" ||
  fail "the source or build tree is still visible in the namespace (or it could not be hidden)"
echo "hidden from the programs: ${hide[*]}"

run() {
  echo "\$ (cd $tmp/work && ${*/#$root/PREFIX})"
  local rc=0
  sealed "$@" >"$tmp/out.log" 2>"$tmp/err.log" || rc=$?
  ((rc == 0)) || { cat "$tmp/out.log" "$tmp/err.log"; fail "$* exited $rc"; }
  if grep -q "warning" "$tmp/err.log"; then cat "$tmp/err.log"; fail "$* warned"; fi
  tail -n 2 "$tmp/out.log" | sed 's/^/  /'
}
run "$root/bin/selfcal" --version
run "$root/bin/selfcal" simulate --points --seed 3 --out sim
run "$root/bin/selfcal" calibrate sim/observations.yaml --out cal --write-camera-opencv cal/camera_opencv.yaml
# The simulated robot server with a shipped robot, stopped after a second (SIGTERM: a clean stop, exit 0).
run timeout --preserve-status 1 "$root/bin/selfcal-robot-sim" --robot config/robots/ur5e.yaml --port 0
grep -q "^listening on 127.0.0.1:" "$tmp/out.log" || fail "selfcal-robot-sim did not start"
for file in sim/report.json sim/report.html sim/calibrated_model.yaml cal/report.json cal/report.html \
  cal/calibrated_model.yaml cal/camera_opencv.yaml; do
  [[ -s $tmp/work/$file ]] || fail "$file not written"
done
# report.html inlines plotly.js (3.8 MB minified): a page without it is a few hundred kB.
for page in sim/report.html cal/report.html; do
  size=$(stat -c %s "$tmp/work/$page")
  ((size > 2000000)) || fail "$page is $size bytes: plotly.js not inlined"
  echo "$page: $size bytes"
done

# Without any plotly.js the warning names every place searched, the installed one first.
if [[ $mode == prefix && -f $root/share/selfcal/plotly.min.js ]]; then
  rm "$root/share/selfcal/plotly.min.js"
  [[ -d /usr/share/python3-plotly ]] && hide+=(/usr/share/python3-plotly)
  if sealed "$root/bin/selfcal" report sim/report.json --out none.html >"$tmp/out.log" 2>&1; then
    fail "report without plotly.js succeeded"
  fi
  sed 's/^/  /' "$tmp/out.log"
  grep -qF "searched $root/share/selfcal/plotly.min.js, /usr/share/python3-plotly/plotly.js" "$tmp/out.log" ||
    fail "the refusal does not name the places searched"
fi
# The build tree's own selfcal falls back to the source tree, except with SELFCAL_NO_SOURCE_FALLBACK=1.
if [[ $mode == prefix ]]; then
  if (cd "$tmp/work" && SELFCAL_NO_SOURCE_FALLBACK=1 "$build/app/selfcal" simulate --points --no-html --out nofallback \
    >"$tmp/out.log" 2>&1); then
    fail "SELFCAL_NO_SOURCE_FALLBACK=1: the build tree's selfcal still found the source tree's config/"
  fi
  grep -q "config/robots/puma560.yaml" "$tmp/out.log" || { cat "$tmp/out.log"; fail "the refusal names no robot file"; }
  echo "SELFCAL_NO_SOURCE_FALLBACK=1: $(head -n 1 "$tmp/out.log")"
fi
echo "install test ($mode): passed"
