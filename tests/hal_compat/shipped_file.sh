#!/usr/bin/env bash
# Runs one HAL file LinuxCNC ships through our tools. Exit 77 (ctest: skipped) when LinuxCNC's
# sample configs are not installed, as on most CI machines.
# Usage: shipped_file.sh load   HALRUN           FILE [INI] [PATTERN]
#        shipped_file.sh syntax HAL_SYNTAX_CHECK FILE [INI]
# FILE and INI are relative to the sample-config directory ($LINUXCNC_CONFIGS, default
# /usr/share/doc/linuxcnc/examples/sample-configs) or absolute; a .gz twin is unpacked.
# `load` passes when halrun --sim-clock exits 0 and its output contains PATTERN.
set -euo pipefail
mode=$1 tool=$2 file=$3 ini=${4:-} pattern=${5:-}
configs=${LINUXCNC_CONFIGS:-/usr/share/doc/linuxcnc/examples/sample-configs}
work=$(mktemp -d /tmp/hal-compat-test-XXXXXX)
trap 'rm -rf "$work"' EXIT

# Copies a shipped file into the work directory, unpacking it when only a .gz is shipped.
fetch() {
    local src=$1
    [[ $src = /* ]] || src=$configs/$src
    local dest
    dest=$work/$(basename "$src")
    if [ -f "$src" ]; then
        cp "$src" "$dest"
    elif [ -f "$src.gz" ]; then
        gunzip -c "$src.gz" > "$dest"
    else
        echo "SKIP: $src is not installed (LinuxCNC sample configs absent)"
        exit 77
    fi
    echo "$dest"
}

hal=$(fetch "$file")
ini_args=()
[ -n "$ini" ] && ini_args=(-i "$(fetch "$ini")")
cd "$work"
case $mode in
    load)
        out=$("$tool" --sim-clock --instance "compat-test-$$" "${ini_args[@]}" -f "$hal" 2>&1) || {
            echo "$out"
            echo "FAIL: halrun exited non-zero on $file"
            exit 1
        }
        echo "$out"
        if [ -n "$pattern" ] && ! grep -q -- "$pattern" <<< "$out"; then
            echo "FAIL: output lacks '$pattern'"
            exit 1
        fi
        ;;
    syntax)
        "$tool" "${ini_args[@]}" "$hal"
        ;;
    *)
        echo "unknown mode $mode" >&2
        exit 2
        ;;
esac
