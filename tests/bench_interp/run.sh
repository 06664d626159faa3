#!/usr/bin/env bash
# Interpreter benchmark: times `cnc check` on three generated programs (surfacing lines, arcs,
# a subprogram called through nested G65 repeats) and, when LinuxCNC 2.9's rs274 is installed,
# the equivalent programs on `rs274 -g`. See docs/benchmarks.md.
#
#   run.sh [--lines N] [--reps R] [--build DIR] [--no-linuxcnc] [--keep]
#     --lines N   program size: N lines / N arcs; the loop case makes 2N/5 calls (default 500000)
#     --reps R    repetitions per measurement; best and median are printed (default 5)
#     --build DIR build directory holding bin/cnc (default build/ at the repo root)
#     --cnc PATH  the cnc executable itself (overrides --build)
#     --keep      keep the generated programs (their directory is printed)
#
# Each case also runs at N/4 (both interpreters) so peak RSS can be compared across lengths.
# Rates use the best wall time; the rate from the best user CPU time (GNU time, 1/100 s) is
# printed beside it because on a shared machine user time varies less with load.
# Exit 1 if a program fails to check (the figures would be meaningless); missing a target
# only prints MISS.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
lines=500000
reps=5
build=$root/build
cnc=
use_linuxcnc=1
keep=0
rs274=/usr/bin/rs274
timer=/usr/bin/time

while [ $# -gt 0 ]; do
    case $1 in
        --lines) lines=$2; shift 2 ;;
        --reps) reps=$2; shift 2 ;;
        --build) build=$2; shift 2 ;;
        --cnc) cnc=$2; shift 2 ;;
        --no-linuxcnc) use_linuxcnc=0; shift ;;
        --keep) keep=1; shift ;;
        -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
        *) echo "run.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
    esac
done

[ -n "$cnc" ] || cnc=$build/bin/cnc
[ -x "$cnc" ] || { echo "run.sh: $cnc not found; build it: cmake --build $build --target cnc" >&2; exit 2; }
[ -x "$timer" ] || { echo "run.sh: $timer (GNU time) is needed for peak RSS" >&2; exit 2; }
[[ $lines =~ ^[0-9]+$ ]] && [ "$lines" -ge 2000 ] || { echo "run.sh: --lines must be an integer >= 2000" >&2; exit 2; }
[[ $reps =~ ^[0-9]+$ ]] && [ "$reps" -ge 1 ] || { echo "run.sh: --reps must be >= 1" >&2; exit 2; }
[ "$use_linuxcnc" = 1 ] && [ ! -x "$rs274" ] && use_linuxcnc=0

# Targets from issue 3 (this machine).
target_lines_s=3000000
target_loop_moves_s=700000
target_rss_kb=16384

work=$(mktemp -d "${TMPDIR:-/tmp}/bench_interp.XXXXXX")
if [ "$keep" = 1 ]; then echo "programs kept in $work"; else trap 'rm -rf "$work"' EXIT; fi
gen=$root/tests/bench_interp/gen.py

# The loop case's call count: 2N/5 (200k at the default), a multiple of the inner repeat (200).
loop_calls() { local c=$(( $1 * 2 / 5 / 200 * 200 )); [ "$c" -ge 200 ] || c=200; echo "$c"; }

# measure LABEL CMD...: runs CMD reps times, prints "best_wall median_wall best_user max_rss_kb".
# Wall time comes from bash's microsecond clock around the run (GNU time's %e has only 1/100 s,
# 6 % of a 0.16 s run); user time and peak RSS come from GNU time.
# Any failed run aborts: a program that does not check cleanly measures nothing.
measure() {
    local label=$1; shift
    local walls=() users=() rss=0 i
    for ((i = 0; i < reps; i++)); do
        local t0=$EPOCHREALTIME
        if ! "$timer" -f '%e %U %M' -o "$work/time" "$@" > "$work/out" 2> "$work/err" < /dev/null; then
            echo "run.sh: $label failed: $*" >&2
            head -5 "$work/err" "$work/out" >&2
            exit 1
        fi
        local t1=$EPOCHREALTIME
        read -r _ u m < <(tail -1 "$work/time")
        walls+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f", b - a }')"); users+=("$u")
        [ "$m" -gt "$rss" ] && rss=$m
    done
    local sorted_w sorted_u
    sorted_w=$(printf '%s\n' "${walls[@]}" | sort -g)
    sorted_u=$(printf '%s\n' "${users[@]}" | sort -g)
    echo "$(head -1 <<< "$sorted_w") $(sed -n "$(( (reps + 1) / 2 ))p" <<< "$sorted_w") $(head -1 <<< "$sorted_u") $rss"
}

