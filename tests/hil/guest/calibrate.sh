# Sourced by the HIL guest's /init (tests/hil/guest_init.sh), which gives
# pass/fail: `animrt calibrate` over SocketCAN on vcan0 against the
# simulated CiA 402 drive (node 40) that `animrt sim` serves in the guest,
# once homing where the joint rests (method 37), once on the drive's home
# switch (method 19, `sim.switches`). Each run: the robot file rewritten in
# place with the range moved (comments kept), the drive homed.
#
# The hand: `animrt sim`'s control interface turns serial servos only, so a
# second master on the bus moves the drive as a hand would while calibrate
# follows it (calibrate reads it by SDO and sends no PDO or SYNC while the
# joint is limp): operational, enabled in cyclic synchronous position mode
# at each position in turn (RPDO 228h: controlword, target; applied at each
# SYNC), then disabled and pre-operational again, as calibrate left it.

cal_robot=/configs/robots/cia402_calibrate.yaml

le16() { printf '%02X%02X' $(($1 & 255)) $(($1 >> 8 & 255)); }
le32() {
  v=$(($1 & 0xFFFFFFFF))
  printf '%02X%02X%02X%02X' $((v & 255)) $((v >> 8 & 255)) $((v >> 16 & 255)) $((v >> 24 & 255))
}
cal_pdo() { cansend vcan0 "228#$(le16 $1)$(le32 $2)" && cansend vcan0 080#; }
cal_hand() {  # COUNTS...: the positions in turn (the drive's counts), the last held
  cansend vcan0 000#0128
  for cw in 6 7 15; do cal_pdo $cw $1; done
  for t in "$@"; do cal_pdo 15 $t; sleep 0.4; last=$t; done
  cal_pdo 6 $last
  cal_pdo 0 $last
  cansend vcan0 000#8028
}

# The drive's position actual (6064h) by an SDO upload, or empty.
cal_position() {
  candump -L vcan0,5A8:7FF > /tmp/cal_sdo.log 2>/dev/null &
  d=$!
  sleep 0.2
  cansend vcan0 628#4064600000000000
  sleep 0.3
  kill $d 2>/dev/null; wait $d 2>/dev/null
  f=$(grep -m1 '#43646000' /tmp/cal_sdo.log | sed 's/.*#43646000//')
  [ ${#f} = 8 ] || return
  v=$((0x$(echo "$f" | sed 's/\(..\)\(..\)\(..\)\(..\)/\4\3\2\1/')))
  [ $v -ge 2147483648 ] && v=$((v - 4294967296))
  echo $v
}

# The drive's statusword in its TPDO (1A8h) while it was in homing mode
# (6060h = 6 to 6060h = 8 by SDO, 628h), from a candump log: "attained"
# once bits 12 and 10 were set with bit 13 clear; "search" before it if
# it had moved first (bits 10, 12, 13 clear: searching).
cal_homing() {
  awk 'function hex(s,   i, v) {
         for (i = 1; i <= length(s); i++) v = v * 16 + index("0123456789ABCDEF", substr(s, i, 1)) - 1
         return v }
       { split($3, f, "#") }
       f[1] == "628" && substr(f[2], 1, 10) == "2F60600006" { homing = 1; next }
       f[1] == "628" && substr(f[2], 1, 10) == "2F60600008" { homing = 0; next }
       homing && f[1] == "1A8" && !done {
         sw = hex(substr(f[2], 3, 2) substr(f[2], 1, 2))
         if (and(sw, 0x3400) == 0) search = 1
         if (and(sw, 0x3400) == 0x1400) { done = 1; printf "%s%s", search ? "search " : "", "attained" }
       }' $1
}

# NAME ROBOT EXPECTED_LINE HAND_COUNTS...: calibrate with the hand moving the joint.
cal_run() {
  name=$1 robot=$2 expect=$3
  shift 3
  : > /tmp/${name}_out.txt
  candump -L vcan0,1A8:7FF,628:7FF > /tmp/${name}.log 2>/dev/null &
  cal_dump=$!
  animrt calibrate $robot --non-interactive --yes --seconds-per-joint 4 \
    > /tmp/${name}_out.txt 2>&1 &
  c=$!
  n=0
  while ! grep -q '^axis: move it through its whole range' /tmp/${name}_out.txt && [ $n -lt 300 ] &&
    kill -0 $c 2>/dev/null; do
    sleep 0.1; n=$((n + 1))
  done
  grep -q '^axis: move it through its whole range' /tmp/${name}_out.txt && cal_hand "$@"
  wait $c
  rc=$?
  kill $cal_dump 2>/dev/null; wait $cal_dump 2>/dev/null
  if [ $rc = 0 ] && grep -q "$expect" /tmp/${name}_out.txt &&
    grep -q '1 joint calibrated' /tmp/${name}_out.txt; then
    pass "$name ($(grep -m1 'its home reads' /tmp/${name}_out.txt))"
  else
    fail $name "animrt calibrate exited $rc: $(tr '\n' ';' < /tmp/${name}_out.txt | head -c 400)"
  fi
}

# NAME ROBOT MIN MAX: the file holds the range moved (within 0.3 deg), the
# drive's zero_counts and no other key, every comment and line kept.
cal_file() {
  name=$1 robot=$2
  lim=$(grep -m1 'limits:' $robot)
  why=$(echo "$lim" | awk -v lo=$3 -v hi=$4 '{
    match($0, /min_deg: [-0-9.]+/); mn = substr($0, RSTART + 9, RLENGTH - 9) + 0
    match($0, /max_deg: [-0-9.]+/); mx = substr($0, RSTART + 9, RLENGTH - 9) + 0
    if (mn < lo - 0.3 || mn > lo + 0.3 || mx < hi - 0.3 || mx > hi + 0.3)
      printf "limits %s .. %s deg, expected %s .. %s", mn, mx, lo, hi }')
  [ -z "$why" ] && ! grep -q 'velocity_dps: 90, acceleration_dps2: 600}  # before calibration$' $robot &&
    why="the limits line lost its other keys or its comment: $lim"
  [ -z "$why" ] && ! grep -q '^      zero_counts: 1000      # what the home reads once homed$' $robot &&
    why="zero_counts changed: $(grep zero_ $robot | tr '\n' ';')"
  [ -z "$why" ] && grep -q 'zero_ticks' $robot && why="a zero_ticks key (a cia402 drive has zero_counts)"
  [ -z "$why" ] && [ "$(grep -c '#' $robot)" != "$(grep -c '#' $5)" ] && why="comments lost"
  [ -z "$why" ] && [ "$(wc -l < $robot)" != "$(wc -l < $5)" ] && why="line count changed"
  if [ -z "$why" ]; then pass "$name ($(echo $lim | sed 's/ *#.*//'))"; else fail $name "$why"; fi
}

: > /tmp/cal_sim.txt
animrt sim $cal_robot > /tmp/cal_sim.txt 2>&1 &
cal_sim=$!
n=0
while ! grep -q '^can ' /tmp/cal_sim.txt && [ $n -lt 100 ]; do sleep 0.1; n=$((n + 1)); done
# Method 37: no homing key. The hand: -20, +30, then 5 deg of the drive's
# counts; the home, where it rests, then reads zero_counts (1000).
sed '/^      homing: /d' $cal_robot > /tmp/cal37.yaml
cp /tmp/cal37.yaml /tmp/cal37_before.yaml
sed -i 's|\.\./gaits/|/configs/gaits/|' /tmp/cal37.yaml /tmp/cal37_before.yaml
cal_run calibrate_cia402_method37 /tmp/cal37.yaml \
  'axis: homed on its current position: its home reads 1000 ticks' -2000 3000 500
cal_file calibrate_cia402_method37_file /tmp/cal37.yaml -25 25 /tmp/cal37_before.yaml
p=$(cal_position)
h=$(cal_homing /tmp/calibrate_cia402_method37.log)
if [ "$h" = attained ] && [ -n "$p" ] && [ $p -ge 980 ] && [ $p -le 1020 ]; then
  pass "calibrate_cia402_method37_drive_homed (statusword: homing attained on the spot; position actual $p at the home)"
else
  fail calibrate_cia402_method37_drive_homed "statusword in homing mode: '$h' (expected attained on the spot); position actual '$p' at the home (expected 1000)"
fi
# Method 19: the search ends at the switch's edge (25 deg of the encoder),
# which then reads 1000; the hand then -15, +20, +5 deg from there.
sed 's|\.\./gaits/|/configs/gaits/|' $cal_robot > /tmp/cal19.yaml
cp /tmp/cal19.yaml /tmp/cal19_before.yaml
cal_run calibrate_cia402_method19 /tmp/cal19.yaml \
  'axis: homed on its switch: its home reads 1000 ticks' -500 3000 1500
cal_file calibrate_cia402_method19_file /tmp/cal19.yaml -15 20 /tmp/cal19_before.yaml
h=$(cal_homing /tmp/calibrate_cia402_method19.log)
if [ "$h" = "search attained" ]; then
  pass "calibrate_cia402_method19_drive_homed (statusword: searching, then homing attained)"
else
  fail calibrate_cia402_method19_drive_homed "statusword in homing mode: '$h' (expected a search, then attained)"
fi
kill $cal_sim 2>/dev/null; wait $cal_sim 2>/dev/null
