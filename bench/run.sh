#!/usr/bin/env bash
# Motion benchmark: for each program in bench/ (or the ones named), our planner's motion time
# against the bound sum(length / min(F, vmax)) and against LinuxCNC 2.9 on the same settings
# (100 mm/s, 1000 mm/s^2 per axis, 1 kHz servo, G64 P0.01 unless the program sets one, jerk
# unlimited), planning throughput, and how much faster than real time `cnc run --sim-clock` ran.
# See bench/README.md and docs/benchmarks.md ("Motion").
#
#   bench/run.sh [--build DIR] [--no-build] [--no-linuxcnc] [--linuxcnc-reps N] [--jerk J]
#                [PROGRAM...]
#   bench/run.sh --check      every bench program passes `cnc check`; generated ones up to date
#
# --build DIR    build folder (default build-bench/ at the repository root, configured Release
#                and built here unless --no-build)
# --no-linuxcnc  skip LinuxCNC (it is skipped anyway when not installed)
# --linuxcnc-reps N  LinuxCNC runs per program (default 2); the table keeps the shortest
#                motion time and notes the spread
# --jerk J       also plan with this jerk limit, mm/s^3 (default 100000; 0 = skip): its own
#                column (LinuxCNC 2.9 has no jerk limit to compare with)
set -euo pipefail

bench_dir=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$bench_dir/.." && pwd)
build=$root/build-bench
do_build=1
use_linuxcnc=1
linuxcnc_reps=2
jerk_mm_s3=100000
check_only=0
programs=()
while [[ $# -gt 0 ]]; do
    case $1 in
        --build) build=$(realpath "$2"); shift 2 ;;
        --no-build) do_build=0; shift ;;
        --no-linuxcnc) use_linuxcnc=0; shift ;;
        --linuxcnc-reps) linuxcnc_reps=$2; shift 2 ;;
        --jerk) jerk_mm_s3=$2; shift 2 ;;
        --check) check_only=1; shift ;;
        -h | --help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) echo "$0: unknown option $1" >&2; exit 64 ;;
        *) programs+=("$(realpath "$1")"); shift ;;
    esac
