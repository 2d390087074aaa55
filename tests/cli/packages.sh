#!/usr/bin/env bash
# The runtime package (packaging/build-debs, from this build): its Depends
# (from dpkg-shlibdeps) has no libtorch, MPI, Recast or other training
# library; extracted into an empty root, the animrt it installs runs from
# there and validates every shipped robot file from the installed data
# folder; its service unit passes `systemd-analyze verify`; the udev rule
# sets the FTDI latency timer to 1 ms and the limits file gives the service
# user real-time limits; lintian reports no error.
set -uo pipefail
animrt=$(realpath "$1")
root=$2
build=$(dirname "$(dirname "$animrt")")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

deb=$(DEB_PACKAGES=animrt DEB_COMPRESS=gzip DEB_COMPRESS_LEVEL=1 "$root/packaging/build-debs" "$build" "$tmp/deb" 2>&1) ||
  fail "build-debs: $deb"
[[ -f $deb ]] || fail "build-debs made no package: $deb"

depends=$(dpkg-deb -f "$deb" Depends) || fail "no control file in $deb"
[[ $depends == *"libc6"* && $depends == *"libserialport0"* ]] || fail "Depends misses libraries: $depends"
for lib in libtorch libopenmpi libmpi librecast libopenblas libc10; do
  [[ $depends != *"$lib"* ]] || fail "the runtime package depends on $lib: $depends"
done

dpkg-deb -x "$deb" "$tmp/root" || fail "cannot extract $deb"
installed=$tmp/root/usr/bin/animrt
version=$(sed -n 's/^project(animrt VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
out=$("$installed" --version 2>&1) || fail "installed --version: $out"
[[ $out == "animrt $version" ]] || fail "installed --version: $out"
cd "$tmp" || fail "cannot enter $tmp"
for robot in "$tmp"/root/usr/share/animrt/robots/*.yaml; do
  out=$("$installed" validate "$robot" 2>&1) || fail "installed validate $robot: $out"
done
out=$("$installed" view --help 2>&1)
[[ $out == *"--dashboard-www TEXT:DIR=$tmp/root/usr/share/animrt/www"* ]] ||
  fail "installed dashboard page: $out"
[[ -f $tmp/root/usr/share/animrt/www/index.html ]] || fail "no dashboard page in the package"

grep -q 'SUBSYSTEM=="usb-serial".*ATTR{latency_timer}="1"' \
  "$tmp"/root/lib/udev/rules.d/*animrt*.rules || fail "no udev rule for the latency timer"
grep -q '^@animrt - rtprio' "$tmp/root/etc/security/limits.d/animrt.conf" || fail "no rtprio limit"
grep -q '^@animrt - memlock unlimited' "$tmp/root/etc/security/limits.d/animrt.conf" ||
  fail "no memlock limit"
dpkg-deb -I "$deb" conffiles | grep -q /etc/animrt/animrt.conf || fail "configuration not a conffile"

# The unit against the extracted root (the host's targets beside it).
unit=lib/systemd/system/animrt.service
cp /lib/systemd/system/*.target "$tmp/root/lib/systemd/system/" 2>/dev/null
out=$(systemd-analyze verify --root="$tmp/root" "/$unit" 2>&1) || fail "systemd-analyze: $out"
[[ -z $out ]] || fail "systemd-analyze verify: $out"
for key in Type=notify WatchdogSec= LimitRTPRIO= LimitMEMLOCK= Restart=on-failure \
  StartLimitBurst= TimeoutStopSec= KillSignal=SIGTERM; do
  grep -q "^$key" "$tmp/root/$unit" || fail "the unit has no $key"
done

out=$(lintian --fail-on error "$deb" 2>&1) || fail "lintian: $out"
echo "ok"
