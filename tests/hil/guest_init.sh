#!/bin/busybox sh
# /init of the HIL guest (see tests/hil/run). Runs the guest tests, sends
# the results to the host on /dev/ttyS3 (files framed by "=== BEGIN name ==="
# and "=== END ===" lines), then powers off. Every test prints one line,
# "PASS name" or "FAIL name: why", into results.txt.
/bin/busybox --install -s /bin
export PATH=/bin:/sbin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
mkdir -p /tmp
R=/tmp/results.txt
: > $R
pass() { echo "PASS $1" >> $R; echo "hil-guest: PASS $1"; }
fail() { echo "FAIL $1: $2" >> $R; echo "hil-guest: FAIL $1: $2"; }

# -- kernel CAN --------------------------------------------------------------
ok=1
for m in can can-raw can-dev vcan; do
  insmod /lib/modules/$m.ko 2>/tmp/insmod.err || { ok=0; fail kernel_can "insmod $m: $(cat /tmp/insmod.err)"; }
done
if [ $ok = 1 ] && ip link add dev vcan0 type vcan && ip link set vcan0 up; then
  pass kernel_can
fi

# -- serial: libserialport on the 8250 UART, host-side simulated servos --------
if [ -e /sys/class/tty/ttyS1/device/driver ]; then
  animrt run /configs/robots/quadruped_ttyS1.yaml --backend hardware --duration 3 --no-realtime \
    --summary-json /tmp/serial_summary.json > /tmp/serial_run.txt 2>&1
  rc=$?
  if [ $rc = 0 ] && grep -q '"end_reason": "duration"' /tmp/serial_summary.json; then
    pass serial_quadruped
  else
    fail serial_quadruped "animrt run exited $rc: $(grep -m1 error /tmp/serial_run.txt)"
  fi
else
  fail serial_quadruped "no 8250 driver behind /dev/ttyS1"
fi

# -- serial: kill -9 of a run; the host-side servos' Bus Watchdog stops them ---
# The guest only kills the run here; the host reads the servos after the guest
# has powered off (tests/hil/run, serial_kill9_servos_stopped).
if [ -e /sys/class/tty/ttyS1/device/driver ]; then
  animrt run /configs/robots/quadruped_ttyS1.yaml --backend hardware --no-realtime \
    > /tmp/serial_kill_run.txt 2>&1 &
  krun=$!
  i=0
  while [ $i -lt 200 ] && ! grep -q 'activate: torque on' /tmp/serial_kill_run.txt; do
    sleep 0.1; i=$((i + 1))
  done
  if grep -q 'activate: torque on' /tmp/serial_kill_run.txt && kill -0 $krun 2>/dev/null; then
    sleep 1.5
    kill -9 $krun
    wait $krun 2>/dev/null
    pass serial_kill9_sent
  else
    kill -9 $krun 2>/dev/null; wait $krun 2>/dev/null
    fail serial_kill9_sent "animrt run did not reach its motion: $(head -c 300 /tmp/serial_kill_run.txt)"
  fi
fi

# -- Modbus RTU: libmodbus on the second 8250 UART, host-side simulated drive ---
# (tests/hil/run checks in the summary that the drive tracked.)
if [ -e /sys/class/tty/ttyS2/device/driver ]; then
  animrt run /configs/robots/modbus_rtu.yaml --backend hardware --duration 3 --no-realtime \
    --summary-json /tmp/modbus_summary.json > /tmp/modbus_run.txt 2>&1
  rc=$?
  if [ $rc = 0 ] && grep -q '"end_reason": "duration"' /tmp/modbus_summary.json; then
    pass modbus_rtu_drive
  else
    fail modbus_rtu_drive "animrt run exited $rc: $(grep -m1 error /tmp/modbus_run.txt)"
  fi
else
  fail modbus_rtu_drive "no 8250 driver behind /dev/ttyS2"
fi

