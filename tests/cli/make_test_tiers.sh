#!/usr/bin/env bash
# scripts/test-tiers (make test) with a stand-in for make that logs what it
# is asked for: the tiers' tests run in the foreground in order, each only
# after its own build, which ran in the background at idle CPU priority; a
# background build that fails fails the run with its log, and no tier after
# it runs; a failing tier stops the background builds.
set -uo pipefail
root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cat > "$tmp/make" <<'FAKE'
#!/usr/bin/env bash
# The last argument is the target; builds take a little while.
target=${!#}
echo "start $target $(chrt -p $$ 2>/dev/null | sed -n 's/.*policy: //p')" >> "$FAKE_LOG"
case $target in
  *-build|deb|install-root) echo $$ > "$FAKE_DIR/$target.pid"; sleep "${FAKE_SLOW:-0.3}" ;;
esac
# A tier may wait until a background build has started.
if [ -n "${FAKE_AFTER:-}" ] && [ "$target" = "${FAKE_FAIL:-}" ]; then
  for _ in $(seq 100); do [ -e "$FAKE_DIR/$FAKE_AFTER.pid" ] && break; sleep 0.05; done
fi
[ "$target" = "${FAKE_FAIL:-}" ] && { echo "the build of $target broke"; exit 2; }
echo "end $target" >> "$FAKE_LOG"
FAKE
chmod +x "$tmp/make"
run() {  # LOG: runs the tiers with the stand-in, output in LOG.out
  FAKE_LOG=$tmp/$1 FAKE_DIR=$tmp MAKE=$tmp/make "$root/scripts/test-tiers" > "$tmp/$1.out" 2>&1
}
order() { grep -n "^$2" "$tmp/$1" | head -1 | cut -d: -f1; }

# --- every tier passes --------------------------------------------------------
run ok || fail "the tiers failed: $(cat "$tmp/ok.out")"
grep -q "every tier passed" "$tmp/ok.out" || fail "no end line: $(cat "$tmp/ok.out")"
tiers=(test-release test-sanitize test-fuzz test-hil test-arm64)
[ "$(id -u)" -eq 0 ] && tiers+=(test-boot)
got=$(sed -n 's/^start \(test-[a-z0-9]*\).*/\1/p' "$tmp/ok")
[ "$got" = "$(printf '%s\n' "${tiers[@]}")" ] || fail "tiers ran as: $got"
for pair in sanitize-build:test-sanitize fuzz-build:test-fuzz arm64-build:test-arm64 build:test-release; do
  b=${pair%%:*} t=${pair#*:}
  [ -n "$(order ok "end $b\$")" ] || fail "$b never ended"
  [ "$(order ok "end $b\$")" -lt "$(order ok "start $t ")" ] || fail "$t started before $b ended"
done
if chrt --idle 0 true 2>/dev/null; then
  for b in sanitize-build fuzz-build arm64-build; do
    grep -q "^start $b SCHED_IDLE" "$tmp/ok" || fail "$b did not run at idle priority: $(grep "start $b" "$tmp/ok")"
  done
  grep -q "^start test-release SCHED_OTHER" "$tmp/ok" || fail "the release tests ran at: $(grep "start test-release" "$tmp/ok")"
fi

# --- a background build fails -------------------------------------------------
FAKE_FAIL=fuzz-build run broken && fail "a failed fuzz build passed: $(cat "$tmp/broken.out")"
grep -q "the build of fuzz-build broke" "$tmp/broken.out" || fail "the failed build's log is not shown: $(cat "$tmp/broken.out")"
grep -q "fuzz-build FAILED" "$tmp/broken.out" || fail "no FAILED line: $(cat "$tmp/broken.out")"
grep -q "^start test-fuzz\|^start test-hil\|^start test-arm64" "$tmp/broken" && fail "tiers ran after the failed build: $(cat "$tmp/broken")"

# --- a tier fails while the background builds run: they are stopped ------------
rm -f "$tmp"/*.pid
FAKE_SLOW=30 FAKE_FAIL=test-release FAKE_AFTER=sanitize-build run stopped &&
  fail "a failed release tier passed"
pid=$(cat "$tmp/sanitize-build.pid" 2>/dev/null) || fail "the sanitizer build never started: $(cat "$tmp/stopped")"
for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
kill -0 "$pid" 2>/dev/null && { kill "$pid"; fail "the sanitizer build kept running after the release tier failed"; }
echo "PASS"
