# shellcheck shell=bash
# Sourced by the HIL scripts: Debian's kernel package for the guest, fetched
# with apt-get download into OUT/kernel once and unpacked there (never
# installed on this host). Sets kernel_pkg, kver, vmlinuz and kroot (the
# unpacked package: kroot/lib/modules/$kver holds the modules).
hil_kernel() {  # OUT
  kernel_pkg="$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}')"
  [ -n "$kernel_pkg" ] || fail "cannot tell which kernel package linux-image-amd64 depends on (apt-get update?)"
  local kdir="$1/kernel" deb
  mkdir -p "$kdir"
  if ! ls "$kdir"/"$kernel_pkg"_*.deb >/dev/null 2>&1; then
    step "fetching $kernel_pkg"
    (cd "$kdir" && apt-get download -q "$kernel_pkg" >/dev/null 2>&1) || fail "apt-get download $kernel_pkg failed"
  fi
  deb="$(ls "$kdir"/"$kernel_pkg"_*.deb | head -1)"
  if [ ! -f "$kdir/unpacked.stamp" ] || [ "$deb" -nt "$kdir/unpacked.stamp" ]; then
    rm -rf "$kdir/root"
    dpkg-deb -x "$deb" "$kdir/root"
    touch "$kdir/unpacked.stamp"
  fi
  kver="${kernel_pkg#linux-image-}"
  kroot="$kdir/root"
  vmlinuz="$kroot/boot/vmlinuz-$kver"
  [ -f "$vmlinuz" ] || fail "no $vmlinuz in $deb"
}
