#!/usr/bin/env bash
# Tool-level lifecycle of a HAL instance: halcmd starts an owner when none runs, SIGTERM
# shuts it down cleanly, a killed owner's leftovers are detected and replaced, halrun -U
# cleans up. Each step prints what it checks; any mismatch fails the test.
set -u
bin=$1
export HAL_INSTANCE="tools-$$"
export HAL_RUNTIME_DIR=$(mktemp -d)
shm="/dev/shm/cnchal.$(id -u).$HAL_INSTANCE"
fail() { echo "FAIL: $*"; "$bin/halrun" -U >/dev/null 2>&1; exit 1; }
owner_pid() { pgrep -f "halrun --serve --instance $HAL_INSTANCE" | head -1; }

# 1. halcmd with no instance starts one and runs the command in it.
out=$("$bin/halcmd" loadrt and2 2>&1) || fail "halcmd loadrt: $out"
[[ "$out" == *"started HAL instance '$HAL_INSTANCE'"* ]] || fail "no start notice: $out"
[ -e "$shm" ] || fail "no segment $shm"
[ "$("$bin/halcmd" getp and2.0.out)" = "FALSE" ] || fail "getp through the started owner"
"$bin/halcmd" --no-start setp and2.0.in0 1 || fail "second command"
[ "$("$bin/halcmd" getp and2.0.in0)" = "TRUE" ] || fail "value kept between halcmd calls"
echo "ok: halcmd starts an owner and talks to it"

# 2. SIGTERM: the owner stops threads, unloads, removes segment and socket, exits 0.
pid=$(owner_pid)
[ -n "$pid" ] || fail "owner process not found"
kill -TERM "$pid"
for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.05; done
kill -0 "$pid" 2>/dev/null && fail "owner still running after SIGTERM"
[ -e "$shm" ] && fail "segment left after SIGTERM"
[ -e "$HAL_RUNTIME_DIR/$HAL_INSTANCE.sock" ] && fail "socket left after SIGTERM"
echo "ok: SIGTERM shuts the owner down cleanly"

# 3. A killed owner leaves its segment; the next owner detects and replaces it.
"$bin/halcmd" loadrt or2 >/dev/null 2>&1 || fail "restart"
pid=$(owner_pid)
kill -KILL "$pid"
sleep 0.2
[ -e "$shm" ] || fail "expected a stale segment after SIGKILL"
out=$(printf 'loadrt and2\ngetp and2.0.out\n' | "$bin/halrun" -f /dev/stdin 2>&1) || fail "halrun after a crash: $out"
[[ "$out" == *"removed stale HAL instance '$HAL_INSTANCE' left by dead process $pid"* ]] || fail "no stale notice: $out"
[ -e "$shm" ] && fail "halrun left its segment"
echo "ok: a dead owner's segment is detected and replaced"

# 4. halrun -U stops a live owner and cleans up.
"$bin/halcmd" loadrt and2 >/dev/null 2>&1 || fail "restart 2"
"$bin/halrun" -U || fail "halrun -U"
[ -e "$shm" ] && fail "segment left after halrun -U"
[ -z "$(owner_pid)" ] || fail "owner alive after halrun -U"
echo "ok: halrun -U stops the owner"

# 5. No instance: halcmd --no-start says so and fails.
out=$("$bin/halcmd" --no-start show 2>&1) && fail "halcmd succeeded without an instance"
[[ "$out" == *"no HAL instance '$HAL_INSTANCE' is running"* ]] || fail "message: $out"
echo "ok: halcmd --no-start explains a missing instance"
rm -rf "$HAL_RUNTIME_DIR"