# -- CAN: SocketCAN on vcan0, simulated motors and drive in another process ------
candump -L vcan0 > /tmp/vcan0.log 2>/tmp/candump.err &
dump=$!
# The file exists before the wait looks at it: a grep of a missing file
# made the wait end at once, and the check fail, when the background start
# had not created it yet.
: > /tmp/can_sim.txt
animrt sim /configs/robots/quadruped_can_vcan0.yaml > /tmp/can_sim.txt 2>&1 &
sim=$!
n=0
while [ "$(grep -c '^can ' /tmp/can_sim.txt)" -lt 3 ] && [ $n -lt 100 ]; do sleep 0.1; n=$((n + 1)); done
if [ "$(grep -c '^can ' /tmp/can_sim.txt)" -lt 3 ]; then
  fail can_sim "animrt sim did not come up on vcan0: $(head -c 300 /tmp/can_sim.txt)"
else
  pass can_sim
fi
# animrt scan --can on the real SocketCAN interface: the simulated CiA 402
# drive (node 32) answers its SDO reads of 0x1000 and 0x1018.
animrt scan --can vcan0 --listen-ms 300 --ids 30-34 --timeout-ms 200 > /tmp/can_scan.txt 2>&1
rc=$?
if [ $rc = 0 ] && grep -Eq '^vcan0 +canopen +- +32 +device type 0x' /tmp/can_scan.txt; then
  pass can_scan
else
  fail can_scan "animrt scan exited $rc: $(head -c 300 /tmp/can_scan.txt)"
fi
animrt run /configs/robots/quadruped_can_vcan0.yaml --backend hardware --duration 3 --no-realtime \
  --summary-json /tmp/can_summary.json > /tmp/can_run.txt 2>&1
rc=$?
if [ $rc = 0 ] && grep -q '"end_reason": "duration"' /tmp/can_summary.json; then
  pass can_quadruped
else
  fail can_quadruped "animrt run exited $rc: $(grep -m1 error /tmp/can_run.txt)"
fi
kill $sim 2>/dev/null; wait $sim 2>/dev/null
# With nobody answering, bring-up names every silent device (exit 3).
animrt run /configs/robots/quadruped_can_vcan0.yaml --backend hardware --duration 1 --no-realtime \
  > /tmp/can_missing_run.txt 2>&1
rc=$?
if [ $rc = 3 ] && grep -q 'no answer to exit motor mode from motor id 1 (lf_hip)' /tmp/can_missing_run.txt; then
  pass can_missing_devices
else
  fail can_missing_devices "expected exit 3 naming the motors, got $rc: $(head -c 300 /tmp/can_missing_run.txt)"
fi
# -- CAN kill -9: the drive's own guard stops it ------------------------------
# animrt sim serves the devices; animrt run drives them until it is killed
# with SIGKILL (no stop ramp, no deactivate). The
# drive's heartbeat consumer (device_watchdog_ms, 400 ms in this copy) must
# then send EMCY 8130h (heartbeat error) after the host's last heartbeat and
# answer an SDO upload of its statusword (sent here with cansend) with a
# state other than Operation Enabled. The MIT motors' limp state does not
# show on the wire (any frame to a motor restarts its timeout).
: > /tmp/can_kill_sim.txt
animrt sim /configs/robots/quadruped_can_vcan0.yaml > /tmp/can_kill_sim.txt 2>&1 &
ksim=$!
n=0
while [ "$(grep -c '^can ' /tmp/can_kill_sim.txt)" -lt 3 ] && [ $n -lt 100 ]; do sleep 0.1; n=$((n + 1)); done
candump -L vcan0,0A0:7FF,77F:7FF,5A0:7FF > /tmp/can_kill.log 2>/dev/null &
kdump=$!
animrt run /configs/robots/quadruped_can_vcan0.yaml --backend hardware --duration 0 --no-realtime \
  > /tmp/can_kill_run.txt 2>&1 &