# check_moves PROGRAM EXPECTED: the summary of the last `cnc check` must count EXPECTED moves or
# more (the preamble adds a few), so a generator or interpreter change that silently drops
# blocks cannot make the figures look good.
check_moves() {
    local got
    got=$(grep -oiE '[0-9]+ moves|moves[: ]+[0-9]+' "$work/out" | grep -oE '[0-9]+' | head -1 || true)
    if [ -z "$got" ] || [ "$got" -lt "$2" ]; then
        echo "run.sh: $1: expected at least $2 moves in the check summary, got '${got:-none}'" >&2
        cat "$work/out" >&2
        exit 1
    fi
}

rate() { awk -v n="$1" -v t="$2" 'BEGIN { if (t <= 0) print "inf"; else printf "%.0f", n / t }'; }
verdict() { awk -v a="$1" -v b="$2" -v dir="$3" 'BEGIN { ok = (dir == "ge") ? (a >= b) : (a <= b); print ok ? "ok" : "MISS" }'; }
human() { awk -v n="$1" 'BEGIN { if (n == "inf") print n; else if (n >= 1e6) printf "%.2fM", n / 1e6; else printf "%.0fk", n / 1e3 }'; }

echo "interpreter benchmark: $(date -u '+%F %T') UTC, $(nproc) cores, load: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "cnc: $cnc; reps: $reps; rates use the best wall time"
[ "$use_linuxcnc" = 1 ] && echo "LinuxCNC: $rs274 -g IN /dev/null" || echo "LinuxCNC: not run"
echo

for kind in surfacing arcs loop; do
    for size in $(( lines / 4 )) "$lines"; do
        if [ "$kind" = loop ]; then
            count=$(loop_calls "$size"); units=$(( count * 2 )); unit=moves
            what="$count calls x 2 moves"; target=$target_loop_moves_s
        else
            count=$size; units=$size; unit=lines; [ "$kind" = arcs ] && unit=arcs
            what="$count $unit"; target=$target_lines_s
        fi
        prog=$work/$kind-$size
        python3 "$gen" "$kind" "$count" ncstudio "$prog.nc"
        read -r bw mw bu rss < <(measure "cnc check $kind" "$cnc" check "$prog.nc")
        check_moves "$kind-$size" "$units"
        ours=$(rate "$units" "$bw")
        printf '%-9s %-24s cnc check: best %6.3f s median %6.3f s user %5.2f s  %8s %s/s (user: %s) [target >= %s: %s]  peak RSS %6.1f MB [<= 16 MB: %s]\n' \
            "$kind" "$what" "$bw" "$mw" "$bu" "$(human "$ours")" "$unit" "$(human "$(rate "$units" "$bu")")" "$(human "$target")" \
            "$(verdict "$ours" "$target" ge)" "$(awk -v k="$rss" 'BEGIN{print k/1024}')" "$(verdict "$rss" "$target_rss_kb" le)"
        eval "rss_${kind}_$size=$rss"
        if [ "$use_linuxcnc" = 1 ]; then
            python3 "$gen" "$kind" "$count" linuxcnc "$prog.ngc"
            read -r tbw tmw tbu trss < <(measure "rs274 $kind" "$rs274" -g "$prog.ngc" /dev/null)
            theirs=$(rate "$units" "$tbw")
            eval "trss_${kind}_$size=$trss"
            printf '%-9s %-24s rs274 -g:  best %6.3f s median %6.3f s user %5.2f s  %8s %s/s  peak RSS %6.1f MB   ours/theirs: speed %sx, RSS %sx\n' \
                "" "" "$tbw" "$tmw" "$tbu" "$(human "$theirs")" "$unit" "$(awk -v k="$trss" 'BEGIN{print k/1024}')" \
                "$(awk -v a="$tbw" -v b="$bw" 'BEGIN{ if (b <= 0) print "inf"; else printf "%.1f", a / b }')" \
                "$(awk -v a="$rss" -v b="$trss" 'BEGIN{ printf "%.2f", a / b }')"
        fi
        rm -f "$prog.nc" "$prog.ngc"
    done
    small=$(eval echo "\$rss_${kind}_$(( lines / 4 ))"); big=$(eval echo "\$rss_${kind}_$lines")
    printf '%-9s peak RSS at N/4 %.1f MB, at N %.1f MB: growth %+d KB [flat (< 1 MB): %s]\n' "$kind" \
        "$(awk -v k="$small" 'BEGIN{print k/1024}')" "$(awk -v k="$big" 'BEGIN{print k/1024}')" \
        "$(( big - small ))" "$(verdict "$(( big - small ))" 1024 le)"
    if [ "$use_linuxcnc" = 1 ]; then
        small=$(eval echo "\$trss_${kind}_$(( lines / 4 ))"); big=$(eval echo "\$trss_${kind}_$lines")
        printf '%-9s rs274 peak RSS at N/4 %.1f MB, at N %.1f MB: growth %+d KB\n' "" \
            "$(awk -v k="$small" 'BEGIN{print k/1024}')" "$(awk -v k="$big" 'BEGIN{print k/1024}')" "$(( big - small ))"
    fi
    echo
done