done
if [[ ${#programs[@]} -eq 0 ]]; then
    # Fixed order: the reference program, the generated stress programs, the seeds' parts.
    programs=("$bench_dir"/tp_default.ngc "$bench_dir"/surface_3d.ngc
        "$bench_dir"/pocket_sharp.ngc "$bench_dir"/tangent_arcs.ngc "$bench_dir"/seed_*.ngc)
fi

if [[ $do_build -eq 1 ]]; then
    if [[ ! -f $build/CMakeCache.txt ]]; then
        cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
    fi
    cmake --build "$build" -j2 --target cnc bench_motion components >/dev/null
fi
cnc=$build/bin/cnc
bench_motion=$build/bin/bench_motion
for tool in "$cnc" "$bench_motion"; do
    [[ -x $tool ]] || { echo "$0: $tool is missing (build it, or drop --no-build)" >&2; exit 1; }
done

rel() { realpath --relative-to="$root" "$1"; }

if [[ $check_only -eq 1 ]]; then
    failed=0
    for prog in "${programs[@]}"; do
        if out=$("$cnc" check "$prog" 2>&1); then
            echo "ok    $(rel "$prog")"
        else
            echo "FAIL  $(rel "$prog")"
            printf '%s\n' "$out" | sed 's/^/      /'
            failed=1
        fi
    done
    if python3 "$bench_dir"/gen_programs.py --check; then
        echo "ok    generated programs match bench/gen_programs.py"
    else
        failed=1
    fi
    exit $failed
fi

if [[ $use_linuxcnc -eq 1 ]] && { ! command -v linuxcnc >/dev/null ||
    ! /usr/bin/python3 -c 'import linuxcnc' 2>/dev/null; }; then
    echo "LinuxCNC 2.9 (linuxcnc-uspace and its python3 module) is not installed:" \
        "its columns are left empty" >&2
    use_linuxcnc=0
fi

# A program that fails on one side gets "failed" in that side's cells, its reason on stderr, and
# the script exits 1 after printing the table.
declare -A segments bound ours ratio seg_per_s ours_jerk run_motion speedup lcnc lcnc_note accel_bound
declare -A lcnc_dev
failures=0
fail_note() {
    echo "$0: $1 failed on $(rel "$2"):" >&2
    printf '%s\n' "$3" | grep -v '^program,' | tail -n 3 | sed 's/^/    /' >&2
    failures=$((failures + 1))
}

# Our planner alone: bench_motion plans each program through the real interpreter and samples
# it at the servo period (CSV: program,jerk_mm_s3,segments,bound_s,motion_s,ratio,plan_seg_per_s,
# accel_bound_s,accel_ratio; accel_bound_s is the acceleration-aware lower bound).
# (--jerk before --csv: a --jerk value list would swallow the program names that follow it.)
jerks=(--jerk 0)
[[ $jerk_mm_s3 == 0 ]] || jerks+=(--jerk "$jerk_mm_s3")
for prog in "${programs[@]}"; do
    if ! csv=$("$bench_motion" "${jerks[@]}" --csv "$prog" 2>&1); then
        fail_note bench_motion "$prog" "$csv"
        ours[$prog]=failed
        continue
    fi
    while IFS=, read -r _ jerk segs b m r rate lb _; do
        if [[ $jerk != 0 ]]; then
            ours_jerk[$prog]=$m
        else
            segments[$prog]=$segs bound[$prog]=$b ours[$prog]=$m ratio[$prog]=$r seg_per_s[$prog]=$rate
            accel_bound[$prog]=$lb
        fi
    done < <(printf '%s\n' "$csv" | grep -v '^program,')
done

# The whole machine: `cnc run --sim-clock` on bench/sim/bench.ini, timed on the wall clock.
for prog in "${programs[@]}"; do
    t0=$EPOCHREALTIME
    if ! summary=$("$cnc" run "$bench_dir"/sim/bench.ini "$prog" --sim-clock 2>&1); then
        fail_note "cnc run" "$prog" "$summary"
        run_motion[$prog]=failed
        continue
    fi
    t1=$EPOCHREALTIME
    motion=$(printf '%s\n' "$summary" | sed -n 's/^motion time: \([0-9.]*\) s$/\1/p')
    run_motion[$prog]=$motion
    speedup[$prog]=$(awk -v m="$motion" -v a="$t0" -v b="$t1" 'BEGIN { printf "%.0f", m / (b - a) }')
done

# LinuxCNC 2.9 in real time (bench/linuxcnc/run.sh): motion time from its servo-cycle count.
# Under heavy load one run of tangent_arcs took 31.39 s against 31.18 s in three later runs (its
# wall clock ran 1.4 s over its count too): its task, an ordinary process, feeds the realtime
# planner, and the planner can only look ahead over what it was fed. The shortest run counts.
if [[ $use_linuxcnc -eq 1 ]]; then
    for prog in "${programs[@]}"; do
        times=()
        for ((rep = 0; rep < linuxcnc_reps; ++rep)); do
            echo "LinuxCNC: $(rel "$prog") run $((rep + 1))/$linuxcnc_reps ..." >&2
            # Its commanded X Y Z every cycle, checked against the path and the limits below.
            trace=$(mktemp /tmp/lcnctrace.XXXXXX)
            if ! result=$("$bench_dir"/linuxcnc/run.sh --trace "$trace" "$prog" 2>&1); then
                rm -f "$trace"
                fail_note LinuxCNC "$prog" "$result"
                lcnc[$prog]=failed
                continue 2
            fi
            times+=("$(printf '%s\n' "$result" | sed -n 's/^motion_s=//p')")
            # Largest distance from the programmed path (the worst of the runs).
            if check=$("$bench_motion" --trace-check "$trace" "$prog" 2>&1); then
                dev=$(printf '%s\n' "$check" | sed -n 's/^  max distance from the path \([0-9.]*\) mm.*/\1/p')
                lcnc_dev[$prog]=$(printf '%s\n%s\n' "${lcnc_dev[$prog]:-0}" "$dev" | sort -g | tail -n 1)
            fi
            rm -f "$trace"
            runs=$(printf '%s\n' "$result" | sed -n 's/^runs=//p')
            [[ $runs == 1 ]] || lcnc_note[$prog]=" (stopped $((runs - 1))x mid-program)"
        done
        read -r best worst < <(printf '%s\n' "${times[@]}" | sort -g | sed -n '1p;$p' | paste -sd' ')
        lcnc[$prog]=$best
        if [[ -n $worst && $worst != "$best" ]]; then
            lcnc_note[$prog]+=" (max $worst)"
        fi
    done
fi

jerk_head="ours, jerk $jerk_mm_s3 s"
[[ $jerk_mm_s3 == 0 ]] && jerk_head="ours, jerk-limited s"
echo "| program | segments | bound s | accel bound s | ours s | ours/bound | ours/accel bound | cnc run s | LinuxCNC s | LinuxCNC max deviation mm | ours/LinuxCNC | plan seg/s | sim-clock x real time | $jerk_head |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
num() { [[ $2 =~ ^[0-9.e+-]+$ ]] && printf "$1" "$2" || printf '%s' "${2:--}"; }
for prog in "${programs[@]}"; do
    o=${ours[$prog]}
    l=${lcnc[$prog]:-}
    vs=-
    [[ $l =~ ^[0-9.]+$ && $o =~ ^[0-9.]+$ ]] && vs=$(awk -v a="$o" -v b="$l" 'BEGIN { printf "%.3f", a / b }')
    j=${ours_jerk[$prog]:-}
    [[ -n $j ]] && j=$(awk -v a="$j" -v b="$o" 'BEGIN { printf "%.3f (%+.3f)", a, a - b }')
    lb=${accel_bound[$prog]:-}
    vs_lb=-
    [[ $lb =~ ^[0-9.]+$ && $o =~ ^[0-9.]+$ ]] && vs_lb=$(awk -v a="$o" -v b="$lb" 'BEGIN { printf "%.4f", a / b }')
    printf '| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n' \
        "$(basename "$prog")" "${segments[$prog]:--}" "$(num %.3f "${bound[$prog]:-}")" \
        "$(num %.3f "$lb")" "$(num %.3f "$o")" "$(num %.4f "${ratio[$prog]:-}")" "$vs_lb" \
        "${run_motion[$prog]:--}" \
        "${l:--}${lcnc_note[$prog]:-}" "${lcnc_dev[$prog]:--}" "$vs" \
        "$(num %.3g "${seg_per_s[$prog]:-}")" \
        "${speedup[$prog]:--}" "${j:--}"
done
[[ $failures -eq 0 ]] || { echo "$0: $failures failed run(s), see above" >&2; exit 1; }
