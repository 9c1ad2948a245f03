#!/usr/bin/env bash
# Bounded fuzzing for CI (issue 14, docs/reliability.md "Fuzzing"): builds
# the cargo-fuzz targets of fuzz/ (`scene`: TOML bytes; `overrides`: a base
# scene with key=value overrides), replays every saved regression input and
# seed once, then fuzzes each target for FUZZ_SECONDS (default 60) seconds.
# Exits non-zero on any crash, hang (-timeout) or out-of-memory; the input
# that did it is left in fuzz/artifacts/<target>/.
#
# Works on a stable toolchain: cargo-fuzz passes rustc a few -Z flags, which
# RUSTC_BOOTSTRAP=1 lets stable accept. No sanitizer: ballcage-core forbids
# unsafe code, so AddressSanitizer would only slow the run down.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${FUZZ_SECONDS:-60}"
seed="${FUZZ_SEED:-1}"  # fixed: the same inputs on every CI run; any seed for a campaign
export RUSTC_BOOTSTRAP=1

echo "== fuzz: cargo-fuzz"
if ! cargo fuzz --version >/dev/null 2>&1; then
  cargo install cargo-fuzz --locked
fi
cargo fuzz --version

# Release with debug assertions and overflow checks (cargo-fuzz's default),
# 16 codegen units instead of its 1: a build twice as fast on 2 cores.
build=(--sanitizer none --codegen-units 16)
echo "== fuzz: build (release, debug assertions, no sanitizer)"
cargo fuzz build "${build[@]}"

# libFuzzer flags of every run: a 10 s hang is a failure, 4 GB is an OOM.
common=(-timeout=10 -rss_limit_mb=4096 -seed="$seed" -print_final_stats=1)

echo "== fuzz: replay fuzz/regressions and fuzz/seeds (each input once)"
cargo fuzz run "${build[@]}" scene fuzz/regressions/*.toml fuzz/seeds/scene/* -- "${common[@]}" -max_len=65536

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/scene" "$work/overrides"

echo "== fuzz: scene, ${seconds} s"
cargo fuzz run "${build[@]}" scene "$work/scene" fuzz/seeds/scene -- \
  "${common[@]}" -max_total_time="$seconds" -max_len=65536 -dict=fuzz/scene.dict

echo "== fuzz: overrides, ${seconds} s"
cargo fuzz run "${build[@]}" overrides "$work/overrides" -- \
  "${common[@]}" -max_total_time="$seconds"