krun=$!
# Killed 1.5 s after the drives were switched on (bring-up is slow under
# emulation): in the start ramp or the gait, the drive in Operation Enabled.
n=0
while ! grep -q 'activate: torque on' /tmp/can_kill_run.txt && [ $n -lt 200 ] && kill -0 $krun 2>/dev/null; do
  sleep 0.1; n=$((n + 1))
done
sleep 1.5
if kill -0 $krun 2>/dev/null; then
  kill -9 $krun
  wait $krun 2>/dev/null
  sleep 1
  cansend vcan0 620#4041600000000000
  sleep 0.3
  kill $kdump 2>/dev/null; wait $kdump 2>/dev/null
  # candump -L: "(seconds) vcan0 ID#DATA"; the host's last heartbeat, the
  # first heartbeat-error EMCY after it, the statusword answer.
  verdict=$(awk '
    { t = substr($1, 2, length($1) - 2) + 0; split($3, f, "#") }
    f[1] == "77F" && f[2] == "05" { hb = t; emcy = 0 }
    f[1] == "0A0" && substr(f[2], 1, 4) == "3081" && hb > 0 && emcy == 0 { emcy = t }
    f[1] == "5A0" && substr(f[2], 1, 8) == "4B416000" { sw = substr(f[2], 9, 2) }
    END {
      if (hb == 0) { print "no heartbeat of the host (77F#05) recorded"; exit }
      if (emcy == 0) { print "no EMCY 8130h after the host'"'"'s last heartbeat"; exit }
      if (sw == "") { print "no answer to the statusword upload"; exit }
      printf "ok %.3f %s\n", emcy - hb, sw
    }' /tmp/can_kill.log)
  case "$verdict" in
    ok*)
      set -- $verdict
      if [ $((0x$3 & 0x6F)) -ne $((0x27)) ]; then
        pass "can_kill9_drive_stopped (EMCY 8130h $2 s after the last host heartbeat, statusword low byte 0x$3)"
      else
        fail can_kill9_drive_stopped "still in Operation Enabled after SIGKILL (statusword low byte 0x$3)"
      fi ;;
    *) fail can_kill9_drive_stopped "$verdict" ;;
  esac
else
  kill $kdump 2>/dev/null; wait $kdump 2>/dev/null
  fail can_kill9_drive_stopped "animrt run ended before the kill: $(head -c 300 /tmp/can_kill_run.txt)"
fi
kill $ksim 2>/dev/null; wait $ksim 2>/dev/null

sleep 0.2
kill $dump 2>/dev/null; wait $dump 2>/dev/null
# The recording holds each protocol's traffic (candump -L: "(time) vcan0 ID#DATA").
check() { grep -q " vcan0 $2\$" /tmp/vcan0.log && pass "candump_$1" || fail "candump_$1" "no $2 in vcan0.log"; }
check mit_enter_motor_mode '001#FFFFFFFFFFFFFFFC'
check mit_reply '000#01.*'
check nmt_start_node32 '000#0120'
check sync '080#'
check sdo_device_type '5A0#4300100092010200'
check heartbeat_operational '720#05'
check tpdo '1A0#.*'

# -- CAN: animrt calibrate homes a CiA 402 drive (methods 37 and 19) ----------
. /hil/calibrate.sh

echo DONE >> $R
# -- results to the host --------------------------------------------------------
stty -F /dev/ttyS3 raw -echo 2>/dev/null
{
  for f in results.txt vcan0.log serial_summary.json serial_run.txt modbus_summary.json \
           modbus_run.txt can_summary.json can_run.txt can_sim.txt can_missing_run.txt \
           can_kill.log can_kill_run.txt cal_sim.txt calibrate_cia402_method37_out.txt \
           cal37.yaml calibrate_cia402_method37.log calibrate_cia402_method19_out.txt cal19.yaml \
           calibrate_cia402_method19.log; do
    [ -f /tmp/$f ] || continue
    echo "=== BEGIN $f ==="
    cat /tmp/$f
    echo "=== END ==="
  done
} > /dev/ttyS3
sync
poweroff -f
