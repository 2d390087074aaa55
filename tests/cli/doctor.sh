#!/usr/bin/env bash
# animrt doctor: on this machine every check prints one OK/WARN/FAIL line
# (a fix under each WARN and FAIL) and the exit code says whether one
# failed; on a host made up under ANIMRT_DOCTOR_ROOT, a slow FTDI latency
# timer, a power-saving governor and a CAN interface that is down are found
# with their fixes, and bringing the interface up clears the failure; an
# isolated CPU the process may run outside of is a warning with the
# affinity to set, and a process pinned to it is OK.
set -uo pipefail
animrt=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

check_structure() {  # OUTPUT: every line a check, a fix or the summary
  local out=$1 previous=""
  while IFS= read -r line; do
    if [[ $line =~ ^(OK\ \ |WARN|FAIL)\ \ [A-Za-z_\ ]+:\ .+ ]]; then
      :
    elif [[ $line =~ ^\ \ \ \ \ \ fix:\ .+ ]]; then
      [[ $previous =~ ^(WARN|FAIL) ]] || fail "a fix under a line that needs none: $previous"
    elif [[ $line =~ ^[0-9]+\ checks:\ [0-9]+\ failed,\ [0-9]+\ warnings$ ||
            $line == "host files read under"* ]]; then
      :
    else
      fail "unexpected line: $line"
    fi
    if [[ $previous =~ ^(WARN|FAIL) && ! $line =~ fix: ]]; then
      fail "no fix under: $previous"
    fi
    previous=$line
  done <<< "$out"
}

out=$("$animrt" doctor 2>&1)
code=$?
check_structure "$out"
for name in "serial adapter" "latency timer" dialout "rtprio limit" "memlock limit" SCHED_FIFO \
  mlockall kernel CPU "CPU governor" CAN; do
  grep -q "^[OKWARNFIL ]\{4\}  $name" <<< "$out" || fail "no $name check: $out"
done
if grep -q "^FAIL" <<< "$out"; then want=3; else want=0; fi
[[ $code -eq $want ]] || fail "exit $code with these results: $out"

host=$tmp/host
mkdir -p "$host/dev/serial/by-id" "$host/sys/bus/usb-serial/devices/ttyUSB0" \
  "$host/sys/bus/usb-serial/devices/ttyUSB1" "$host/sys/kernel" \
  "$host/sys/devices/system/cpu/cpu0/cpufreq" "$host/sys/devices/system/cpu/cpu1/cpufreq" \
  "$host/sys/class/net/can0" "$host/sys/class/net/eth0"
touch "$host/dev/ttyUSB0"
ln -s ../../ttyUSB0 "$host/dev/serial/by-id/usb-FTDI_FT232R_USB_UART_A10K-if00-port0"
echo 16 > "$host/sys/bus/usb-serial/devices/ttyUSB0/latency_timer"
echo 1 > "$host/sys/bus/usb-serial/devices/ttyUSB1/latency_timer"
echo 1 > "$host/sys/kernel/realtime"
echo powersave > "$host/sys/devices/system/cpu/cpu0/cpufreq/scaling_governor"
echo performance > "$host/sys/devices/system/cpu/cpu1/cpufreq/scaling_governor"
echo 280 > "$host/sys/class/net/can0/type"
echo 0x80 > "$host/sys/class/net/can0/flags"
echo 500000 > "$host/sys/class/net/can0/bitrate"
echo 1 > "$host/sys/class/net/eth0/type"
echo 0x1003 > "$host/sys/class/net/eth0/flags"

out=$(ANIMRT_DOCTOR_ROOT=$host "$animrt" doctor 2>&1)
code=$?
check_structure "$out"
[[ $code -eq 3 ]] || fail "a CAN interface down is not a failure (exit $code): $out"
expect() { grep -q -- "$1" <<< "$out" || fail "expected '$1' in: $out"; }
expect "^OK    serial adapter: usb-FTDI_FT232R_USB_UART_A10K-if00-port0 -> .*/dev/ttyUSB0"
expect "^WARN  latency timer: ttyUSB0: 16 ms"
expect "fix: echo 1 | sudo tee /sys/bus/usb-serial/devices/ttyUSB0/latency_timer"
expect "^OK    latency timer: ttyUSB1: 1 ms"
expect "^OK    kernel: PREEMPT_RT"
expect "^WARN  CPU governor: cpu0 powersave"
expect "fix: sudo cpupower frequency-set -g performance"
expect "^FAIL  CAN: can0 is down, bitrate 500000"
expect "fix: sudo ip link set can0 up type can bitrate"
grep -q "eth0" <<< "$out" && fail "eth0 is not a CAN interface: $out"
expect "checks: 1 failed, 2 warnings"

echo 0x1 > "$host/sys/class/net/can0/flags"
out=$(ANIMRT_DOCTOR_ROOT=$host "$animrt" doctor 2>&1)
code=$?
[[ $code -eq 0 ]] || fail "can0 up, still exit $code: $out"
grep -q "^OK    CAN: can0 up, bitrate 500000" <<< "$out" || fail "can0 up: $out"
grep -q "^OK    CPU: runs on CPU [0-9]*, may run on .*no CPU isolated" <<< "$out" ||
  fail "no isolated CPU: $out"

if [[ $(nproc) -ge 2 ]]; then
  last=$(($(nproc) - 1))
  echo "$last" > "$host/sys/devices/system/cpu/isolated"
  out=$(ANIMRT_DOCTOR_ROOT=$host "$animrt" doctor 2>&1)
  check_structure "$out"
  grep -q "^WARN  CPU: .*isolated $last but the loop may run outside it" <<< "$out" ||
    fail "isolated CPU not used: $out"
  grep -q "fix: pin it there: under systemd, CPUAffinity=$last " <<< "$out" || fail "no fix: $out"
  out=$(ANIMRT_DOCTOR_ROOT=$host taskset -c "$last" "$animrt" doctor 2>&1)
  grep -q "^OK    CPU: runs on CPU $last, may run on $last of [0-9]*, isolated $last$" <<< "$out" ||
    fail "pinned to the isolated CPU: $out"
fi
echo "doctor: ok"
